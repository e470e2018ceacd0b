"""One obtained mesh against its golden, as the pytest fixture ``mesh_regression`` checks it
(:mod:`srarap_cli.pytest_plugin`): the same gates as a manifest's ``expect``, the same
one-line verdict as ``compare``, the golden created when missing and rewritten where asked,
and the obtained mesh left beside a golden it does not match."""
import os
from dataclasses import dataclass, field
from typing import Any

from ..io.mesh import Mesh, read_mesh
from ..io.mesh.formats import by_extension, suffix_of
from ..runtime.commit import commit_files
from ..solver.api_checks import mesh_like
from .comparison import (
    Observed,
    compare_meshes,
    judge,
    parse_expect,
    read_golden_record,
    verdict_line,
    write_golden,
)


@dataclass
class RegressionOutcome:
    """``failure``: the test's failure message (None: it passes); ``properties``: the figures
    for pytest's JUnit (name, value)."""

    failure: str | None
    properties: list[tuple[str, Any]] = field(default_factory=list)


def obtained_path(golden: str) -> str:
    """Where a mesh that does not match ``golden`` is left: ``x.obj`` -> ``x.obtained.obj``."""
    stem, ext = os.path.splitext(golden)
    return f"{stem}.obtained{ext}"


def check_against_golden(obtained: Any, golden: str, mode: str,
                         gates: dict[str, Any]) -> RegressionOutcome:
    """Check ``obtained`` (a DeformResult, a Mesh, a ``(V, F)`` pair, a trimesh or meshio
    mesh) against the mesh at ``golden`` with ``gates`` (a manifest's ``expect`` keys);
    ``mode``: ``check``, ``update`` or ``accept`` (see :mod:`srarap_cli.pytest_plugin`)."""
    if "golden" in gates:
        raise ValueError("mesh_regression.check: the golden's path comes from the test's "
                         "(basename= and extension= change it), not from a golden= keyword")
    expect = parse_expect({**gates, "golden": golden}, ValueError, golden)
    fmt = by_extension(golden)
    if fmt is None:
        raise ValueError(f"{golden}: extension {suffix_of(golden)!r} is no mesh format")
    mesh, run = _obtained(obtained)
    root = os.path.dirname(golden)
    os.makedirs(root, exist_ok=True)  # tests of one module may make it at once (xdist)
    if not os.path.exists(golden):
        action = write_golden(golden, mesh, run, root)
        if mode == "accept":
            return RegressionOutcome(None, [("golden", action)])
        return RegressionOutcome(f"mesh_regression: no golden at {golden}: {action} from the "
                                 "obtained mesh; look at it, then rerun")
    found = compare_meshes(read_mesh(golden), mesh, expect.align).scaled(expect.relative)
    unit = " (fractions of the golden's diagonal)" if expect.relative else ""
    failed = judge(found, expect, run, read_golden_record(golden) if expect.needs_record
                   else None, unit, "golden", "obtained")
    properties = [(f"mesh_regression.{name}", value) for name, value in (
        ("max", found.max), ("p95", found.p95), ("beyond_tol", found.verdict(expect.tol).beyond),
        ("iterations", run.iterations), ("energy", run.energy)) if value is not None]
    left = obtained_path(golden)
    if not failed:
        if os.path.exists(left):  # a failure's leftover, now stale
            os.remove(left)
        return RegressionOutcome(None, properties)
    commit_files([(left, fmt.encode(mesh)[0])], inside=root)
    line = verdict_line(found, expect, failed, unit, ("golden", "obtained"))
    if mode != "check":
        action = write_golden(golden, mesh, run, root)
        if mode == "accept":
            return RegressionOutcome(None, properties + [("golden", action)])
        line += f"; golden {action}: look at it, then rerun"
    return RegressionOutcome(f"mesh_regression: {line}; obtained mesh: {left}", properties)


def _obtained(obtained):
    """The obtained mesh and the figures of the solve that made it (none for a mesh)."""
    if hasattr(obtained, "positions") and hasattr(obtained, "to_arrays"):  # a DeformResult
        return (Mesh.from_arrays(*obtained.to_arrays()),
                Observed(obtained.iterations, obtained.energy, obtained.seconds))
    if isinstance(obtained, Mesh):
        return obtained, Observed()
    return Mesh.from_arrays(*mesh_like(obtained, "obtained")), Observed()
