"""``srarap info``: what a mesh is and what a handle file does to it, without solving."""
import json

import click

from ..io.mesh.formats import MeshFormat
from ..runtime.encoding import utf8
from ..tasks.info import describe
from ..tasks.preflight import load_posed, read_any_mesh
from .common import guarded, input_format_option, pose_options, printable, write_stdout


@click.command("info")
@click.argument("mesh")
@click.argument("handles", required=False)
@input_format_option
@click.option("--json", "as_json", is_flag=True, help="One JSON document on standard output.")
@pose_options
@guarded
def info(mesh: str, handles: str | None, input_format: MeshFormat | None,
         as_json: bool, fps: float | None, frame: float) -> None:
    """Describe MESH and what HANDLES selects and does, without solving.

    The mesh: counts, extent per axis, problems. With HANDLES, each group's vertices and
    action: a dry run of the checks deform makes (exit 4 when the file is invalid).
    """
    source = read_any_mesh(mesh, input_format)[0]
    name = "<stdin>" if mesh == "-" else mesh
    posed = None if handles is None else load_posed(handles, source.vertices, fps, frame)
    of_mesh, of_handles = describe(source, posed, name)
    out = {"mesh": name, **of_mesh}
    if of_handles is not None:
        out.update({"handles": handles, **of_handles})
    if as_json:
        write_stdout(utf8(json.dumps(out, indent=2) + "\n"))
    else:
        write_stdout(utf8(_text(out) + "\n"))


def _text(d):
    lines = [f"{d['mesh']}: {d['vertices']} vertices, {d['faces']} faces "
             f"({d['triangles']} triangles), {d['components']} connected part"
             f"{'s' if d['components'] != 1 else ''}, {d['boundary_loops']} boundary loop"
             f"{'s' if d['boundary_loops'] != 1 else ''}"]
    for k, axis in enumerate("xyz"):
        lines.append(f"  {axis}: {d['bbox_min'][k]:.6g} .. {d['bbox_max'][k]:.6g} "
                     f"(extent {d['extent'][k]:.6g})")
    lines.append(f"  diagonal {d['diagonal']:.6g}; up axis, a guess: {d['up_guess']}")
    genus = "" if d["genus"] is None else f", genus {d['genus']}"
    lines.append(f"  Euler characteristic {d['euler']}{genus}")
    lines += [f"  problem: {p}" for p in d["problems"]] or ["  no problems found"]
    if "groups" in d:
        lines.append(f"{d['handles']}: {len(d['groups'])} groups, {d['constrained']} "
                     f"constrained vertices, {d['free']} free"
                     + (f" (region of interest: {d['region']} vertices)" if d["region"]
                        is not None else ""))
        for g in d["groups"]:
            lines.append(f"  {g['name']}: {g['vertices']} vertices: {g['action']}")
        for o in d["overlaps"]:
            lines.append(f"  overlap: {o['vertices']} vertices in both "
                         f"{o['groups'][0]!r} and {o['groups'][1]!r}")
        lines += [f"  warning: {w}" for w in d["warnings"]]
    return "\n".join(map(printable, lines))  # names from the files: no control characters
