"""``srarap render`` and ``srarap plot`` as jobs a Python caller can run too: a mesh (or an
animation's frames) drawn to a PNG or a GIF, energy logs plotted. Each job is checked before
any work and commits its one file."""
import io
import os
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...io.handles import load_handles
from ...io.mesh import read_frames, reading_beside
from ...io.mesh.formats import MeshFormat
from ...io.solve_log import read_log
from ...runtime.commit import commit_files
from ...runtime.errors import InputError, UsageProblem
from ...runtime.parallel import available_cpus
from .. import job_fields as fields
from ..animate import frame_paths
from ..info import up_axis, up_decided
from ..preflight import check_output_path, read_any_mesh, refuse_overwrite
from .frames import animated_gif, contact_sheet, frame_pictures, sheet_choice
from .log_axis import decades_axis
from .preview import preview_png
from .render import VIEWS

#: frames of an animated GIF at most (each one a picture held until the file is encoded); a
#: contact sheet draws 24 of any number
MAX_GIF_FRAMES = 10_000
#: what ``render`` takes: colourings, layouts, the axis drawn upward
COLORS, LAYOUTS = ("shade", "distortion"), ("ghost", "side")
UPS = ("auto", "y", "z", "x", "-y", "-z", "-x")
#: what ``--up auto`` says when the extents do not tell
UP_NOTE = ("srarap: note: drawn with +y up: the mesh's extents do not tell which axis is up "
           "(most OBJ and PLY files are y-up); --up z if it stands on z")


def pixel_size(text: str) -> tuple[int, int]:
    """``WIDTHxHEIGHT`` as two ints of 16 to 8000 pixels; UsageProblem else."""
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise UsageProblem(f"--size {text!r}: expected WIDTHxHEIGHT, e.g. 800x600") from None
    if not (16 <= w <= 8000 and 16 <= h <= 8000):
        raise UsageProblem(f"--size {text!r}: width and height must be 16 to 8000 pixels")
    return w, h


def check_view(view: str) -> None:
    """A view name of :data:`~.render.VIEWS` or a direction ``x,y,z``; UsageProblem else."""
    if view in VIEWS:
        return
    try:
        d = np.array([float(x) for x in view.split(",")])
    except ValueError:
        d = np.zeros(0)
    if d.shape != (3,) or not np.isfinite(d).all() or not np.abs(d).max() > 0:
        raise UsageProblem(f"--view {view!r}: a view name ({', '.join(VIEWS)}) or 'x,y,z'")


@dataclass(frozen=True)
class RenderJob:
    """``mesh`` (a file, or an animation's frame pattern ``'f_{:04d}.obj'``) drawn to ``out``
    (a PNG; a GIF or a contact-sheet PNG for a frame pattern). ``size``: ``WIDTHxHEIGHT``
    (default 800x600, 480x360 a frame)."""

    mesh: str
    out: str
    handles: str | None = None
    rest: str | None = None
    color: str = "shade"
    layout: str = "ghost"
    up: str = "auto"
    views: tuple[str, ...] = ("iso",)
    size: str | None = None
    fps: float = 12.0
    input_format: MeshFormat | None = None

    def __post_init__(self) -> None:
        for name, optional in (("mesh", False), ("out", False), ("handles", True),
                               ("rest", True), ("size", True)):
            fields.text(self, name, optional)
        fields.choice(self, "color", COLORS)
        fields.choice(self, "layout", LAYOUTS)
        fields.choice(self, "up", UPS)
        fields.texts(self, "views")
        fields.number(self, "fps", 1.0, 50.0)


def run_render(job: RenderJob, on_note: Callable[[str], None] | None = None) -> str:
    """Draw ``job``; ``on_note`` hears the line ``--up auto`` says when it guesses y.
    Returns the file written."""
    fields.of_type(job, RenderJob, "run_render")
    if "{" in job.mesh:
        _frames(job, on_note)
        return job.out
    if job.out.lower().endswith(".gif"):
        raise UsageProblem(f"output {job.out!r}: a GIF is an animation's: give MESH as a frame "
                           "pattern ('frames/f_{:04d}.obj'); one mesh renders to .png")
    check_output_path(job.out, (".png",), "output")
    size = pixel_size(job.size or "800x600")
    for view in job.views:
        check_view(view)
    refuse_overwrite([job.out], mesh=job.mesh, handles=job.handles,
                     others=[("rest mesh", job.rest)] if job.rest else [])
    if job.rest == "-" and job.mesh == "-":
        raise UsageProblem("MESH and --rest cannot both be standard input (-)")
    if job.rest == "-":  # the rest shape from standard input, the shown mesh from its file
        base, shown = read_any_mesh("-")[0], read_any_mesh(job.mesh, job.input_format)[0]
    else:
        with reading_beside(job.rest) as rest:  # the rest shape read beside the shown one
            shown = read_any_mesh(job.mesh, job.input_format)[0]
            base = rest()
    if base is not None and len(base.vertices) != len(shown.vertices):
        raise UsageProblem("--rest: the rest mesh must have the same vertices")
    if job.color == "distortion" and base is None:
        raise UsageProblem("--color distortion needs --rest")
    constraints = (load_handles(job.handles, (base or shown).vertices, any_rate=True)
                   if job.handles else None)
    up = _auto_up(base or shown, on_note) if job.up == "auto" else job.up
    commit_files([(job.out, preview_png(shown, base, constraints, job.color, job.layout,
                                        list(job.views), size, up))])
    return job.out


def _frames(job, on_note):
    """``render`` of a frame pattern: an animated GIF or a contact sheet."""
    check_output_path(job.out, (".gif", ".png"), "output")
    if job.rest or job.color != "shade" or job.layout != "ghost" or len(job.views) > 1:
        raise UsageProblem("a frame pattern takes --handles, --view (one), --up, --size "
                           "and --fps; not --rest, --color, --layout or several views")
    check_view(job.views[0])
    size = pixel_size(job.size or "480x360")
    paths = frame_paths(job.mesh)
    gif = job.out.lower().endswith(".gif")
    if gif and len(paths) > MAX_GIF_FRAMES:
        raise InputError(f"{job.mesh}: {len(paths)} frames, more than a GIF takes "
                         f"({MAX_GIF_FRAMES}); -o sheet.png draws 24 of them")
    refuse_overwrite([job.out], handles=job.handles, others=[("frame", p) for p in paths])
    numbers = list(range(len(paths))) if gif else sheet_choice(len(paths))
    # a sheet reads only the frames it draws; parsing and drawing hold the GIL: processes
    parts = available_cpus()
    meshes = read_frames([paths[k] for k in numbers], parts)
    if any(len(m.vertices) != len(meshes[0].vertices) for m in meshes):
        raise InputError(f"{job.mesh}: the frames do not all have the same vertices")
    constraints = (load_handles(job.handles, meshes[0].vertices, any_rate=True)
                   if job.handles else None)
    up = _auto_up(meshes[0], on_note) if job.up == "auto" else job.up
    pictures = frame_pictures(meshes, numbers, constraints, job.views[0], size, up, parts)
    data = animated_gif(pictures, job.fps) if gif else contact_sheet(pictures)
    commit_files([(job.out, data)])


def _auto_up(mesh, on_note):
    """``--up auto``: the axis the extents tell, or y, said to be assumed."""
    if not up_decided(mesh) and on_note is not None:
        on_note(UP_NOTE)
    return up_axis(mesh)


@dataclass(frozen=True)
class PlotJob:
    """Total energy against iteration and time of the deform ``logs`` (CSV/JSONL), one
    curve each, drawn to the PNG ``out`` of ``size`` pixels."""

    logs: tuple[str, ...]
    out: str
    size: str = "1000x420"

    def __post_init__(self) -> None:
        fields.texts(self, "logs")
        fields.text(self, "out")
        fields.text(self, "size")


def run_plot(job: PlotJob) -> str:
    """Plot ``job``; returns the file written."""
    fields.of_type(job, PlotJob, "run_plot")
    check_output_path(job.out, (".png",), "output")
    refuse_overwrite([job.out], others=[("log", path) for path in job.logs])
    w, h = pixel_size(job.size)
    tables = [(path, read_log(path)) for path in job.logs]  # every log checked first
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(w / 100, h / 100), dpi=100)
    times, energies = [], []
    for path, rows in tables:
        it = [float(r["iteration"]) for r in rows]
        e = [float(r["total"]) for r in rows]
        t = [max(float(r["seconds"]), 1e-4) for r in rows]
        times += t
        energies += e
        a.plot(it, e, label=os.path.basename(path))
        b.plot(t, e, label=os.path.basename(path))
    for ax in (a, b):
        decades_axis(ax, "y", energies, "{:.4g}")
    decades_axis(b, "x", times)
    for ax, xl in ((a, "iteration"), (b, "wall time [s]")):
        ax.set_xlabel(xl)
        ax.set_ylabel("total energy")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    plt.close(fig)
    commit_files([(job.out, buf.getvalue())])
    return job.out
