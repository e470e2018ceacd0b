"""``srarap deform``: mesh + handle file -> deformed mesh + energy log."""
from typing import Any

import click

from ..io.mesh.formats import MeshFormat
from ..runtime import exit_codes, memory
from ..runtime.parallel import cap_note
from ..runtime.stages import heard_by
from ..tasks.deform import DeformJob, JobStatus, cache_hint, run_job, summary_line
from .common import (
    EarlyWarnings,
    MeshFormatType,
    cache_option,
    guarded,
    input_format_option,
    pose_options,
    report,
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
           details=done.solve.report_lines() + cache_hint(done.solve, cache)
           + cap_note(done.settings.threads)
           + ([f"srarap: peak memory: {measured}"] if measured else []),
           summary=summary_line(done.solve, done.settings,
                            done.written and ("<stdout>" if out == "-" else out)))
    if done.status is JobStatus.NOT_CONVERGED:
        raise SystemExit(exit_codes.NOT_CONVERGED)
