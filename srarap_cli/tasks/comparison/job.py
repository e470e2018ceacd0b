"""``srarap compare`` as a job a Python caller can run too: two mesh files compared, the
figures written as JSON, an HTML report and JUnit, and the verdict's exit code."""
import json
from dataclasses import dataclass
from typing import Any

from ...io.mesh.formats import MeshFormat
from ...io.mesh.mesh import Mesh
from ...runtime import exit_codes
from ...runtime.commit import commit_files
from ...runtime.encoding import utf8
from ...runtime.errors import UsageProblem
from ..job_status import JobResult, JobStatus
from ..pictures import difference_picture, shape_picture
from ..preflight import check_output_path, read_any_mesh, refuse_overwrite
from ..reports import encode_png, junit_xml, report_html
from .compare import Comparison, Verdict, compare_meshes


@dataclass(frozen=True)
class CompareJob:
    """Meshes ``a`` and ``b`` (paths; one may be ``-``) within ``tol`` (a fraction of A's
    diagonal with ``relative``), and the files to write: ``json``, ``report`` (HTML),
    ``junit``."""

    a: str
    b: str
    tol: float = 0.0
    relative: bool = False
    json: str | None = None
    report: str | None = None
    junit: str | None = None
    input_format: MeshFormat | None = None


@dataclass(frozen=True)
class CompareOutcome:
    """The comparison (in the job's unit), its verdict, the exit code (0 within, 7 not)."""

    job: CompareJob
    found: Comparison
    verdict: Verdict

    @property
    def exit_code(self) -> int:
        return exit_codes.OK if self.verdict.within else exit_codes.BEYOND_TOLERANCE

    @property
    def warnings(self) -> list[str]:
        return []

    def figures(self) -> dict[str, Any]:
        """What ``--json`` writes."""
        return {"a": self.job.a, "b": self.job.b, "mode": self.found.mode,
                "relative": self.job.relative, "tol": self.job.tol,
                "within_tol": self.verdict.within, "max": self.found.max,
                "mean": self.found.mean, "rms": self.found.rms,
                "diagonal": self.found.diagonal, "farthest": self.found.farthest,
                "beyond_tol": self.verdict.beyond}

    def where(self) -> str:
        """Where the largest difference is, when it is beyond the tolerance."""
        far = self.found.farthest
        if self.verdict.within or far is None or "position" not in far:
            return ""
        at = ", ".join(f"{x:.4g}" for x in far["position"])
        return (f"; farthest: {far['mesh'].upper()}'s vertex {far['vertex']} at ({at}); "
                f"{100 * self.verdict.beyond:.3g}% of the vertices beyond tol")

    def summary(self) -> str:
        unit = " of the diagonal" if self.job.relative else ""
        return (f"srarap compare: {'within' if self.verdict.within else 'BEYOND'} tol "
                f"{self.job.tol:g}{unit} ({self.found.mode}): max {self.found.max:.6g}, mean "
                f"{self.found.mean:.6g}, rms {self.found.rms:.6g}{unit}{self.where()}")


def run_compare(job: CompareJob) -> CompareOutcome:
    """Compare ``job``'s meshes and commit the files it asks for (all or none)."""
    for path, ext, what in ((job.json, (".json",), "--json"),
                            (job.report, (".html", ".htm"), "--report"),
                            (job.junit, (".xml",), "--junit")):
        if path is not None:
            check_output_path(path, ext, what)
    refuse_overwrite([job.json, job.report, job.junit],
                     others=[("mesh A", job.a), ("mesh B", job.b)])
    if job.a == job.b == "-":
        raise UsageProblem("only one of A and B can be '-' (standard input)")
    ma, mb = read_any_mesh(job.a, job.input_format)[0], read_any_mesh(job.b, job.input_format)[0]
    found = compare_meshes(ma, mb).scaled(job.relative)
    done = CompareOutcome(job, found, found.verdict(job.tol))
    files = [] if job.json is None else [(job.json, utf8(json.dumps(done.figures(), indent=2)
                                                          + "\n"))]
    if job.report is not None or job.junit is not None:
        within = done.verdict.within
        status = JobStatus.OK if within else JobStatus.REGRESSED
        row = JobResult(f"{job.a} vs {job.b}", status, status.exit_code, compare_max=found.max,
                        compare_mean=found.mean, tol=job.tol, message="" if within else
                        f"max distance {found.max:.3g} > tol {job.tol:g}{done.where()}")
        if job.report is not None:
            pictures = compare_pictures(ma, mb, found, job.tol)
            files.append((job.report, utf8(report_html([row], {row.job: pictures},
                                                       "srarap compare"))))
        if job.junit is not None:
            files.append((job.junit, utf8(junit_xml([row], "compare"))))
    commit_files(files)
    return done


def compare_pictures(a: Mesh, b: Mesh, found: Comparison, tol: float) -> dict[str, str]:
    """``compare``'s report pictures (base64 PNG): ``shape``, B over A ghosted (when they
    share vertices), and ``difference``, B coloured by each vertex's distance to A (in
    ``found``'s unit)."""
    out = {}
    if found.mode == "per-vertex":
        out["shape"] = encode_png(shape_picture(a, b, None))
    out["difference"] = encode_png(difference_picture(a, b, found.of_b(len(b.vertices)), tol,
                                                      found.scale))
    return out
