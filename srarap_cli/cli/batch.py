"""``srarap batch``: run a manifest of deformations, skipping what is up to date."""
import os
import re
import shlex

import click

from ..runtime import exit_codes
from ..runtime.signals import Terminated
from ..solver.settings import BY_NAME
from ..tasks.batch import BatchJob, run_batch
from ..tasks.job_status import JobStatus
from .common import guarded, printable, say
from .options import StrictCommand, ThreadCount, setting_option
from .progress import job_heartbeat

#: a Dask scheduler address: protocol://host:port, or host:port
SCHEDULER = re.compile(r"(?:[a-z][a-z0-9+.-]*://)?[^\s:/]+:\d{1,5}")


@click.command("batch", cls=StrictCommand)
@click.argument("manifest")
@click.option("--workers", type=click.IntRange(min=1), default=1, show_default=True,
              help="Worker processes.")
@click.option("--scheduler", help="Run the jobs on Dask (pip install 'srarap-cli[dask]'): "
              "'local' starts --workers single-threaded worker processes here; an address "
              "('tcp://host:8786') uses that cluster, whose workers must share this file "
              "system and should run one thread each (dask worker --nthreads 1) with "
              "OPENBLAS_NUM_THREADS=1 and Dask's profiler off (see the workflows guide).")
@click.option("-o", "--output", "out", default=".", show_default=True,
              help="Folder for the jobs' outputs and summary.csv / summary.json.")
@click.option("--keep-unconverged", is_flag=True,
              help="Write the mesh of a job that did not converge (exit code still 3).")
@click.option("--report", help="Also write an HTML report (one self-contained file: each job's "
              "numbers, a picture of its shape, its difference to the golden mesh and its "
              "energy curve, drawn by the workers; failures and regressions first).")
@click.option("--junit", help="Also write JUnit XML (one test case per job) for CI systems.")
@click.option("--summary-md", "markdown", metavar="FILE", help="Also write a Markdown summary "
              "(a table, failures first) for a GitHub job summary ($GITHUB_STEP_SUMMARY).")
@click.option("--metrics", metavar="FILE", help="Also write the jobs' figures as OpenMetrics "
              "(GitLab's metrics report, metrics.txt): iterations, seconds, energy, distances.")
@click.option("--update-goldens", is_flag=True, help="Write the golden of every job that has "
              "none or regressed from this run's output (the others are left untouched); "
              "the run still exits 8: review what was written.")
@click.option("--accept-goldens", is_flag=True, help="As --update-goldens, and those jobs "
              "pass: the new results are the truth.")
@click.option("--threads", type=ThreadCount(), metavar="N",
              help="Threads for each job's solve, at most the CPUs divided by --workers. "
              "[default: $SRARAP_THREADS, else the CPUs divided by --workers]")
@setting_option(BY_NAME["strict"])
@setting_option(BY_NAME["allow"])
@click.option("-q", "--quiet", is_flag=True, help="No summary table.")
@guarded
def batch(manifest: str, workers: int, scheduler: str | None, out: str, keep_unconverged: bool,
          report: str | None, junit: str | None, markdown: str | None, metrics: str | None,
          update_goldens: bool, accept_goldens: bool, threads: int | None,
          strict: str | None, allow: tuple[str, ...] | None, quiet: bool) -> None:
    """Run every job of MANIFEST (YAML/JSON); a failing job never stops the others.

    Exit code 0 when every job is ok or up to date, 8 when any job failed, regressed against
    its golden mesh or has no golden (--update-goldens writes it), else 3 when any did not
    converge (its mesh is not written unless --keep-unconverged; the status is recorded, so
    an unchanged job reports it again on every rerun without solving). --strict and --allow
    are each job's, over the manifest's.
    """
    if scheduler is not None and scheduler != "local" and not SCHEDULER.fullmatch(scheduler):
        raise click.BadParameter(f"{scheduler!r} is neither 'local' nor a scheduler address "
                                 "such as tcp://host:8786", param_hint="--scheduler")
    goldens = "accept" if accept_goldens else "update" if update_goldens else "check"
    done = run_batch(BatchJob(
        manifest, out, workers=workers, scheduler=scheduler, keep_unconverged=keep_unconverged,
        goldens=goldens, threads=threads, settings={"strict": strict or None,
                                                    "allow": allow or None},
        report=report, junit=junit, markdown=markdown, metrics=metrics,
        heartbeat=None if quiet else job_heartbeat))
    _tell(done.rows, out, quiet, done.stopped)
    _tell_goldens(done.rows, manifest, out, goldens)
    if done.failure is not None:
        raise done.failure
    if done.stopped is not None:
        raise SystemExit(exit_codes.TERMINATED if isinstance(done.stopped, Terminated)
                         else exit_codes.INTERRUPTED)
    if done.exit_code:
        raise SystemExit(done.exit_code)


def _tell(rows, out, quiet, stopped):
    """The console table (one line a job: its status, seconds, warnings and message, the
    name printed escaped) and the summary line."""
    counts = {s: sum(r.status is s for r in rows) for s in JobStatus}
    if quiet and stopped is None:
        return
    for r in rows if not quiet else ():
        warned = f"  {len(r.warnings)} warning(s)" if r.warnings else ""
        extra = f"  {printable(r.message)}" if r.message else ""
        seconds = "" if r.seconds is None else f"{r.seconds:8.2f} s"
        say(f"{printable(r.job):24} {r.status.value:13} {seconds:>10}{warned}{extra}")
    summary = ", ".join(f"{v} {k.value}" for k, v in counts.items() if v)
    warned = sum(bool(r.warnings) for r in rows)
    if warned:
        summary += f" ({warned} with warnings: see the summary's warnings column)"
    note = (" (nothing to solve: all up to date)"
            if counts[JobStatus.UP_TO_DATE] == len(rows) else "")
    if stopped is not None:
        word = "terminated" if isinstance(stopped, Terminated) else "interrupted"
        note = (f"; {word}: the jobs not finished are marked interrupted in "
                f"{os.path.join(out, 'summary.csv')}")
    say(f"srarap batch: {len(rows)} jobs: {summary}{note}")


def _tell_goldens(rows, manifest, out, goldens):
    """What became of the goldens: the command that creates the missing ones, or those this
    run wrote (said even with -q: a golden written or missing is never silent)."""
    written = [r for r in rows if r.golden]
    missing = [r for r in rows if r.status is JobStatus.NO_GOLDEN and not r.golden]
    if missing:
        command = shlex.join(["srarap", "batch", manifest, "-o", out, "--update-goldens"])
        say(f"srarap batch: {len(missing)} job(s) without a golden: {command} creates "
            f"{'it' if len(missing) == 1 else 'them'} from this run's outputs")
    if written:
        what = "; ".join(f"{action}: " + ", ".join(printable(r.job) for r in written
                                                  if r.golden == action)
                         for action in dict.fromkeys(r.golden for r in written))
        after = ("accepted as the truth" if goldens == "accept" else
                 "review them, then rerun (or --accept-goldens)")
        say(f"srarap batch: goldens written ({what}); {after}")
