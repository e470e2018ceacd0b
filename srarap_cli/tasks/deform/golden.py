"""A job's output against its golden mesh: the distances and every gate of its ``expect`` into
its result (``regressed`` when any fails, ``no-golden`` when there is none), and, where the
run was asked to, the golden created or replaced from the output."""
import os
from collections.abc import Mapping
from typing import Any

from ...io.mesh import read_mesh
from ...io.mesh.formats import suffix_of
from ..comparison import (
    Expect,
    Observed,
    compare_meshes,
    judge,
    parse_expect,
    read_golden_record,
    write_golden,
)
from ..job_status import JobResult, JobStatus


def as_expect(expect: Expect | Mapping[str, Any]) -> Expect:
    """``expect`` as an :class:`Expect` (a mapping is parsed as a manifest's is)."""
    return expect if isinstance(expect, Expect) else parse_expect(expect, ValueError)


def check_golden(result: JobResult, expect: Expect | Mapping[str, Any], out: str,
                 goldens: str = "check", root: str | None = None) -> None:
    """Compare the mesh ``out`` with ``expect``'s golden into ``result``: the distances
    (``compare_*`` and ``beyond_tol``, in the unit of ``tol``: a fraction of the golden
    mesh's diagonal with ``relative``; ``aligned``: the rigid motion applied first), status
    ``regressed`` with every failing gate in the message, or ``no-golden`` when the golden is
    missing; the figures are kept in ``result.seen.golden`` for the report's difference
    picture. With ``goldens`` ``update`` or ``accept`` (see
    :data:`..comparison.goldens.GOLDEN_MODES`) a missing or regressed golden is written from
    ``out`` (never outside ``root``) and ``result.golden`` says so; ``accept`` makes the job
    pass."""
    expect = as_expect(expect)
    run = Observed(result.iterations, result.energy,
                   result.seconds if result.solved else result.seen.recorded_seconds)
    result.tol = expect.tol
    if not os.path.exists(expect.golden):
        result.status, result.exit_code = JobStatus.NO_GOLDEN, JobStatus.NO_GOLDEN.exit_code
        result.message = f"no golden mesh at {expect.golden}"
        if goldens == "check":
            result.message += " (--update-goldens creates it from this run's output)"
    else:
        _measure(result, expect, out, run)
    if goldens != "check" and result.status in (JobStatus.NO_GOLDEN, JobStatus.REGRESSED):
        _write(result, expect, out, run, goldens, root)


def _measure(result, expect, out, run):
    found = compare_meshes(read_mesh(expect.golden), read_mesh(out),
                           expect.align).scaled(expect.relative)
    for name, value in found.row_figures(expect.tol).items():
        setattr(result, name, value)
    result.seen.golden = (found, expect)
    record = read_golden_record(expect.golden) if expect.needs_record else None
    unit = " (fractions of the golden mesh's diagonal)" if found.relative else ""
    failed = judge(found, expect, run, record, unit)
    if failed:
        result.status, result.exit_code = JobStatus.REGRESSED, JobStatus.REGRESSED.exit_code
        result.message = "; ".join(failed)


def _write(result, expect, out, run, goldens, root):
    root = root if root is not None else os.path.dirname(os.path.abspath(expect.golden))
    same_format = suffix_of(out) == suffix_of(expect.golden)  # then the output's own bytes
    result.golden = write_golden(expect.golden, None if same_format else read_mesh(out), run,
                                 root, obtained_path=out)
    if goldens == "accept":
        result.status, result.exit_code = JobStatus.OK, JobStatus.OK.exit_code
        result.message = f"golden {result.golden} (accepted): {result.message}"
    else:
        result.message += (f"; golden {result.golden} from this run's output: review it, "
                           "then rerun (--accept-goldens takes it as the truth)")
