"""``srarap deform``: mesh + handle file -> deformed mesh + energy log."""
import math
import os
import sys
from typing import Any

import click

from ..io.mesh import FORMATS
from ..io.mesh.formats import MeshFormat, by_extension, extensions
from ..io.solve_log import LOG_FORMATS, format_log
from ..runtime import descriptors, exit_codes, memory
from ..runtime.commit import commit_files
from ..runtime.errors import OutputError
from ..runtime.limits import check_solve
from ..solver.multires.size import AUTO_THRESHOLD
from ..solver.settings import resolve
from ..solver.stop import StopReason
from ..tasks.distortion import vertex_distortion
from ..tasks.info import up_axis
from ..tasks.pipeline import deform_mesh, refuse_warnings
from ..tasks.preview import preview_png
from .common import (
    MeshFormatType,
    cache_option,
    check_output_path,
    guarded,
    input_format_option,
    load_posed,
    pose_options,
    read_any_mesh,
    refuse_overwrite,
    report,
    wall_seconds,
    with_verbosity,
    write_stdout,
)
from .options import settings_options
from .progress import SolveProgress


@click.command("deform")
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
    fmt = _output_format(out, out_format, mesh)
    if fmt is not None:
        _check_format_options(fmt, ascii, write_distortion)
    if out != "-":  # an extension the table knows, or --format for a name without one
        check_output_path(out, None if by_extension(out) is None and out_format else extensions(),
                          "output")
    elif descriptors.closed(1):
        raise OutputError("-o -: standard output is closed; name an output file")
    if preview is not None:
        check_output_path(preview, (".png",), "preview")
    if log is not None:
        check_output_path(log, LOG_FORMATS, "log")
        if os.path.abspath(log) == os.path.abspath(out):
            raise click.UsageError("--log and --output name the same file")
    refuse_overwrite([out, log, preview], mesh=mesh, handles=handles)
    if (verbosity or 0) >= 2:  # -v: peak memory per stage (off otherwise: see runtime.memory)
        memory.enable()
    peak = memory.start()
    source, source_format = read_any_mesh(mesh, input_format)
    peaks = {"read": memory.stop(peak)}
    if fmt is None:
        fmt = source_format
        _check_format_options(fmt, ascii, write_distortion)
    name = "<stdin>" if mesh == "-" else mesh
    check_solve(name, len(source.vertices))
    constraints = load_posed(handles, source.vertices, fps, frame)
    opts = resolve(constraints.solver, overrides)
    progress = SolveProgress(enabled=verbosity != 0 and sys.stderr.isatty())
    peak = memory.start()
    try:
        deformed, result, notes = deform_mesh(source, constraints, opts, callback=progress,
                                              cache=cache, name=name)
    finally:
        progress.close()
    peaks["solve"], peak = memory.stop(peak), memory.start()
    if write_distortion:
        deformed.vertex_data["distortion"] = vertex_distortion(
            source.vertices, deformed.vertices, source.triangles()[0])
    done = result.complete
    mesh_bytes, lost = fmt.encode(deformed, ascii)
    refuse_warnings(opts, lost)
    keep = done or keep_unconverged
    files = [(out, mesh_bytes)] if keep and out != "-" else []
    if preview is not None and keep:
        files.append((preview, preview_png(deformed, source, constraints, view="iso",
                                                  up=up_axis(source) if preview_up == "auto"
                                                  else preview_up)))
    if log is not None:
        files.append((log, format_log(result.log, os.path.splitext(log)[1].lower()).encode()))
    if keep and out == "-":  # first: the files are committed only once it was written
        write_stdout(mesh_bytes)
    commit_files(files)
    peaks["write"] = memory.stop(peak)
    shown = "<stdout>" if out == "-" else out
    measured = memory.gigabytes(peaks)
    report(verbosity, warnings=notes + lost,
           details=result.report_lines() + ([f"srarap: peak memory: {measured}"]
                                             if measured else []),
           summary=_summary(result, opts, shown if keep else None))
    if not done:
        raise SystemExit(exit_codes.NOT_CONVERGED)


def _output_format(out, out_format, mesh):
    """The output's MeshFormat: ``--format``, or the extension of ``out``; for ``-o -``
    without ``--format``, the input file's, or None for standard input (its bytes decide)."""
    if out == "-":
        return out_format or (None if mesh == "-" else by_extension(mesh))
    fmt = by_extension(out)
    if out_format is not None and fmt is not None and fmt is not out_format:
        raise click.UsageError(f"--format {out_format.name} does not match the output {out!r}")
    return fmt or out_format


def _check_format_options(fmt, ascii, write_distortion):
    if ascii and not fmt.has_ascii:
        raise click.UsageError(f"--ascii applies to {_having('has_ascii')} output only")
    if write_distortion and not fmt.keeps_vertex_data:
        raise click.UsageError(f"--write-distortion needs a {_having('keeps_vertex_data')} "
                               "output")


def _having(attribute):
    """The names of the formats with ``attribute`` set, for a message: ``PLY``."""
    return "/".join(f.name.upper() for f in FORMATS.values() if getattr(f, attribute))


def _summary(result, opts, out):
    """The one summary line: why the solve stopped (at full resolution), the
    full-resolution and coarse iterations apart, the energy, the process's wall seconds."""
    coarse = f" (+ {result.coarse_iterations} coarse)" if result.coarse_iterations else ""
    e = result.energies()
    energy = (f"energy {e['total']:.6g} (membrane {e['membrane']:.6g}, bending "
              f"{e['bending']:.6g})")
    reason = result.stop_reason
    if result.approximate:
        state = (f"approximate (multires transfer: coarse solve "
                 f"{'converged' if result.coarse_converged else 'NOT converged'} in "
                 f"{result.coarse_iterations} iterations, none at full resolution)")
        energy = f"full-resolution {energy}, {result.start_energy['total']:.6g} at the start"
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
