"""Many deformations from one manifest: up-to-date checks, parallel workers, a summary.

A manifest (YAML or JSON) lists jobs; paths are relative to the manifest::

    defaults: {method: sr-linear-sym, tol: 1.0e-6}      # solver settings for every job
    jobs:
      - name: bar-twist
        mesh: ../sample_meshes/bar.obj
        handles: ../configs/bar-twist.yaml
        output: bar-twist.obj                           # relative to the output folder
        settings: {max_iter: 500}                       # this job only
        expect: {golden: golden/bar-twist.obj, tol: 1.0e-9, relative: true}

A job is up to date when its output exists and the sidecar ``<output>.srarap.json`` records
the same fingerprint (content of the mesh, the handle file and every file it names, settings,
srarap version).
"""
import functools
import hashlib
import json
import os
import time
from importlib import metadata
from typing import Any

from ..io.handles import load_handles, referenced_files
from ..io.input_files import read_input_bytes
from ..io.mesh import format_mesh, read_mesh
from ..runtime import exit_codes
from ..runtime.commit import commit_files
from ..runtime.errors import InputError, NumericalError, SingularSystemError
from ..runtime.signals import Terminated
from ..solver.settings import resolve
from ..solver.stop import StopReason
from .batch_dask import run_on_dask
from .batch_rows import BatchInterrupted, Job, Row, interrupted_row, lost_row
from .compare import beyond, compare_meshes
from .job_pictures import difference_picture, energy_picture, shape_picture
from .pipeline import deform_mesh
from .report import EXIT_CODES, encode_png
from .worker_pool import PoolStopped, run_in_processes


def fingerprint(job: Job) -> str:
    """Content hash of everything that decides a job's output."""
    h = hashlib.sha256()
    for path in (job["mesh"], job["handles"], *referenced_files(job["handles"])):
        try:
            h.update(hashlib.sha256(read_input_bytes(path)).digest())
        except InputError:
            h.update(b"missing:" + path.encode())
    h.update(json.dumps([job["settings"], job["output"], metadata.version("srarap-cli")],
                        sort_keys=True).encode())
    return h.hexdigest()


def run_job(job: Job, out_dir: str, keep_unconverged: bool = False,
            pictures: bool = False) -> Row:
    """Run one job; never raises. Returns its summary row (dict with SUMMARY_FIELDS; with
    ``pictures``, also ``pictures``: the report's pictures of the job, see
    :func:`job_pictures`).

    A job that does not converge writes its sidecar (the status, so a rerun reports it without
    solving again) but not its mesh, unless ``keep_unconverged``: as ``srarap deform``."""
    start = time.perf_counter()
    row = {"job": job["name"], "status": "failed", "stop": "", "iterations": None,
           "energy": None, "seconds": None, "compare_max": None, "message": "",
           "compare_mean": None, "tol": None, "exit_code": None}
    seen: dict[str, Any] = {}  # what the pictures are drawn from
    out = os.path.join(out_dir, job["output"])
    sidecar = out + ".srarap.json"
    try:
        key = fingerprint(job)
        recorded = _recorded_row(sidecar) if _recorded(sidecar) == key else None
        if recorded is not None and (os.path.exists(out) or (
                recorded["status"] == "not-converged" and not keep_unconverged)):
            # an unchanged job that did not converge stays not converged, run after run
            row.update(recorded, status="up-to-date" if recorded["status"] == "ok" else
                       recorded["status"])
            if row["status"] != "up-to-date":
                row["message"] = "inputs unchanged since the recorded run"
        else:
            mesh = read_mesh(job["mesh"])
            constraints = load_handles(job["handles"], mesh.vertices)
            opts = resolve(constraints.solver, job["settings"])
            deformed, result, _ = deform_mesh(mesh, constraints, opts, name=job["mesh"])
            seen.update(mesh=mesh, deformed=deformed, constraints=constraints, log=result.log)
            data, _ = format_mesh(deformed, os.path.splitext(out)[1].lower())
            status = "ok" if result.complete else "not-converged"
            stop = result.stop_reason.value
            row.update(status=status, stop=stop, iterations=result.iterations,
                       energy=result.energy)
            os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
            record = json.dumps({"fingerprint": key, "iterations": result.iterations,
                                 "energy": result.energy, "status": status,
                                 "stop": stop}).encode()
            keep = status == "ok" or keep_unconverged
            commit_files([(out, data)] * keep + [(sidecar, record)])
            if not keep:
                row["message"] = "mesh not written (--keep-unconverged writes it)"
        if job["expect"] is not None and os.path.exists(out) and row["status"] != "not-converged":
            seen["golden"] = _check_golden(row, job["expect"], out)
    except Exception as exc:  # noqa: BLE001 -- a failing job is reported, never fatal
        row.update(status="failed", message=str(exc).splitlines()[0] if str(exc) else
                   type(exc).__name__, exit_code=_failure_code(exc))
        if isinstance(exc, NumericalError):
            row["stop"] = StopReason.NON_FINITE.value
    if row["exit_code"] is None:
        row["exit_code"] = EXIT_CODES.get(row["status"])
    row["seconds"] = time.perf_counter() - start
    if pictures:  # after the seconds: the solve's, not the drawing's
        row["pictures"] = job_pictures(job, out, seen)
    return row


def _failure_code(exc):
    """The exit code ``srarap deform`` gives for the failure ``exc``."""
    if isinstance(exc, InputError):
        return exit_codes.INVALID_INPUT
    if isinstance(exc, (NumericalError, SingularSystemError)):
        return exit_codes.NUMERICAL_FAILURE
    if isinstance(exc, OSError):
        return exit_codes.OUTPUT_ERROR
    return 1


def job_pictures(job: Job, out: str, seen: dict[str, Any]) -> dict[str, str]:
    """The report's pictures of a job (base64 PNG by name: ``shape``, ``difference``,
    ``energy``), drawn from what the job solved or, for one up to date, from its files;
    those without their data are left out (a failed job's, a missing golden's); a drawing
    that fails leaves ``note`` instead, which the report shows."""
    out_pictures: dict[str, str] = {}
    try:
        mesh = seen["mesh"] if "mesh" in seen else read_mesh(job["mesh"])
        deformed = seen.get("deformed")
        if deformed is None and os.path.exists(out):
            deformed = read_mesh(out)
        if deformed is None or len(deformed.vertices) != len(mesh.vertices):
            return out_pictures
        constraints = (seen["constraints"] if "constraints" in seen
                       else load_handles(job["handles"], mesh.vertices, any_rate=True))
        out_pictures["shape"] = encode_png(shape_picture(mesh, deformed, constraints))
        golden = seen.get("golden")
        if golden is not None:
            figures, expect = golden
            scale = figures["diagonal"] if expect["relative"] and figures["diagonal"] > 0 \
                else 1.0
            d = figures["distances"]
            d = d if figures["mode"] == "per-vertex" else d[-len(deformed.vertices):]
            out_pictures["difference"] = encode_png(
                difference_picture(mesh, deformed, d, expect["tol"], scale))
        if seen.get("log"):
            out_pictures["energy"] = encode_png(energy_picture(seen["log"]))
    except Exception as exc:  # noqa: BLE001 -- the report says why, the job's result stands
        out_pictures["note"] = f"pictures not drawn: {type(exc).__name__}: {exc}"
    return out_pictures


def _check_golden(row, expect, out):
    """Compare the job's output with its golden mesh into ``row``; returns the figures and
    ``expect`` (for the report's difference picture)."""
    figures = compare_meshes(read_mesh(expect["golden"]), read_mesh(out))
    scale = figures["diagonal"] if expect["relative"] and figures["diagonal"] > 0 else 1.0
    row.update(compare_max=figures["max"] / scale, compare_mean=figures["mean"] / scale,
               tol=expect["tol"])
    if row["compare_max"] > expect["tol"]:
        row["status"] = "regressed"
        far = figures["where"]
        at = "" if far is None else (f" at vertex {far['vertex']} of the "
                                     f"{'golden' if far['mesh'] == 'a' else 'output'} mesh")
        row["message"] = (f"max distance {row['compare_max']:.3g} > tol {expect['tol']:g}"
                          f"{at}; {100 * beyond(figures, expect['tol'], expect['relative']):.3g}"
                          "% of the vertices beyond tol")
    return figures, expect


def _recorded(sidecar):
    try:
        with open(sidecar) as fh:
            rec = json.load(fh)
        # a record without a status predates status records: run the job again
        return rec.get("fingerprint") if "status" in rec else None
    except (OSError, ValueError):
        return None


def _recorded_row(sidecar):
    with open(sidecar) as fh:
        rec = json.load(fh)
    return {"iterations": rec.get("iterations"), "energy": rec.get("energy"),
            "status": rec["status"], "stop": rec.get("stop", "")}


def run_batch(jobs: list[Job],
              out_dir: str, workers: int = 1, scheduler: str | None = None, keep_unconverged: bool = False,
              pictures: bool = False) -> list[Row]:
    """Run jobs: on a Dask cluster at ``scheduler``, else in ``workers`` local processes
    (in this process when 1). Rows come back in manifest order. ``keep_unconverged``: see
    :func:`run_job`.

    The Dask workers must see the same files as this process (a shared file system).
    """
    run = functools.partial(run_job, out_dir=out_dir, keep_unconverged=keep_unconverged,
                            pictures=pictures)
    if scheduler is not None:
        return run_on_dask(jobs, run, scheduler, workers)
    if workers <= 1:
        rows: list[Row] = []
        try:
            for job in jobs:
                rows.append(run(job))
        except (KeyboardInterrupt, Terminated) as exc:
            raise BatchInterrupted(rows + [interrupted_row(j) for j in jobs[len(rows):]],
                                   exc) from None
        return rows
    return _run_in_processes(jobs, run, workers)


def _run_in_processes(jobs, run, workers):
    """Jobs in ``workers`` processes (:mod:`.worker_pool`), rows in manifest order; a signal
    raises :class:`BatchInterrupted` with the rows of the jobs that finished."""
    try:
        return run_in_processes(jobs, run, workers, lost_row)
    except PoolStopped as exc:
        raise BatchInterrupted([exc.rows.get(k) or interrupted_row(job)
                                for k, job in enumerate(jobs)], exc.signal) from None


