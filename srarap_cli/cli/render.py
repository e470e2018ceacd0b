"""``srarap render`` and ``srarap plot``: pictures of meshes and of energy logs."""
import os

import click
import numpy as np

from ..io.handles import load_handles
from ..io.mesh import read_mesh
from ..io.mesh.formats import MeshFormat
from ..io.solve_log import read_log
from ..runtime.commit import commit_files
from ..runtime.errors import InputError
from ..tasks.frame_files import frame_paths
from ..tasks.frames import animated_gif, contact_sheet, frame_pictures, sheet_choice
from ..tasks.info import up_axis, up_decided
from ..tasks.log_axis import decades_axis
from ..tasks.preflight import check_output_path, read_any_mesh, refuse_overwrite
from ..tasks.preview import preview_png
from ..tasks.render import VIEWS
from .common import FiniteFloat, guarded, input_format_option, say


def parse_size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise click.BadParameter(f"{text!r}: expected WIDTHxHEIGHT, e.g. 800x600") from None
    if not (16 <= w <= 8000 and 16 <= h <= 8000):
        raise click.BadParameter(f"{text!r}: width and height must be 16 to 8000 pixels")
    return w, h


@click.command("render")
@click.argument("mesh")
@click.option("-o", "--output", "out", required=True, help="PNG to write.")
@click.option("--handles", help="Handle file: its groups are coloured (selected on the rest shape).")
@click.option("--rest", help="Rest mesh (same vertices): shown beside or behind, and needed "
              "for --color distortion.")
@click.option("--color", type=click.Choice(["shade", "distortion"]), default="shade",
              show_default=True)
@click.option("--layout", type=click.Choice(["ghost", "side"]), default="ghost",
              show_default=True,
              help="Rest shape ghosted behind the mesh (small deformations show), or beside it.")
@click.option("--up", type=click.Choice(["auto", "y", "z", "x", "-y", "-z", "-x"]),
              default="auto", show_default=True,
              help="The mesh's axis drawn upward: auto is the guess 'srarap info' prints (y or "
                   "z: the length of a long object, else the side it stands on); y for most "
                   "OBJ/PLY files, z for CAD and scanner data.")
@click.option("--view", "views", multiple=True, default=("iso",), show_default=True,
              help=f"{', '.join(VIEWS)}, or a viewing direction 'x,y,z'; repeat for "
                   "several views side by side.")
@click.option("--size", help="WIDTHxHEIGHT in pixels (of each frame, for a frame pattern). "
                                "[default: 800x600; 480x360 a frame]")
@click.option("--fps", type=FiniteFloat(min=1, max=50), default=12.0, show_default=True,
              help="Frames per second of an animated GIF.")
@input_format_option
@guarded
def render(mesh: str, out: str, handles: str | None, rest: str | None, color: str, layout: str,
           up: str, views: tuple[str, ...], size: str | None, fps: float,
           input_format: MeshFormat | None) -> None:
    """Render MESH to a PNG, headless.

    MESH may be an animation's frame pattern (as 'srarap animate' writes: 'frames/f_{:04d}.obj'):
    its frames from 0 on, framed alike, become an animated GIF (-o anim.gif) or a contact sheet
    of up to 24 of them (-o sheet.png).
    """
    if "{" in mesh:
        return _frames(mesh, out, handles, rest, color, layout, up, views, size, fps)
    check_output_path(out, (".png",), "output")
    size = parse_size(size or "800x600")
    for view in views:
        _check_view(view)
    refuse_overwrite([out], mesh=mesh, handles=handles,
                     others=[("rest mesh", rest)] if rest else [])
    shown = read_any_mesh(mesh, input_format)[0]
    base = read_mesh(rest) if rest else None
    if base is not None and len(base.vertices) != len(shown.vertices):
        raise click.BadParameter("the rest mesh must have the same vertices", param_hint="--rest")
    if color == "distortion" and base is None:
        raise click.UsageError("--color distortion needs --rest")
    constraints = (load_handles(handles, (base or shown).vertices, any_rate=True) if handles
                   else None)
    if up == "auto":
        up = _auto_up(base or shown)
    commit_files([(out, preview_png(shown, base, constraints, color, layout, list(views),
                                    size, up))])


#: frames of an animated GIF at most (each one a picture held until the file is encoded); a
#: contact sheet draws 24 of any number
MAX_GIF_FRAMES = 10_000


def _frames(pattern, out, handles, rest, color, layout, up, views, size, fps):
    """``render`` of a frame pattern: an animated GIF or a contact sheet."""
    check_output_path(out, (".gif", ".png"), "output")
    if rest or color != "shade" or layout != "ghost" or len(views) > 1:
        raise click.UsageError("a frame pattern takes --handles, --view (one), --up, --size "
                               "and --fps; not --rest, --color, --layout or several views")
    _check_view(views[0])
    size = parse_size(size or "480x360")
    paths = frame_paths(pattern)
    gif = out.lower().endswith(".gif")
    if gif and len(paths) > MAX_GIF_FRAMES:
        raise InputError(f"{pattern}: {len(paths)} frames, more than a GIF takes "
                         f"({MAX_GIF_FRAMES}); -o sheet.png draws 24 of them")
    refuse_overwrite([out], handles=handles, others=[("frame", p) for p in paths])
    numbers = list(range(len(paths))) if gif else sheet_choice(len(paths))
    meshes = [read_mesh(paths[k]) for k in numbers]  # a sheet reads only the frames it draws
    if any(len(m.vertices) != len(meshes[0].vertices) for m in meshes):
        raise InputError(f"{pattern}: the frames do not all have the same vertices")
    constraints = (load_handles(handles, meshes[0].vertices, any_rate=True) if handles
                   else None)
    up = _auto_up(meshes[0]) if up == "auto" else up
    pictures = frame_pictures(meshes, numbers, constraints, views[0], size, up)
    data = animated_gif(pictures, fps) if gif else contact_sheet(pictures)
    commit_files([(out, data)])


def _check_view(view):
    if view in VIEWS:
        return
    try:
        d = np.array([float(x) for x in view.split(",")])
    except ValueError:
        d = np.zeros(0)
    if d.shape != (3,) or not np.isfinite(d).all() or not np.abs(d).max() > 0:
        raise click.BadParameter(f"{view!r}: a view name ({', '.join(VIEWS)}) or 'x,y,z'",
                                 param_hint="--view")


@click.command("plot")
@click.argument("logs", nargs=-1, required=True)
@click.option("-o", "--output", "out", required=True, help="PNG to write.")
@click.option("--size", default="1000x420", show_default=True, help="WIDTHxHEIGHT in pixels.")
@guarded
def plot(logs: tuple[str, ...], out: str, size: str) -> None:
    """Plot total energy against iteration and time for one or more deform logs (CSV/JSONL)."""
    check_output_path(out, (".png",), "output")
    refuse_overwrite([out], others=[("log", path) for path in logs])
    w, h = parse_size(size)
    import io

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tables = [(path, read_log(path)) for path in logs]  # every log checked before drawing
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
    commit_files([(out, buf.getvalue())])


def _auto_up(mesh):
    """``--up auto``: the axis the extents tell, or y, said to be assumed."""
    axis = up_axis(mesh)
    if not up_decided(mesh):
        say("srarap: note: drawn with +y up: the mesh's extents do not tell which axis is up "
            "(most OBJ and PLY files are y-up); --up z if it stands on z")
    return axis
