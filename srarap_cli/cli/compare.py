"""``srarap compare``: are two meshes the same within a tolerance?"""
import json

import click

from ..io.mesh.formats import MeshFormat
from ..runtime import exit_codes
from ..runtime.commit import commit_files
from ..tasks.compare import compare_meshes
from .common import check_output_path, guarded, input_format_option, read_any_mesh, refuse_overwrite


@click.command("compare")
@click.argument("a")
@click.argument("b")
@click.option("--tol", type=click.FloatRange(min=0), default=0.0, show_default=True,
              help="Largest allowed distance (model units, or a fraction with --relative).")
@click.option("--relative", is_flag=True,
              help="Distances as fractions of A's bounding-box diagonal.")
@click.option("--json", "report", help="Also write the figures to this JSON file.")
@click.option("-q", "--quiet", is_flag=True, help="No summary line.")
@input_format_option
@guarded
def compare(a: str, b: str, tol: float, relative: bool, report: str | None, quiet: bool,
            input_format: MeshFormat | None) -> None:
    """Compare meshes A and B: per vertex when they have the same vertices and faces, else by
    the symmetric Hausdorff distance of their surfaces.

    Exit code 0 when the largest distance is within --tol, 7 when it is not.
    """
    if report is not None:
        check_output_path(report, (".json",), "--json")
    refuse_overwrite([report], others=[("mesh A", a), ("mesh B", b)])
    if a == b == "-":
        raise click.UsageError("only one of A and B can be '-' (standard input)")
    ma, mb = read_any_mesh(a, input_format)[0], read_any_mesh(b, input_format)[0]
    figures = compare_meshes(ma, mb)
    scale = figures["diagonal"] if relative and figures["diagonal"] > 0 else 1.0
    shown = {k: figures[k] / scale for k in ("max", "mean", "rms")}
    within = shown["max"] <= tol
    result = {"a": a, "b": b, "mode": figures["mode"], "relative": relative, "tol": tol,
              "within_tol": within, **shown, "diagonal": figures["diagonal"]}
    if report is not None:
        commit_files([(report, (json.dumps(result, indent=2) + "\n").encode())])
    if not quiet:
        unit = " of the diagonal" if relative else ""
        click.echo(f"srarap compare: {'within' if within else 'BEYOND'} tol {tol:g}{unit} "
                   f"({figures['mode']}): max {shown['max']:.6g}, mean {shown['mean']:.6g}, "
                   f"rms {shown['rms']:.6g}{unit}", err=True)
    if not within:
        raise SystemExit(exit_codes.BEYOND_TOLERANCE)
