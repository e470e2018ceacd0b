"""``srarap bench``: every method on one problem, compared on wall time to a given energy."""
from typing import Any

import click

from ..runtime.encoding import utf8
from ..tasks.bench import CHOICES, OWN_DEFAULTS, BenchJob, run_bench
from .common import FiniteFloat, guarded, write_stdout
from .options import settings_options


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
    names = tuple(m.strip() for m in methods.split(",") if m.strip())
    run_bench(BenchJob(mesh, handles, names, time_budget, out, overrides),
              on_table=lambda text: write_stdout(utf8(text)))
