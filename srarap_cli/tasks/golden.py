"""A job's output against its golden mesh: the distances into its result, ``regressed``
beyond the tolerance."""
from collections.abc import Mapping
from typing import Any

from ..io.mesh import read_mesh
from .compare import beyond, compare_meshes
from .job_status import JobResult, JobStatus


def check_golden(result: JobResult, expect: Mapping[str, Any], out: str) -> None:
    """Compare the mesh ``out`` with ``expect["golden"]`` into ``result`` (``compare_max``,
    ``compare_mean``, ``tol``; status ``regressed`` and a message naming the farthest vertex
    beyond ``expect["tol"]``, relative to the golden's diagonal with ``expect["relative"]``);
    the figures are kept in ``result.seen["golden"]`` for the report's difference picture."""
    figures = compare_meshes(read_mesh(expect["golden"]), read_mesh(out))
    scale = figures["diagonal"] if expect["relative"] and figures["diagonal"] > 0 else 1.0
    result.compare_max, result.compare_mean = figures["max"] / scale, figures["mean"] / scale
    result.tol = expect["tol"]
    result.seen["golden"] = (figures, expect)
    if result.compare_max > expect["tol"]:
        far = figures["where"]
        at = "" if far is None else (f" at vertex {far['vertex']} of the "
                                     f"{'golden' if far['mesh'] == 'a' else 'output'} mesh")
        result.status, result.exit_code = JobStatus.REGRESSED, JobStatus.REGRESSED.exit_code
        unit = " (fractions of the golden mesh's diagonal)" if scale != 1.0 else ""
        result.message = (f"max distance {result.compare_max:.3g} > tol {expect['tol']:g}"
                          f"{unit}{at}; "
                          f"{100 * beyond(figures, expect['tol'], expect['relative']):.3g}% "
                          "of the vertices beyond tol")
