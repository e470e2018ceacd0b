"""One deformation job, files in and files out: the path ``srarap deform`` and every job of
``srarap batch`` take, so that both check, warn, fail and write alike.

:func:`run_job` checks the outputs, reads the mesh and the handle file, solves, encodes,
commits every file at once and compares with a golden mesh; it returns a :class:`JobResult`
(or raises, for the command line to map to its exit code). :func:`run_job_safely` never
raises: a failure is a result with status ``failed`` and the exit code ``srarap deform``
gives for it (:func:`srarap_cli.runtime.failures.classify`).
"""
import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ...io.documents import load_document
from ...io.handles import solver_settings
from ...io.mesh.formats import FORMATS, MeshFormat, by_extension, extensions
from ...io.solve_log import LOG_FORMATS, format_log
from ...runtime import descriptors, memory
from ...runtime.commit import commit_files
from ...runtime.encoding import utf8
from ...runtime.errors import InputError, NumericalError, OutputError, UsageProblem
from ...runtime.failures import classify
from ...runtime.limits import check_solve
from ...runtime.stages import begun as stage_begun
from ...runtime.stages import ended as stage_ended
from ...runtime.stages import forget as forget_stages
from ...solver.settings import resolve
from ...solver.stop import StopReason
from ..comparison import Expect
from ..distortion import vertex_distortion
from ..fingerprint import fingerprint
from ..info import up_axis
from ..job_status import JobResult, JobStatus, Seen
from ..pictures import preview_png
from ..pipeline import deform_mesh, refuse_warnings
from ..preflight import check_output_path, load_posed, read_any_mesh, refuse_overwrite
from .golden import check_golden
from .record import input_bytes, read_record, record_bytes, sidecar_path

__all__ = ["DeformJob", "JobResult", "JobStatus", "recorded_result", "run_job",
           "run_job_safely"]


@dataclass(frozen=True)
class DeformJob:
    """What one deformation reads and writes.

    Attributes
    ----------
    mesh, handles : str, input paths (``mesh`` ``-``: standard input)
    output : str, the mesh to write (``-``: standard output)
    settings : mapping, solver settings over the handle file's (``max_iter``, ``strict``...)
    name : str, the job's name in a batch's summary
    input_format, output_format : MeshFormat, optional, for a mesh on a stream
    ascii, write_distortion : bool, the output's variant and its ``distortion`` property
    log, preview : str, optional, the energy log (.csv/.jsonl) and a PNG to write too
    preview_up : str, the axis drawn upward in the preview (``auto``: guessed)
    keep_unconverged : bool, write the mesh of a solve that did not converge
    cache : str, optional, folder of simplified meshes (multiresolution)
    fps, frame : the pose of keyframed groups
    expect : Expect or mapping, optional, the golden (path) and the gates it must pass (see
        :class:`~srarap_cli.tasks.comparison.gates.Expect`): compare with it
    goldens : {"check", "update", "accept"}, what to do with a missing or regressed golden
        (see :data:`..comparison.goldens.GOLDEN_MODES`)
    golden_root : str, optional, the folder goldens may be written in (a batch: the
        manifest's)
    record : bool, keep a record beside the output and take an unchanged job's result from
        it without solving (batches)
    inside : str, optional, a folder every file the job writes must stay in, symbolic links
        followed, at the moment it is written (a batch's ``-o``)
    """

    mesh: str
    handles: str
    output: str
    settings: Mapping[str, Any] = field(default_factory=dict)
    name: str = ""
    input_format: MeshFormat | None = None
    output_format: MeshFormat | None = None
    ascii: bool = False
    write_distortion: bool = False
    log: str | None = None
    preview: str | None = None
    preview_up: str = "auto"
    keep_unconverged: bool = False
    cache: str | None = None
    fps: float | None = None
    frame: float = 0.0
    expect: Expect | Mapping[str, Any] | None = None
    goldens: str = "check"
    golden_root: str | None = None
    record: bool = False
    inside: str | None = None


def run_job(job: DeformJob, callback: Callable[[dict], None] | None = None,
            write_stdout: Callable[[bytes], None] | None = None,
            on_warnings: Callable[[list[str]], None] | None = None) -> JobResult:
    """Run ``job``; raise on failure (InputError, OutputError, NumericalError, ...).

    ``callback`` receives each log row of the solve; ``write_stdout`` takes the mesh's bytes
    when the output is ``-`` (before any file is committed); ``on_warnings`` hears the
    warnings known before the setup and before the solve, as they are known (the result
    holds them all). The result's ``status`` is ``ok``, ``up-to-date``, ``not-converged``
    or ``regressed``.
    """
    start = time.perf_counter()
    fmt = _preflight(job)
    key = _key(job) if job.record else None  # of the inputs as they were when the job began
    result = recorded_result(job, key) if key is not None else None
    if result is None:
        result = _solve(job, fmt, callback, write_stdout, key, on_warnings)
    if job.expect is not None and result.status is not JobStatus.NOT_CONVERGED \
            and os.path.exists(job.output):
        result.seconds = time.perf_counter() - start  # what a seconds gate judges
        check_golden(result, job.expect, job.output, job.goldens, job.golden_root)
    result.seconds = time.perf_counter() - start
    return result


def run_job_safely(job: DeformJob, **kwargs: Any) -> JobResult:
    """:func:`run_job`, with a failure returned as a ``failed`` result, never raised."""
    start = time.perf_counter()
    try:
        return run_job(job, **kwargs)
    except Exception as exc:  # noqa: BLE001 -- a failing job is reported, never fatal
        code, text = classify(exc)
        return JobResult(job.name, JobStatus.FAILED, code, message=text.splitlines()[0]
                         if text else type(exc).__name__,
                         stop=StopReason.NON_FINITE.value if isinstance(exc, NumericalError)
                         else "", seconds=time.perf_counter() - start)


def _preflight(job):
    """Check the outputs before any work; the output's format (None: standard input's)."""
    fmt = _output_format(job)
    if fmt is not None:
        _check_format_options(fmt, job)
    if job.output != "-":  # an extension the table knows, or --format for a name without one
        check_output_path(job.output, None if by_extension(job.output) is None
                          and job.output_format else extensions(), "output")
    elif descriptors.closed(1):
        raise OutputError("-o -: standard output is closed; name an output file")
    if job.preview is not None:
        check_output_path(job.preview, (".png",), "preview")
    if job.log is not None:
        check_output_path(job.log, LOG_FORMATS, "log")
        if os.path.abspath(job.log) == os.path.abspath(job.output):
            raise UsageProblem("--log and --output name the same file")
    refuse_overwrite([job.output, job.log, job.preview], mesh=job.mesh, handles=job.handles)
    return fmt


def _output_format(job):
    """``--format``, or the output's extension; for ``-o -`` without ``--format``, the input
    file's, or None for standard input (its bytes decide)."""
    if job.output == "-":
        return job.output_format or (None if job.mesh == "-" else by_extension(job.mesh))
    fmt = by_extension(job.output)
    if job.output_format is not None and fmt is not None and fmt is not job.output_format:
        raise UsageProblem(f"--format {job.output_format.name} does not match the output "
                           f"{job.output!r}")
    return fmt or job.output_format


def _check_format_options(fmt, job):
    def having(attribute):
        return "/".join(f.name.upper() for f in FORMATS.values() if getattr(f, attribute))

    if job.ascii and not fmt.has_ascii:
        raise UsageProblem(f"--ascii applies to {having('has_ascii')} output only")
    if job.write_distortion and not fmt.keeps_vertex_data:
        raise UsageProblem(f"--write-distortion needs a {having('keeps_vertex_data')} output")


def _key(job):
    """The job's fingerprint (:mod:`..fingerprint`): its inputs, its settings resolved over
    the handle file's (a default written out changes nothing), and what it writes."""
    try:
        settings = resolve(solver_settings(job.handles), job.settings)
    except (ValueError, KeyError):  # the run says what is wrong: no record fits it
        return None
    return fingerprint(input_bytes(job.mesh, job.handles), settings, {
        "output": os.path.basename(job.output),
        "format": None if job.output_format is None else job.output_format.name,
        "ascii": job.ascii, "distortion": job.write_distortion, "log": job.log,
        "preview": job.preview, "preview_up": job.preview_up})


def recorded_result(job: DeformJob, key: str | None = None) -> JobResult | None:
    """The result an unchanged job's record gives, or None (the job runs); ``key``: the
    job's fingerprint, when already computed."""
    rec = read_record(sidecar_path(job.output), key or _key(job))
    if rec is None:
        return None
    status = JobStatus(rec["status"])
    if status is JobStatus.OK and os.path.exists(job.output):
        status = JobStatus.UP_TO_DATE
    elif not (status is JobStatus.NOT_CONVERGED and not job.keep_unconverged):
        return None  # the output is gone, or this run writes what that one did not
    result = JobResult(job.name, status, status.exit_code, warnings=rec["warnings"],
                       stop=rec["stop"] or "", iterations=rec["iterations"],
                       energy=rec["energy"], solved=False,
                       message="" if status is JobStatus.UP_TO_DATE
                       else "inputs unchanged since the recorded run",
                       seen=Seen(recorded_seconds=rec["seconds"]))
    return _judged(job, result)


def _judged(job, result):
    """An unchanged job's recorded warnings judged under this run's strictness, which is not
    in the fingerprint (it decides nothing in the mesh): ``failed`` with the line ``--strict``
    gives where it fails them, the files of the recorded run left as they are."""
    try:
        refuse_warnings(_strictness(job), result.warnings)
    except InputError as exc:
        code, text = classify(exc)
        result.status, result.exit_code, result.message = JobStatus.FAILED, code, text
    return result


def _strictness(job):
    """The settings ``strict`` and ``allow`` come from: the handle file's ``solver`` block
    under the job's settings, as a solve resolves them."""
    try:
        doc = load_document(job.handles, "yaml")
        solver = doc.get("solver") if isinstance(doc, dict) else None
        return resolve(solver if isinstance(solver, dict) else {}, dict(job.settings))
    except (InputError, ValueError, TypeError):  # not a YAML handle file: the job's alone
        return resolve(dict(job.settings))


def _solve(job, fmt, callback, write_stdout, key, on_warnings=None):
    peaks: dict[str, int | None] = {}
    peak, mark = memory.start(), time.perf_counter()
    started = mark
    forget_stages()  # a job before this one in the process that failed left its own
    stage_begun("read")
    source, source_format = read_any_mesh(job.mesh, job.input_format)
    peaks["read"] = memory.stop(peak)
    stage_ended("read", time.perf_counter() - mark)
    if fmt is None:
        fmt = source_format
        _check_format_options(fmt, job)
    name = "<stdin>" if job.mesh == "-" else job.mesh
    check_solve(name, len(source.vertices))
    constraints = load_posed(job.handles, source.vertices, job.fps, job.frame)
    opts = resolve(constraints.solver, dict(job.settings))
    peak = memory.start()
    deformed, solve, notes = deform_mesh(source, constraints, opts, callback=callback,
                                         cache=job.cache, name=name, on_warnings=on_warnings)
    peaks["solve"], peak, mark = memory.stop(peak), memory.start(), time.perf_counter()
    stage_begun("write")
    if job.write_distortion:
        deformed.vertex_data["distortion"] = vertex_distortion(
            source.vertices, deformed.vertices, source.triangles()[0])
    status = JobStatus.OK if solve.complete else JobStatus.NOT_CONVERGED
    keep = solve.complete or job.keep_unconverged
    # a mesh that is not written is not encoded: neither its format's losses nor a full
    # temporary folder (meshio's formats) concern a run that ends "not converged"
    mesh_bytes, lost = fmt.encode(deformed, job.ascii) if keep else (b"", [])
    refuse_warnings(opts, lost)
    files = _files(job, keep, mesh_bytes, deformed, source, constraints, solve)
    if key is not None:
        files.append((sidecar_path(job.output), record_bytes(
            key, status.value, solve.iterations, solve.energy, solve.stop_reason.value,
            notes + lost, time.perf_counter() - started)))
    if keep and job.output == "-" and write_stdout is not None:
        write_stdout(mesh_bytes)  # first: the files are committed only once it was written
    commit_files(files, inside=job.inside)
    peaks["write"] = memory.stop(peak)
    stage_ended("write", time.perf_counter() - mark)
    return JobResult(job.name, status, status.exit_code, warnings=notes + lost,
                     stop=solve.stop_reason.value, iterations=solve.iterations,
                     energy=solve.energy, solved=True,
                     message="" if keep else "mesh not written (--keep-unconverged writes it)",
                     written=job.output if keep else None, peaks=peaks, solve=solve,
                     settings=opts, seen=Seen(mesh=source, deformed=deformed,
                                               constraints=constraints, log=solve.log))


def _files(job, keep, mesh_bytes, deformed, source, constraints, solve):
    """The files a job commits together: the mesh, its preview and the log."""
    files = [(job.output, mesh_bytes)] if keep and job.output != "-" else []
    if job.preview is not None and keep:
        up = up_axis(source) if job.preview_up == "auto" else job.preview_up
        files.append((job.preview, preview_png(deformed, source, constraints, view="iso",
                                               up=up)))
    if job.log is not None:
        files.append((job.log, utf8(format_log(solve.log,
                                               os.path.splitext(job.log)[1].lower()))))
    return files
