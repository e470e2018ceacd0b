"""A job's output against its golden mesh: the distances into its result, ``regressed``
beyond the tolerance."""
from collections.abc import Mapping
from typing import Any

from ...io.mesh import read_mesh
from ..comparison import compare_meshes
from ..job_status import JobResult, JobStatus


def check_golden(result: JobResult, expect: Mapping[str, Any], out: str) -> None:
    """Compare the mesh ``out`` with ``expect["golden"]`` into ``result`` (``compare_max``,
    ``compare_mean``, ``tol``; status ``regressed`` and a message naming the farthest vertex
    beyond ``expect["tol"]``, relative to the golden's diagonal with ``expect["relative"]``);
    the figures are kept in ``result.seen["golden"]`` for the report's difference picture."""
    found = compare_meshes(read_mesh(expect["golden"]), read_mesh(out)).scaled(expect["relative"])
    result.compare_max, result.compare_mean = found.max, found.mean
    result.tol = expect["tol"]
    result.seen["golden"] = (found, expect)
    verdict = found.verdict(expect["tol"])
    if not verdict.within:
        far = found.farthest
        at = "" if far is None else (f" at vertex {far['vertex']} of the "
                                     f"{'golden' if far['mesh'] == 'a' else 'output'} mesh")
        result.status, result.exit_code = JobStatus.REGRESSED, JobStatus.REGRESSED.exit_code
        unit = " (fractions of the golden mesh's diagonal)" if found.relative else ""
        result.message = (f"max distance {result.compare_max:.3g} > tol {expect['tol']:g}"
                          f"{unit}{at}; {100 * verdict.beyond:.3g}% of the vertices beyond tol")
