"""``srarap compare``: are two meshes the same within a tolerance?"""
import json

import click

from ..io.mesh.formats import MeshFormat
from ..runtime import exit_codes
from ..runtime.commit import commit_files
from ..runtime.encoding import utf8
from ..tasks.batch.job_pictures import compare_pictures
from ..tasks.batch.report import junit_xml, report_html
from ..tasks.compare import beyond, compare_meshes
from ..tasks.job_status import JobResult, JobStatus
from ..tasks.preflight import check_output_path, read_any_mesh, refuse_overwrite
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
    if report is not None:
        check_output_path(report, (".json",), "--json")
    if html_report is not None:
        check_output_path(html_report, (".html", ".htm"), "--report")
    if junit is not None:
        check_output_path(junit, (".xml",), "--junit")
    refuse_overwrite([report, html_report, junit], others=[("mesh A", a), ("mesh B", b)])
    if a == b == "-":
        raise click.UsageError("only one of A and B can be '-' (standard input)")
    ma, mb = read_any_mesh(a, input_format)[0], read_any_mesh(b, input_format)[0]
    figures = compare_meshes(ma, mb)
    scale = figures["diagonal"] if relative and figures["diagonal"] > 0 else 1.0
    shown = {k: figures[k] / scale for k in ("max", "mean", "rms")}
    within = shown["max"] <= tol
    result = {"a": a, "b": b, "mode": figures["mode"], "relative": relative, "tol": tol,
              "within_tol": within, **shown, "diagonal": figures["diagonal"],
              "farthest": figures["where"], "beyond_tol": beyond(figures, tol, relative)}
    files = [] if report is None else [(report, utf8(json.dumps(result, indent=2) + "\n"))]
    if html_report is not None or junit is not None:
        status = JobStatus.OK if within else JobStatus.REGRESSED
        row = JobResult(f"{a} vs {b}", status, status.exit_code, compare_max=shown["max"],
                        compare_mean=shown["mean"], tol=tol, message="" if within else
                        f"max distance {shown['max']:.3g} > tol {tol:g}{_where(result)}")
        if html_report is not None:
            pictures = compare_pictures(ma, mb, figures, tol, scale)
            files.append((html_report, utf8(report_html([row], {row.job: pictures},
                                                        "srarap compare"))))
        if junit is not None:
            files.append((junit, utf8(junit_xml([row], "compare"))))
    commit_files(files)
    if not quiet:
        unit = " of the diagonal" if relative else ""
        say(f"srarap compare: {'within' if within else 'BEYOND'} tol {tol:g}{unit} "
                   f"({figures['mode']}): max {shown['max']:.6g}, mean {shown['mean']:.6g}, "
                   f"rms {shown['rms']:.6g}{unit}{_where(result)}")
    if not within:
        raise SystemExit(exit_codes.BEYOND_TOLERANCE)


def _where(result):
    """Where the largest difference is, when it is beyond the tolerance."""
    far = result["farthest"]
    if result["within_tol"] or far is None:
        return ""
    if "position" not in far:
        return ""
    at = ", ".join(f"{x:.4g}" for x in far["position"])
    return (f"; farthest: {far['mesh'].upper()}'s vertex {far['vertex']} at ({at}); "
            f"{100 * result['beyond_tol']:.3g}% of the vertices beyond tol")
