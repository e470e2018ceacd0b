"""What a mesh holds beyond positions and triangles, kind by kind, and the warnings a format
that does not keep a kind owes: a format declares the kinds it keeps
(:attr:`~.formats.MeshFormat.keeps`), and what a mesh holds of the others is said here, one
line a kind, so that no format drops data silently (tests/test_format_keeps.py writes every
kind in every format and checks that it comes back or is said).
"""
from collections.abc import Iterable

from .mesh import Mesh
from .ply import per_vertex

#: the kinds, in the order warnings name them: faces of 4 corners, of more, texture
#: coordinates (one per vertex; several at a vertex: seams), normals, other per-vertex
#: properties, OBJ's statements (``mtllib``, ``usemtl``, ``g``, ``s``...)
KINDS = ("quads", "polygons", "uv", "uv_seams", "normals", "vertex_data", "statements")
#: the kinds a format that keeps no more than positions and triangles splits, not drops
SPLIT = ("quads", "polygons")


def held(mesh: Mesh) -> dict[str, str]:
    """``{kind: what mesh holds of it, in words}`` for each kind of :data:`KINDS` it holds.

    Examples
    --------
    >>> import numpy as np
    >>> square = Mesh(vertices=np.eye(4, 3), face_sizes=np.array([4]),
    ...               face_vertices=np.arange(4))
    >>> held(square)
    {'quads': '1 quads'}
    """
    out = {}
    sizes = mesh.face_sizes
    if (sizes == 4).any():
        out["quads"] = f"{int((sizes == 4).sum())} quads"
    if (sizes > 4).any():
        out["polygons"] = f"{int((sizes > 4).sum())} polygons of more than 4 corners"
    if mesh.uv is not None:
        seams = per_vertex(mesh, mesh.uv, mesh.face_uv) is None
        out["uv_seams" if seams else "uv"] = "texture coordinates"
    if mesh.normals is not None:
        out["normals"] = "normals"
    if mesh.vertex_data:
        out["vertex_data"] = f"per-vertex data ({', '.join(sorted(mesh.vertex_data))})"
    if mesh.statements:
        heads = sorted({line.split()[0] for _, line in mesh.statements if line.split()})
        out["statements"] = f"{len(mesh.statements)} OBJ statements ({', '.join(heads)})"
    return out


def drops(mesh: Mesh, name: str, keeps: Iterable[str],
          keepers: dict[str, str]) -> list[str]:
    """A warning line per kind ``mesh`` holds that the format ``name`` does not keep:
    faces split into triangles, or data not written with the extension of a format that
    keeps it (``keepers``: kind -> extension).

    Examples
    --------
    >>> import numpy as np
    >>> square = Mesh(vertices=np.eye(4, 3), face_sizes=np.array([4]),
    ...               face_vertices=np.arange(4), uv=np.eye(4, 2), face_uv=np.arange(4))
    >>> for line in drops(square, "STL", (), {"uv": ".obj"}):
    ...     print(line)
    1 quads written as triangles (STL keeps triangles)
    texture coordinates not written: STL does not keep them (.obj does)
    """
    keeps = set(keeps)
    out = []
    for kind, what in held(mesh).items():
        if kind in keeps:
            continue
        if kind in SPLIT:
            faces = "triangles and quads" if "quads" in keeps else "triangles"
            out.append(f"{what} written as triangles ({name} keeps {faces})")
        else:
            where = f" ({keepers[kind]} does)" if kind in keepers else ""
            why = ("keeps one a vertex, and these have seams (several at a vertex)"
                   if kind == "uv_seams" and "uv" in keeps else "does not keep them")
            out.append(f"{what} not written: {name} {why}{where}")
    return out
