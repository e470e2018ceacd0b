"""``srarap bench``: every method on one problem, compared on wall time to a given energy."""
import os
from typing import Any

import click

from ..io.handles import load_handles
from ..io.mesh import read_mesh
from ..runtime.commit import commit_files
from ..runtime.encoding import utf8
from ..runtime.limits import check_solve
from ..solver.settings import resolve
from ..tasks.bench import ALL_METHODS, IGL, run_methods
from ..tasks.bench_report import curves_csv, plot_png, summary_json, table
from ..tasks.pipeline import problem
from ..tasks.preflight import check_output_path, refuse_overwrite
from .common import FiniteFloat, guarded, write_stdout
from .options import settings_options

CHOICES = ALL_METHODS + (IGL,)
# bench measures how fast each method approaches the minimum, so it runs far past the usual
# stopping point unless told otherwise (the handle file's tol and max_iter do not apply)
OWN_DEFAULTS = {"tol": 1e-9, "max_iter": 100000}
BENCH_FILES = ("curves.csv", "summary.json", "energy.png")


@click.command("bench")
@click.argument("mesh")
@click.argument("handles")
@click.option("--methods", default=",".join(CHOICES), show_default=True,
              help=f"Comma-separated, from: {', '.join(CHOICES)}.")
@click.option("--time-budget", type=FiniteFloat(min=0, min_open=True), default=30.0,
              show_default=True, help="Seconds each method may run.")
@click.option("-o", "--output", "out",
              help="Folder for curves.csv, summary.json and energy.png (created if missing).")
@settings_options(exclude=("method", "multires", "multires_mode", "time_limit", "accel", "start",
                           "strict", "allow"),
               defaults=OWN_DEFAULTS)
@guarded
def bench(mesh: str, handles: str, methods: str, time_budget: float, out: str | None,
          overrides: dict[str, Any]) -> None:
    """Run each method on MESH + HANDLES from the same start and compare them.

    Reports per-iteration time, iterations and seconds to come within 1% and 0.1% of the lowest
    SR energy reached, final energy and constraint error; libigl's ARAP is timed in the same run.
    Methods stop at --tol, --max-iter or the time budget.
    """
    names = [m.strip() for m in methods.split(",") if m.strip()]
    unknown = [m for m in names if m not in CHOICES]
    if unknown or not names:
        raise click.BadParameter(f"unknown method {unknown[0] if unknown else '(none)'!r}; "
                                 f"choose from {', '.join(CHOICES)}", param_hint="--methods")
    if out is not None:
        refuse_overwrite([os.path.join(out, name) for name in BENCH_FILES], mesh=mesh,
                         handles=handles)
        for name in BENCH_FILES:  # checked, not made: the commit makes it at the end
            check_output_path(os.path.join(out, name), None, "-o")
    source = read_mesh(mesh)
    check_solve(mesh, len(source.vertices))
    constraints = load_handles(handles, source.vertices, any_rate=True)
    opts = resolve(constraints.solver, OWN_DEFAULTS, overrides)
    p = problem(source, constraints, mesh)
    runs = run_methods(p.V, p.F, p.ids, p.targets, names, settings=opts,
                       time_budget=time_budget)
    write_stdout(utf8(table(runs)))
    if out is not None:
        info = {"mesh": mesh, "handles": handles, "vertices": len(p.V),
                "constrained": len(p.ids), "time_budget": time_budget,
                **{k: getattr(opts, k) for k in ("alpha", "feedback", "weights", "sweeps")}}
        title = f"{os.path.basename(mesh)} ({len(p.V)} vertices)"
        payloads = (utf8(curves_csv(runs)), utf8(summary_json(runs, info)),
                    plot_png(runs, title))
        commit_files([(os.path.join(out, name), data)
                      for name, data in zip(BENCH_FILES, payloads)])
