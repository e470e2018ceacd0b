"""``srarap deform``: mesh + handle file -> deformed mesh + energy log."""
import math
from typing import Any

import click

from ..io.mesh.formats import MeshFormat
from ..runtime import exit_codes, memory
from ..runtime.stages import heard_by
from ..solver.multires.size import AUTO_THRESHOLD
from ..solver.stop import StopReason
from ..tasks.job import DeformJob, JobStatus, run_job
from .common import (
    EarlyWarnings,
    MeshFormatType,
    cache_option,
    guarded,
    input_format_option,
    pose_options,
    report,
    wall_seconds,
    with_verbosity,
    write_stdout,
)
from .options import StrictCommand, settings_options
from .progress import SolveProgress


@click.command("deform", cls=StrictCommand)
@click.argument("mesh")
@click.argument("handles")
@click.option("-o", "--output", "out", required=True,
              help="Deformed mesh to write, in the format of its extension (see --format); "
                   "'-' for standard output.")
@input_format_option
@click.option("--format", "out_format", type=MeshFormatType(),
              help="Format of the output when it is '-' (standard output). [default: the "
                   "input's format]")
@click.option("--ascii", is_flag=True,
              help="Write the text variant of a format that has one (PLY; default: binary).")
@click.option("--log", "log",
              help="Per-iteration energy log: .csv or .jsonl.")
@settings_options()
@cache_option
@click.option("--preview", help="Also write a PNG: rest and deformed shape, handles coloured.")
@click.option("--preview-up", type=click.Choice(["auto", "y", "z", "x", "-y", "-z", "-x"]),
              default="auto",
              show_default=True, help="The mesh's axis drawn upward in --preview.")
@click.option("--write-distortion", is_flag=True,
              help="Add a per-vertex 'distortion' property to PLY output.")
@click.option("--keep-unconverged", is_flag=True,
              help="Write the mesh even when the solve did not converge (exit code still 3).")
@pose_options
@with_verbosity
@guarded
def deform(mesh: str, handles: str, out: str, input_format: MeshFormat | None,
           out_format: MeshFormat | None, ascii: bool, log: str | None,
           overrides: dict[str, Any], cache: str | None, preview: str | None, preview_up: str,
           write_distortion: bool, keep_unconverged: bool, fps: float | None, frame: float,
           verbosity: int | None) -> None:
    """Deform MESH as rigidly as possible with smooth rotations.

    HANDLES is a YAML/JSON handle file, or a Botsch-Sorkine .sel file with its .def beside it.
    Exit codes: 0 converged, 3 not converged (no mesh written unless --keep-unconverged; the
    log is written), 2 usage, 4 invalid input, 5 numerical failure, 6 output error.
    """
    if (verbosity or 0) >= 2:  # -v: peak memory per stage (off otherwise: see runtime.memory)
        memory.enable()
    job = DeformJob(mesh, handles, out, overrides, input_format=input_format,
                    output_format=out_format, ascii=ascii, write_distortion=write_distortion,
                    log=log, preview=preview, preview_up=preview_up,
                    keep_unconverged=keep_unconverged, cache=cache, fps=fps, frame=frame)
    progress = SolveProgress(enabled=verbosity != 0)
    early = EarlyWarnings()
    try:
        with heard_by(progress.stage if (verbosity or 0) >= 2 else None):
            done = run_job(job, callback=progress, write_stdout=write_stdout, on_warnings=early)
    finally:
        progress.close()
    measured = memory.gigabytes(done.peaks)
    report(verbosity, warnings=early.rest(done.warnings),
           details=done.solve.report_lines() + _cache_hint(done.solve, cache)
           + ([f"srarap: peak memory: {measured}"] if measured else []),
           summary=_summary(done.solve, done.settings,
                            done.written and ("<stdout>" if out == "-" else out)))
    if done.status is JobStatus.NOT_CONVERGED:
        raise SystemExit(exit_codes.NOT_CONVERGED)


#: seconds of simplification from which ``-v`` says that ``--cache`` would skip it
SLOW_SIMPLIFY = 10.0


def _cache_hint(result, cache):
    """The ``-v`` line that points a user of a large mesh at ``--cache`` (the simplification
    is the longest stage that runs on one core)."""
    part = result.multires
    seconds = part.stages.get("simplify", 0.0) if part is not None else 0.0
    if cache is not None or part is None or part.cache_hit or seconds < SLOW_SIMPLIFY:
        return []
    return [f"srarap: multires: the simplification took {seconds:.1f} s; --cache DIR keeps "
            "the coarse mesh, and a rerun of this mesh skips it"]


def _summary(result, opts, out):
    """The one summary line: why the solve stopped (at full resolution), the
    full-resolution and coarse iterations apart, the energy, the process's wall seconds."""
    coarse = f" (+ {result.coarse_iterations} coarse)" if result.coarse_iterations else ""
    e = result.energies()
    energy = (f"energy {e['total']:.6g} (membrane {e['membrane']:.6g}, bending "
              f"{e['bending']:.6g})")
    reason = result.stop_reason
    if result.approximate:
        part = result.multires
        state = (f"approximate (multires transfer: coarse solve "
                 f"{'converged' if part.converged else 'NOT converged'} in "
                 f"{part.iterations} iterations, none at full resolution)")
        energy = f"full-resolution {energy}, {part.start_energy['total']:.6g} at the start"
    elif reason is StopReason.CONVERGED:
        state = f"converged in {result.iterations} full-resolution iterations{coarse}"
    elif reason is StopReason.ITERATIONS_RUN:
        state = f"ran the {result.iterations} iterations asked (tol 0){coarse}"
    else:
        state = (f"NOT converged after {result.iterations} full-resolution iterations{coarse} "
                 f"({reason}: {result.stop_detail}; {_advice(result, opts)})")
    return (f"srarap deform: {state}; {energy}; {wall_seconds(result):.2f} s; "
            + (f"wrote {out}" if out else "no mesh written (--keep-unconverged writes it)"))


def _advice(result, opts):
    """What to try after a run that stopped unconverged, from why it stopped."""
    if result.stop_reason is StopReason.TIME_LIMIT:
        return f"stopped by --time-limit {opts.time_limit:g}: allow more time"
    tips = [f"raise --max-iter (was {opts.max_iter})"]
    n = len(result.positions)
    if opts.multires == "off" and n >= AUTO_THRESHOLD:
        tips.append(f"--multires auto (a coarse solve starts the {n} vertices closer)")
    if opts.accel == "none":
        tips.append("use --accel anderson")
    if opts.start == "laplacian":
        tips.append("--start harmonic")
    last = result.log[-1]["rel_change"]
    if not math.isnan(last):
        tips.append(f"or loosen --tol (the last change was {last:.2g})")
    return "try: " + ", ".join(tips)
