"""``srarap bench`` as a job a Python caller can run too: every method on one mesh and
handle file from the same start, the table, and (with a folder) the curves, the summary and
the energy plot."""
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ...io.handles import load_handles
from ...io.mesh import read_mesh
from ...runtime.commit import commit_files
from ...runtime.encoding import utf8
from ...runtime.errors import UsageProblem
from ...runtime.limits import check_solve
from ...solver.settings import resolve
from .. import job_fields as fields
from ..pipeline import problem
from ..preflight import check_output_path, refuse_overwrite
from .methods import ALL_METHODS, IGL, run_methods
from .report import curves_csv, plot_png, summary_json, table

CHOICES = ALL_METHODS + (IGL,)
# bench measures how fast each method approaches the minimum, so it runs far past the usual
# stopping point unless told otherwise (the handle file's tol and max_iter do not apply)
OWN_DEFAULTS = {"tol": 1e-9, "max_iter": 100000}
BENCH_FILES = ("curves.csv", "summary.json", "energy.png")


@dataclass(frozen=True)
class BenchJob:
    """The ``methods`` (of :data:`CHOICES`) on ``mesh`` and ``handles``, each given
    ``time_budget`` seconds, ``settings`` over :data:`OWN_DEFAULTS` and the handle file's;
    ``out``: a folder for :data:`BENCH_FILES` (None: the table only)."""

    mesh: str
    handles: str
    methods: tuple[str, ...] = CHOICES
    time_budget: float = 30.0
    out: str | None = None
    settings: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        fields.text(self, "mesh")
        fields.text(self, "handles")
        fields.text(self, "out", optional=True)
        fields.texts(self, "methods")
        fields.number(self, "time_budget", 0.0, low_open=True)
        if not isinstance(self.settings, Mapping):
            raise TypeError("BenchJob.settings must be a mapping of settings")


def run_bench(job: BenchJob, on_table: Callable[[str], None] | None = None) -> list[Any]:
    """Run ``job``; ``on_table`` hears the results table as soon as it is made (before the
    files). Returns the runs."""
    fields.of_type(job, BenchJob, "run_bench")
    unknown = [m for m in job.methods if m not in CHOICES]
    if unknown or not job.methods:
        raise UsageProblem(f"--methods: unknown method {unknown[0] if unknown else '(none)'!r}; "
                           f"choose from {', '.join(CHOICES)}")
    if job.out is not None:
        refuse_overwrite([os.path.join(job.out, name) for name in BENCH_FILES], mesh=job.mesh,
                         handles=job.handles)
        for name in BENCH_FILES:  # checked, not made: the commit makes it at the end
            check_output_path(os.path.join(job.out, name), None, "-o")
    source = read_mesh(job.mesh)
    check_solve(job.mesh, len(source.vertices))
    constraints = load_handles(job.handles, source.vertices, any_rate=True)
    opts = resolve(constraints.solver, OWN_DEFAULTS, dict(job.settings))
    p = problem(source, constraints, job.mesh)
    runs = run_methods(p.V, p.F, p.ids, p.targets, list(job.methods), settings=opts,
                       time_budget=job.time_budget)
    if on_table is not None:
        on_table(table(runs))
    if job.out is not None:
        info = {"mesh": job.mesh, "handles": job.handles, "vertices": len(p.V),
                "constrained": len(p.ids), "time_budget": job.time_budget,
                **{k: getattr(opts, k) for k in ("alpha", "feedback", "weights", "sweeps")}}
        title = f"{os.path.basename(job.mesh)} ({len(p.V)} vertices)"
        payloads = (utf8(curves_csv(runs)), utf8(summary_json(runs, info)),
                    plot_png(runs, title))
        commit_files([(os.path.join(job.out, name), data)
                      for name, data in zip(BENCH_FILES, payloads)])
    return runs
