"""``srarap bench``: every method on one problem, compared on wall time to a given energy."""
import os

import click

from ..bench import ALL_METHODS, IGL, run_methods
from ..bench_report import curves_csv, plot_png, summary_json, table
from ..errors import OutputError
from ..handles import load_handles
from ..limits import check_solve
from ..mesh_io import read_mesh
from ..mesh_io.commit import commit_files
from ..pipeline import problem, settings
from .common import guarded, solver_options

CHOICES = ALL_METHODS + (IGL,)


@click.command("bench")
@click.argument("mesh")
@click.argument("handles")
@click.option("--methods", default=",".join(CHOICES), show_default=True,
              help=f"Comma-separated, from: {', '.join(CHOICES)}.")
@click.option("--time-budget", type=click.FloatRange(min=0, min_open=True), default=30.0,
              show_default=True, help="Seconds each method may run.")
@click.option("-o", "--output", "out", type=click.Path(file_okay=False),
              help="Folder for curves.csv, summary.json and energy.png (created if missing).")
@solver_options
@guarded
def bench(mesh, handles, methods, time_budget, out, alpha, feedback, max_iter, tol, weights,
          sweeps):
    """Run each method on MESH + HANDLES from the same start and compare them.

    Reports per-iteration time, iterations and seconds to come within 1% and 0.1% of the lowest
    SR energy reached, final energy and constraint error; libigl's ARAP is timed in the same run.
    Methods stop at --tol (default here 1e-9), --max-iter or the time budget.
    """
    names = [m.strip() for m in methods.split(",") if m.strip()]
    unknown = [m for m in names if m not in CHOICES]
    if unknown or not names:
        raise click.BadParameter(f"unknown method {unknown[0] if unknown else '(none)'!r}; "
                                 f"choose from {', '.join(CHOICES)}", param_hint="--methods")
    if out is not None:
        _prepare_folder(out)
    source = read_mesh(mesh)
    check_solve(mesh, len(source.vertices))
    constraints = load_handles(handles, source.vertices)
    opts = settings(constraints.solver, {"alpha": alpha, "feedback": feedback,
                                         "weights": weights, "sweeps": sweeps})
    p = problem(source, constraints)
    runs = run_methods(p.V, p.F, p.ids, p.targets, names, settings=opts,
                       time_budget=time_budget, max_iter=max_iter or 100000,
                       tol=1e-9 if tol is None else tol, sweeps=opts["sweeps"])
    click.echo(table(runs), nl=False)
    if out is not None:
        info = {"mesh": mesh, "handles": handles, "vertices": len(p.V),
                "constrained": len(p.ids), "time_budget": time_budget,
                **{k: opts[k] for k in ("alpha", "feedback", "weights", "sweeps")}}
        title = f"{os.path.basename(mesh)} ({len(p.V)} vertices)"
        commit_files([(os.path.join(out, "curves.csv"), curves_csv(runs).encode()),
                      (os.path.join(out, "summary.json"), summary_json(runs, info).encode()),
                      (os.path.join(out, "energy.png"), plot_png(runs, title))])


def _prepare_folder(out):
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{out}: cannot create folder: {exc.strerror}") from None
