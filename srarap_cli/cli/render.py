"""``srarap render`` and ``srarap plot``: pictures of meshes and of energy logs."""
import click

from ..io.mesh.formats import MeshFormat
from ..tasks.pictures import VIEWS, PlotJob, RenderJob, run_plot, run_render
from .common import FiniteFloat, guarded, input_format_option, say


@click.command("render")
@click.argument("mesh")
@click.option("-o", "--output", "out", required=True,
              help="PNG to write (a frame pattern: a GIF, or a PNG contact sheet).")
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
@click.option("-q", "--quiet", is_flag=True, help="No note (the up-axis guess).")
@input_format_option
@guarded
def render(mesh: str, out: str, handles: str | None, rest: str | None, color: str, layout: str,
           up: str, views: tuple[str, ...], size: str | None, fps: float, quiet: bool,
           input_format: MeshFormat | None) -> None:
    """Render MESH to a PNG, headless.

    MESH may be an animation's frame pattern (as 'srarap animate' writes: 'frames/f_{:04d}.obj'):
    its frames from 0 on, framed alike, become an animated GIF (-o anim.gif) or a contact sheet
    of up to 24 of them (-o sheet.png).
    """
    run_render(RenderJob(mesh, out, handles, rest, color, layout, up, tuple(views), size, fps,
                         input_format), on_note=None if quiet else say)


@click.command("plot")
@click.argument("logs", nargs=-1, required=True)
@click.option("-o", "--output", "out", required=True, help="PNG to write.")
@click.option("--size", default="1000x420", show_default=True, help="WIDTHxHEIGHT in pixels.")
@guarded
def plot(logs: tuple[str, ...], out: str, size: str) -> None:
    """Plot total energy against iteration and time for one or more deform logs (CSV/JSONL)."""
    run_plot(PlotJob(tuple(logs), out, size))
