"""``srarap compare`` as a job a Python caller can run too: two mesh files compared against
every gate asked for, the figures written as JSON, an HTML report, JUnit, a Markdown summary
and OpenMetrics, the golden (B) created or updated where asked, and the verdict's exit code."""
import json
import os
from dataclasses import dataclass
from typing import Any

from ...io.mesh.formats import MeshFormat
from ...io.mesh.mesh import Mesh
from ...runtime import exit_codes
from ...runtime.commit import commit_files
from ...runtime.encoding import utf8
from ...runtime.errors import InputError, UsageProblem
from .. import job_fields as fields
from ..ci_summaries import openmetrics, summary_markdown
from ..job_status import JobResult, JobStatus
from ..pictures import difference_picture, shape_picture
from ..preflight import check_output_path, read_any_mesh, refuse_overwrite
from ..reports import encode_png, junit_xml, report_html
from .align import moved
from .compare import ALIGNMENTS, Comparison, Verdict, compare_meshes
from .gates import Expect, Observed, judge, verdict_line
from .goldens import GOLDEN_MODES, write_golden


@dataclass(frozen=True)
class CompareJob:
    """Meshes ``a`` (obtained) and ``b`` (the golden; paths, one may be ``-``) within
    ``tol`` (a fraction of A's diagonal with ``relative``), and the files to write: ``json``,
    ``report`` (HTML), ``junit``, ``summary_md`` (Markdown), ``metrics`` (OpenMetrics).

    ``beyond_tol``, ``p95``, ``p99``: the other distance gates (see
    :class:`~.gates.Expect`); ``align``: ``rigid`` moves B onto A first; ``goldens``:
    ``update`` writes A to B when B is missing or beyond the gates (the exit code still says
    so), ``accept`` too and exits 0."""

    a: str
    b: str
    tol: float = 0.0
    relative: bool = False
    json: str | None = None
    report: str | None = None
    junit: str | None = None
    input_format: MeshFormat | None = None
    beyond_tol: float = 0.0
    p95: float | None = None
    p99: float | None = None
    align: str = "none"
    goldens: str = "check"
    summary_md: str | None = None
    metrics: str | None = None

    def __post_init__(self) -> None:
        fields.text(self, "a")
        fields.text(self, "b")
        for name in ("json", "report", "junit", "summary_md", "metrics"):
            fields.text(self, name, optional=True)
        fields.number(self, "tol")
        fields.flag(self, "relative")
        fields.number(self, "beyond_tol", high=1.0)
        fields.number(self, "p95", optional=True)
        fields.number(self, "p99", optional=True)
        fields.choice(self, "align", ALIGNMENTS)
        fields.choice(self, "goldens", GOLDEN_MODES)

    def expect(self) -> Expect:
        return Expect(self.b, self.tol, self.relative, self.beyond_tol, self.p95, self.p99,
                      align=self.align)


@dataclass(frozen=True)
class CompareOutcome:
    """The comparison (in the job's unit; None when B was missing and written), its verdict,
    the gates that failed, what became of B (``golden``: ``created``, ``updated`` or ""), and
    the exit code: 0 within, 7 beyond, 8 B missing (written with ``update``); 0 whenever
    ``accept`` wrote B."""

    job: CompareJob
    found: Comparison | None
    verdict: Verdict
    failed: tuple[str, ...] = ()
    golden: str = ""

    @property
    def exit_code(self) -> int:
        if self.golden and self.job.goldens == "accept" or not self.failed:
            return exit_codes.OK
        return exit_codes.BATCH_FAILED if self.found is None else exit_codes.BEYOND_TOLERANCE

    @property
    def warnings(self) -> list[str]:
        return []

    @property
    def status(self) -> JobStatus:
        if self.exit_code == exit_codes.OK:
            return JobStatus.OK
        return JobStatus.NO_GOLDEN if self.found is None else JobStatus.REGRESSED

    def figures(self) -> dict[str, Any]:
        """What ``--json`` writes."""
        found = {} if self.found is None else self.found.figures()
        return {"a": self.job.a, "b": self.job.b, "mode": found.get("mode"),
                "relative": self.job.relative, "tol": self.job.tol,
                "within_tol": not self.failed, "max": found.get("max"),
                "mean": found.get("mean"), "rms": found.get("rms"),
                "diagonal": found.get("diagonal"), "farthest": found.get("farthest"),
                "beyond_tol": self.verdict.beyond, "status": self.status.value,
                "failed": list(self.failed), "golden": self.golden or None,
                **{k: v for k, v in found.items() if k not in _IN_FRONT}}

    def summary(self) -> str:
        unit = " of the diagonal" if self.job.relative else ""
        written = f"; B {self.golden} from A" if self.golden else ""
        if self.found is None:
            return f"srarap compare: no golden at {self.job.b}{written}"
        line = verdict_line(self.found, self.job.expect(), list(self.failed), unit)
        return f"srarap compare: {line}{written}"


_IN_FRONT = ("mode", "max", "mean", "rms", "diagonal", "farthest")


def run_compare(job: CompareJob) -> CompareOutcome:
    """Compare ``job``'s meshes, write B from A where ``job.goldens`` says so, and commit the
    files it asks for (all or none)."""
    fields.of_type(job, CompareJob, "run_compare")
    _check(job)
    ma = read_any_mesh(job.a, job.input_format)[0]
    if job.goldens != "check" and job.b != "-" and not os.path.exists(job.b):
        golden = write_golden(job.b, ma, Observed(), _root(job.b), _file(job.a))
        done = CompareOutcome(job, None, Verdict(job.tol, False, 1.0),
                              (f"no golden at {job.b}",), golden)
        _commit(job, done, ma, None)
        return done
    if job.goldens == "check" and job.b != "-" and not os.path.lexists(job.b):
        raise InputError(f"{job.b}: no such file (a golden not made yet? srarap compare A B "
                         "--update writes A there)")
    mb = read_any_mesh(job.b, job.input_format)[0]
    found = compare_meshes(ma, mb, job.align).scaled(job.relative)
    unit = " of the diagonal" if job.relative else ""
    failed = tuple(judge(found, job.expect(), Observed(), None, unit, "A", "B"))
    golden = ""
    if failed and job.goldens != "check":
        golden = write_golden(job.b, ma, Observed(), _root(job.b), _file(job.a))
    done = CompareOutcome(job, found, found.verdict(job.tol), failed, golden)
    _commit(job, done, ma, mb if found.motion is None else moved(mb, found.motion))
    return done


def _check(job):
    for path, ext, what in ((job.json, (".json",), "--json"),
                            (job.report, (".html", ".htm"), "--report"),
                            (job.junit, (".xml",), "--junit"),
                            (job.summary_md, None, "--summary-md"),
                            (job.metrics, None, "--metrics")):
        if path is not None:
            check_output_path(path, ext, what)
    refuse_overwrite([job.json, job.report, job.junit, job.summary_md, job.metrics],
                     others=[("mesh A", job.a), ("mesh B", job.b)])
    if job.a == job.b == "-":
        raise UsageProblem("only one of A and B can be '-' (standard input)")
    if job.goldens != "check":
        if job.b == "-":
            raise UsageProblem("--update writes B: B cannot be '-' (standard input)")
        if os.path.exists(job.a) and os.path.exists(job.b) \
                and os.path.samefile(job.a, job.b):
            raise InputError(f"{job.b}: is mesh A; refusing to overwrite an input")


def _file(path):
    """A's file, whose bytes become B's where both have one extension (not a stream)."""
    return None if path == "-" or not os.path.isfile(path) else path


def _root(golden):
    """The folder a golden named on the command line may be written in: its own."""
    return os.path.dirname(os.path.abspath(golden))


def _commit(job, done, ma, mb):
    files = [] if job.json is None else [(job.json, utf8(json.dumps(done.figures(), indent=2)
                                                          + "\n"))]
    if any(p is not None for p in (job.report, job.junit, job.summary_md, job.metrics)):
        row = _row(job, done)
        if job.report is not None:
            pictures = {} if mb is None else compare_pictures(ma, mb, done.found, job.tol)
            files.append((job.report, utf8(report_html([row], {row.job: pictures},
                                                       "srarap compare"))))
        if job.junit is not None:
            files.append((job.junit, utf8(junit_xml([row], "compare"))))
        if job.summary_md is not None:
            files.append((job.summary_md, utf8(summary_markdown([row], "srarap compare"))))
        if job.metrics is not None:
            files.append((job.metrics, utf8(openmetrics([row]))))
    commit_files(files)


def _row(job, done):
    """The comparison as one job's row, for the report, JUnit and the summaries."""
    found, status = done.found, done.status
    message = "; ".join(done.failed)
    if done.golden:
        message = f"B {done.golden} from A" + (f": {message}" if message else "")
    row = JobResult(f"{job.a} vs {job.b}", status, done.exit_code, tol=job.tol,
                    message=message, golden=done.golden)
    if found is not None:
        for name, value in found.row_figures(job.tol).items():
            setattr(row, name, value)
    return row


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
