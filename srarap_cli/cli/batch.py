"""``srarap batch``: run a manifest of deformations, skipping what is up to date."""
import csv
import io
import json
import os
import re

import click

from ..runtime import exit_codes
from ..runtime.commit import commit_files
from ..runtime.errors import OutputError
from ..runtime.signals import Terminated, block
from ..tasks.batch import run_batch
from ..tasks.batch_rows import SUMMARY_FIELDS, BatchInterrupted
from ..tasks.manifest import check_outputs, load_manifest
from ..tasks.report import junit_xml, report_html
from .common import check_output_path, guarded

#: a Dask scheduler address: protocol://host:port, or host:port
SCHEDULER = re.compile(r"(?:[a-z][a-z0-9+.-]*://)?[^\s:/]+:\d{1,5}")


@click.command("batch")
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
@click.option("-q", "--quiet", is_flag=True, help="No summary table.")
@guarded
def batch(manifest: str, workers: int, scheduler: str | None, out: str, keep_unconverged: bool,
          report: str | None, junit: str | None, quiet: bool) -> None:
    """Run every job of MANIFEST (YAML/JSON); a failing job never stops the others.

    Exit code 0 when every job is ok or up to date, 8 when any job failed or regressed
    against its golden mesh, else 3 when any did not converge (its mesh is not written unless
    --keep-unconverged; the status is recorded, so an unchanged job reports it again on every
    rerun without solving).
    """
    if scheduler is not None and scheduler != "local" and not SCHEDULER.fullmatch(scheduler):
        raise click.BadParameter(f"{scheduler!r} is neither 'local' nor a scheduler address "
                                 "such as tcp://host:8786", param_hint="--scheduler")
    if report is not None:
        check_output_path(report, (".html", ".htm"), "--report")
    if junit is not None:
        check_output_path(junit, (".xml",), "--junit")
    jobs = load_manifest(manifest)
    check_outputs(jobs, out, manifest)
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{out}: cannot create folder: {exc.strerror}") from None
    try:
        rows, stopped = run_batch(jobs, out, workers, scheduler, keep_unconverged,
                                  pictures=report is not None), None
    except BatchInterrupted as exc:  # the workers are stopped: say what finished
        rows, stopped = exc.rows, exc.signal
        # the summary is what is left to do: a second Ctrl-C or SIGTERM (a CI runner's
        # timeout sends more than one) must not cost it; the exit code says stopped anyway
        block()
    pictures = {r["job"]: r.pop("pictures", {}) for r in rows}
    files = [(os.path.join(out, "summary.csv"), _csv(rows).encode()),
             (os.path.join(out, "summary.json"), (json.dumps(rows, indent=2) + "\n").encode())]
    title = os.path.splitext(os.path.basename(manifest))[0]
    if report is not None:
        files.append((report, report_html(rows, pictures, f"srarap batch: {title}").encode()))
    if junit is not None:
        files.append((junit, junit_xml(rows, title).encode()))
    commit_files(files)
    counts = {s: sum(r["status"] == s for r in rows) for s in
              ("ok", "up-to-date", "not-converged", "regressed", "failed", "interrupted")}
    if not quiet or stopped is not None:
        for r in rows if not quiet else ():
            extra = f"  {r['message']}" if r["message"] else ""
            seconds = "" if r["seconds"] is None else f"{r['seconds']:8.2f} s"
            click.echo(f"{r['job']:24} {r['status']:13} {seconds:>10}{extra}", err=True)
        summary = ", ".join(f"{v} {k}" for k, v in counts.items() if v)
        note = " (nothing to solve: all up to date)" if counts["up-to-date"] == len(rows) else ""
        if stopped is not None:
            word = "terminated" if isinstance(stopped, Terminated) else "interrupted"
            note = (f"; {word}: the jobs not finished are marked interrupted in "
                    f"{os.path.join(out, 'summary.csv')}")
        click.echo(f"srarap batch: {len(rows)} jobs: {summary}{note}", err=True)
    if stopped is not None:
        raise SystemExit(exit_codes.TERMINATED if isinstance(stopped, Terminated)
                         else exit_codes.INTERRUPTED)
    if counts["failed"] or counts["regressed"]:
        raise SystemExit(exit_codes.BATCH_FAILED)
    if counts["not-converged"]:
        raise SystemExit(exit_codes.NOT_CONVERGED)

def _csv(rows):
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=SUMMARY_FIELDS, lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    return buf.getvalue()
