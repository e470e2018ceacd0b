"""``srarap compare``: are two meshes the same within a tolerance?"""
import click

from ..io.mesh.formats import MeshFormat
from ..tasks.comparison import CompareJob, run_compare
from .common import FiniteFloat, Tolerance, guarded, input_format_option, say


@click.command("compare")
@click.argument("a")
@click.argument("b")
@click.option("--tol", type=Tolerance(), default="0", show_default=True,
              help="Largest allowed distance (model units, or a fraction with --relative); "
                   "a percentage (1%) is of A's diagonal.")
@click.option("--relative", is_flag=True,
              help="Distances as fractions of A's bounding-box diagonal.")
@click.option("--beyond-tol", type=FiniteFloat(min=0, max=1), default=0.0, show_default=True,
              metavar="FRACTION", help="Fraction of the vertices allowed farther than --tol "
              "(0: every vertex within it).")
@click.option("--p95", type=FiniteFloat(min=0), metavar="D",
              help="Largest allowed 95th percentile distance (the unit of --tol).")
@click.option("--p99", type=FiniteFloat(min=0), metavar="D",
              help="Largest allowed 99th percentile distance (the unit of --tol).")
@click.option("--align", type=click.Choice(["none", "rigid"]), default="none",
              show_default=True, help="rigid: move B by the rigid motion that brings it "
              "closest to A before measuring (same vertices and faces; the motion is said).")
@click.option("--update", is_flag=True, help="B is a golden: write A there when B is missing "
              "or beyond the gates (exit code still 8 or 7: review it).")
@click.option("--accept", is_flag=True, help="As --update, and exit 0: A is the truth.")
@click.option("--json", "report", help="Also write the figures to this JSON file.")
@click.option("--report", "html_report", help="Also write an HTML report: the figures, B drawn "
              "over A and B coloured by its distance to A.")
@click.option("--junit", help="Also write JUnit XML (one test case) for CI systems.")
@click.option("--summary-md", "markdown", metavar="FILE",
              help="Also write a Markdown summary (a GitHub job summary).")
@click.option("--metrics", metavar="FILE",
              help="Also write the figures as OpenMetrics (GitLab's metrics.txt).")
@click.option("-q", "--quiet", is_flag=True, help="No summary line.")
@input_format_option
@guarded
def compare(a: str, b: str, tol: tuple[float, bool], relative: bool, beyond_tol: float, p95: float | None,
            p99: float | None, align: str, update: bool, accept: bool, report: str | None,
            html_report: str | None, junit: str | None, markdown: str | None,
            metrics: str | None, quiet: bool, input_format: MeshFormat | None) -> None:
    """Compare meshes A and B: per vertex when they have the same vertices and faces, else
    by the distance of every vertex to the other surface, both ways (both one-sided
    distances are said).

    Exit code 0 when every gate holds (the largest distance within --tol, or at most
    --beyond-tol of the vertices beyond it; --p95, --p99), 7 when one does not, 8 when B is
    missing and --update wrote it (--accept: 0).
    """
    goldens = "accept" if accept else "update" if update else "check"
    tol, percent = tol
    relative = relative or percent
    done = run_compare(CompareJob(a, b, tol, relative, report, html_report, junit, input_format,
                                  beyond_tol, p95, p99, align, goldens, markdown, metrics))
    if not quiet or done.golden:
        say(done.summary())
    if done.exit_code:
        raise SystemExit(done.exit_code)
