"""``srarap compare``: are two meshes the same within a tolerance?"""
import click

from ..io.mesh.formats import MeshFormat
from ..tasks.comparison import CompareJob, run_compare
from .common import FiniteFloat, guarded, input_format_option, say


@click.command("compare")
@click.argument("a")
@click.argument("b")
@click.option("--tol", type=FiniteFloat(min=0), default=0.0, show_default=True,
              help="Largest allowed distance (model units, or a fraction with --relative).")
@click.option("--relative", is_flag=True,
              help="Distances as fractions of A's bounding-box diagonal.")
@click.option("--json", "report", help="Also write the figures to this JSON file.")
@click.option("--report", "html_report", help="Also write an HTML report: the figures, B drawn "
              "over A and B coloured by its distance to A.")
@click.option("--junit", help="Also write JUnit XML (one test case) for CI systems.")
@click.option("-q", "--quiet", is_flag=True, help="No summary line.")
@input_format_option
@guarded
def compare(a: str, b: str, tol: float, relative: bool, report: str | None,
            html_report: str | None, junit: str | None, quiet: bool,
            input_format: MeshFormat | None) -> None:
    """Compare meshes A and B: per vertex when they have the same vertices and faces, else by
    the symmetric Hausdorff distance of their surfaces.

    Exit code 0 when the largest distance is within --tol, 7 when it is not.
    """
    done = run_compare(CompareJob(a, b, tol, relative, report, html_report, junit, input_format))
    if not quiet:
        say(done.summary())
    if done.exit_code:
        raise SystemExit(done.exit_code)
