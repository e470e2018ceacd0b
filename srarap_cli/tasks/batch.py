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
import math
import os
import time
from importlib import metadata
from typing import Any

from ..io.documents import load_document
from ..io.handles import load_handles, referenced_files
from ..io.input_files import read_input_bytes
from ..io.mesh import format_mesh, read_mesh
from ..io.mesh.formats import extensions
from ..runtime import exit_codes
from ..runtime.commit import commit_files
from ..runtime.environment import environ_changed
from ..runtime.errors import InputError, NumericalError, SingularSystemError, excerpt
from ..runtime.paths import refuse_overwriting_inputs
from ..runtime.signals import Terminated
from ..runtime.threads import worker_processes
from ..solver.settings import parse_mapping, resolve
from ..solver.stop import StopReason
from .compare import beyond, compare_meshes
from .job_pictures import difference_picture, energy_picture, shape_picture
from .pipeline import deform_mesh
from .report import EXIT_CODES, encode_png
from .worker_pool import WORKER_START, PoolStopped, death_note, run_in_processes

JOB_KEYS = ("name", "mesh", "handles", "output", "settings", "expect")
#: ``stop``: the solve's :class:`~srarap_cli.solver.stop.StopReason` (empty for a job that
#: never reached the solver)
#: a job of a manifest: name, absolute paths, output, settings, expect
Job = dict[str, Any]
#: a job's summary row (keys SUMMARY_FIELDS)
Row = dict[str, Any]
SUMMARY_FIELDS = ("job", "status", "stop", "iterations", "energy", "seconds", "compare_max",
                  "message", "compare_mean", "tol", "exit_code")


def load_manifest(path: str) -> list[Job]:
    """Jobs of a manifest, with absolute paths and merged settings (list of dict)."""
    doc = load_document(path, "json" if path.lower().endswith(".json") else "yaml")
    if not isinstance(doc, dict) or not isinstance(doc.get("jobs"), list) or not doc["jobs"]:
        raise InputError(f"{path}: a manifest needs a non-empty 'jobs' list")
    base = os.path.dirname(os.path.abspath(path))
    defaults = _settings(path, "defaults", doc.get("defaults", {}))
    jobs, names, outputs = [], set(), set()
    for k, job in enumerate(doc["jobs"]):
        where = f"{path}: job {k}"
        if not isinstance(job, dict) or not {"mesh", "handles", "output"} <= set(job):
            raise InputError(f"{where}: needs mesh, handles and output")
        unknown = sorted(set(job) - set(JOB_KEYS))
        if unknown:
            raise InputError(f"{where}: unknown key {unknown[0]!r}")
        output = _output_name(where, job["output"])
        if output in outputs:
            raise InputError(f"{where}: output {output!r} is also another job's output")
        outputs.add(output)
        name = str(job.get("name", os.path.splitext(output)[0]))
        if name in names:
            raise InputError(f"{where}: job name {name!r} used twice")
        names.add(name)
        expect = job.get("expect")
        if expect is not None:
            if not isinstance(expect, dict) or "golden" not in expect:
                raise InputError(f"{where}: expect needs a golden mesh")
            tol = expect.get("tol", 0.0)
            if isinstance(tol, bool) or not isinstance(tol, (int, float)) \
                    or not math.isfinite(tol) or tol < 0:
                raise InputError(f"{where}: expect: tol must be a finite number >= 0")
            expect = {"golden": os.path.join(base, str(expect["golden"])),
                      "tol": float(tol),
                      "relative": bool(expect.get("relative", False))}
        jobs.append({"name": name, "mesh": os.path.join(base, str(job["mesh"])),
                     "handles": os.path.join(base, str(job["handles"])),
                     "output": output, "expect": expect,
                     "settings": {**defaults, **_settings(where, "settings",
                                                          job.get("settings", {}))}})
    return jobs


def _output_name(where, value):
    """A job's output as a relative path inside the output folder, with a mesh extension."""
    if not isinstance(value, str) or not value:
        raise InputError(f"{where}: output must be a file name")
    norm = os.path.normpath(value)
    if os.path.isabs(value) or norm == ".." or norm.startswith(".." + os.sep):
        raise InputError(f"{where}: output {excerpt(value)!r} must stay inside the output "
                         "folder (-o): no absolute path, no '..'")
    if os.path.splitext(norm)[1].lower() not in extensions():
        raise InputError(f"{where}: output {excerpt(value)!r} needs one of the extensions "
                         f"{', '.join(extensions())}")
    return norm


def check_outputs(jobs: list[Job],
                  out_dir: str, manifest: str) -> None:
    """Refuse a run whose outputs (or their sidecars) would land on any job's input or the
    manifest: a batch must never overwrite what it reads."""
    inputs = [("manifest", manifest)]
    for job in jobs:
        inputs += [(f"mesh of job {job['name']!r}", job["mesh"]),
                   (f"handle file of job {job['name']!r}", job["handles"]),
                   *((f"file named by job {job['name']!r}'s handles", path)
                     for path in referenced_files(job["handles"])),
                   *([(f"golden mesh of job {job['name']!r}", job["expect"]["golden"])]
                     if job["expect"] else [])]
    outputs = [os.path.join(out_dir, name) for job in jobs
               for name in (job["output"], job["output"] + ".srarap.json")]
    outputs += [os.path.join(out_dir, name) for name in ("summary.csv", "summary.json")]
    refuse_overwriting_inputs(outputs, inputs)


def _settings(where, key, spec):
    return parse_mapping(spec, key, lambda message: InputError(f"{where}: {message}"))


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
        return _run_on_dask(jobs, run, scheduler, workers)
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


class BatchInterrupted(BaseException):
    """SIGINT or SIGTERM stopped a batch: ``rows`` are the summary rows, in manifest order,
    of the jobs that finished and of the others (``status`` ``interrupted``); ``signal`` the
    exception the signal raised."""

    def __init__(self, rows: list[Row], signal: BaseException) -> None:
        super().__init__("interrupted")
        self.rows, self.signal = rows, signal


def interrupted_row(job: Job) -> Row:
    """The summary row of a job a signal stopped before it finished."""
    return {"job": job["name"], "status": "interrupted", "stop": "", "iterations": None,
            "energy": None, "seconds": None, "compare_max": None,
            "message": "not finished: the batch was interrupted", "compare_mean": None,
            "tol": None, "exit_code": EXIT_CODES["interrupted"]}


def _run_in_processes(jobs, run, workers):
    """Jobs in ``workers`` processes (:mod:`.worker_pool`), rows in manifest order; a signal
    raises :class:`BatchInterrupted` with the rows of the jobs that finished."""
    try:
        return run_in_processes(jobs, run, workers, _lost_row)
    except PoolStopped as exc:
        raise BatchInterrupted([exc.rows.get(k) or interrupted_row(job)
                                for k, job in enumerate(jobs)], exc.signal) from None


def _lost_row(job, exitcode):
    """The summary row of a job whose worker process died when it ran alone."""
    return _unfinished_row(job, death_note(exitcode),
                           128 - exitcode if exitcode < 0 else exitcode or 1)


def _unfinished_row(job, reason, exit_code):
    """The summary row of a job that failed without a row of its own (its process died)."""
    return {**interrupted_row(job), "status": "failed", "exit_code": exit_code,
            "message": f"not finished: {reason}"}


#: what srarap's own Dask workers get instead of Dask's defaults: one BLAS thread, and glibc's
#: dynamic malloc trimming (Dask's nanny sets MALLOC_TRIM_THRESHOLD_=65536, which turned each
#: solve's large temporaries into mmap/munmap pairs: system time 0.23 -> 4.5 s for 20 jobs)
WORKER_ENVIRON = {"OMP_NUM_THREADS": 1, "MKL_NUM_THREADS": 1, "OPENBLAS_NUM_THREADS": 1}
#: Dask settings for the workers srarap starts. They come from a fork server that imported
#: the jobs' code once: a spawned worker imports numpy, scipy, libigl and distributed again
#: (about 1.5 s for two), which made 20 jobs of 5k vertices take 4.7 s against 3.2 s with
#: --workers 2; forked from the batch itself they started at once, but beside the cluster's
#: threads (see :func:`..runtime.threads.worker_processes`). The rest wakes the workers less
#: often:
#: Dask's profiler samples the running task's stack every 10 ms (for a dashboard these
#: clusters do not have), event loops tick every 20 ms, monitors poll psutil 10 times a
#: second; on 2 cores each wake-up takes the core from a solve. With Dask's defaults a job
#: used 5.6% more CPU time in its thread than in a --workers 2 process; with these settings, 1%.
LOCAL_CONFIG = {"distributed.nanny.pre-spawn-environ": WORKER_ENVIRON,
                "distributed.worker.profile.enabled": False,
                "distributed.admin.tick.interval": "1s",
                "distributed.admin.system-monitor.interval": "5s",
                "distributed.worker.memory.monitor-interval": "1s",
                # one task per worker at a time: the death of a worker then counts against
                # the task it ran only (Dask's 1.1 queued a second one there, which failed
                # with it), and a task whose worker died runs once more, then fails (Dask's
                # default, 3 more times, ran a job too large for the machine into its limit
                # 4 times)
                "distributed.scheduler.worker-saturation": 1.0,
                "distributed.scheduler.allowed-failures": 1}


def _run_on_dask(jobs, run, scheduler, workers):
    """On the cluster at ``scheduler``, or on a local one of ``workers`` single-threaded
    worker processes when ``scheduler`` is ``local``."""
    try:
        import dask
        from distributed import LocalCluster
    except ImportError:
        raise InputError("--scheduler needs Dask: pip install 'srarap-cli[dask]'") from None
    run = functools.partial(run, out_dir=os.path.abspath(run.keywords["out_dir"]))
    if scheduler != "local":
        return _gather_at(scheduler, jobs, run, scheduler)
    # the cluster runs threads from its start: its workers come from a fork server
    with _without_dasks_trim_setting(), \
            worker_processes([WORKER_START, "distributed"], threads_ahead=True) as context:
        with dask.config.set({**LOCAL_CONFIG, "distributed.worker.multiprocessing-method":
                              context.get_start_method()}):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
        try:
            return _gather_at(cluster, jobs, run, scheduler)
        finally:
            cluster.close()


def _gather_at(cluster, jobs, run, scheduler):
    """The jobs' rows from ``cluster`` (an address or a cluster), which ``--scheduler
    scheduler`` named."""
    from distributed import Client

    try:
        return _gather(Client(cluster, timeout=30), jobs, run)
    except (OSError, TimeoutError) as exc:
        raise InputError(f"--scheduler {scheduler}: cannot connect ({exc})") from None


def _without_dasks_trim_setting():
    """A Dask nanny started earlier in this process left its MALLOC_TRIM_THRESHOLD_ in
    ``os.environ``, where new workers would inherit it: hold it back while they spawn."""
    left = os.environ.get("MALLOC_TRIM_THRESHOLD_") == "65536"
    return environ_changed({"MALLOC_TRIM_THRESHOLD_": None} if left else {})




def _silence_dask():
    """Dask's and asyncio's log lines while a cluster is stopped early (cancelled tasks,
    lost workers, the interrupted gather's tasks collected later) are not the user's
    concern: the summary says what finished. For the rest of the process, which is ending."""
    import logging
    for name in ("distributed", "asyncio"):
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)


def _gather(client, jobs, run):
    """The rows of ``jobs`` run on ``client``'s cluster. A job Dask gave up on (its worker
    died each time it ran it: Dask's KilledWorker) is a failed row, not the batch's end."""
    with client:
        futures = client.map(run, jobs, pure=False)
        rows = []
        try:
            # one at a time: a finished task whose worker died is computed again, and its
            # result() waits for that
            for future, job in zip(futures, jobs):
                rows.append(_dask_row(future, job))
        except (KeyboardInterrupt, Terminated) as exc:
            _silence_dask()
            rows = [f.result() if f.status == "finished" else interrupted_row(job)
                    for f, job in zip(futures, jobs)]
            client.cancel(futures)
            raise BatchInterrupted(rows, exc) from None
        return rows


def _dask_row(future, job):
    """The job's row from its task; a failed row when the task ended without one
    (``run_job`` itself never raises: its worker died, or the cluster lost it)."""
    import asyncio

    try:
        return future.result()
    except (Exception, asyncio.CancelledError) as exc:
        if type(exc).__name__ == "KilledWorker":
            reason = ("its worker process died each time Dask ran it (the system may have "
                      "run out of memory)")
        else:
            reason = f"Dask: {type(exc).__name__}: {(str(exc).splitlines() or [''])[0][:200]}"
        return _unfinished_row(job, reason, 1)
