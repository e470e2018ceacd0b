"""STL, binary and ASCII, read and written here.

Reading welds the facets' corners into vertices exactly as meshio does (identical
coordinates become one vertex, numbered in order of first appearance), so a mesh read here
and one read by meshio have the same vertices in the same order. Unlike meshio's reader, the
ASCII grammar is checked (a truncated or misspelt facet is an error naming it) and parsing
is vectorized (no Python loop per number). Taking STL out of meshio also keeps meshio and
its terminal-rendering dependencies out of the default install.
"""
import os
import re

import numpy as np

from ...runtime.errors import InputError
from ..input_files import open_input
from .mesh import Mesh

_RECORD = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
# one ASCII facet: facet normal a b c / outer loop / vertex x y z (x3) / endloop / endfacet
_FACET = [b"facet", b"normal", None, None, None, b"outer", b"loop",
          b"vertex", None, None, None, b"vertex", None, None, None,
          b"vertex", None, None, None, b"endloop", b"endfacet"]
_CORNERS = [8, 9, 10, 12, 13, 14, 16, 17, 18]


def read_stl(path: str | os.PathLike) -> Mesh:
    """Read a binary or ASCII STL file.

    A file whose size is exactly 84 + 50 x (its triangle count) is binary, whatever its
    header says (binary files often start with ``solid`` too); otherwise it must be ASCII.

    Parameters
    ----------
    path : str
        The STL file.

    Returns
    -------
    Mesh
        Triangles over the welded corners.

    Raises
    ------
    InputError : neither a consistent binary file nor well-formed ASCII STL.
    """
    with open_input(path, "rb") as fh:
        data = fh.read()
    if len(data) >= 84:
        count = int(np.frombuffer(data, dtype="<u4", count=1, offset=80)[0])
        if 84 + 50 * count == len(data):
            corners = np.frombuffer(data, dtype=_RECORD, count=count, offset=84)["v"]
            return _welded(corners.reshape(-1, 3))
    if not data.strip():
        return _welded(np.zeros((0, 3)))
    if not data.lstrip()[:5].lower() == b"solid":
        raise InputError(f"{path}: not a readable STL file (binary size does not match "
                         f"its triangle count, and it does not start with 'solid')")
    return _welded(_ascii_corners(path, data))


_SOLID_LINE = re.compile(rb"^[ \t]*(end)?solid\b[^\n]*$", re.IGNORECASE | re.MULTILINE)


def _ascii_corners(path, data):
    """Corners of every facet of every solid. Keywords in any case; ``solid`` and
    ``endsolid`` lines are dropped whole, so a solid's name (even ``facet``) is never read
    as a keyword, and several solids one after another read as one."""
    ends = [m for m in _SOLID_LINE.finditer(data) if m.group(1)]
    if not ends or data[ends[-1].end():].strip():
        raise InputError(f"{path}: not a readable STL file (it does not end with 'endsolid': "
                         "truncated?)")
    body = _SOLID_LINE.sub(b"", data).lower().split()
    if len(body) % len(_FACET):
        whole = len(body) // len(_FACET)
        raise InputError(f"{path}: not a readable STL file (facet {whole} is incomplete or "
                         f"not a triangle)")
    grid = np.array(body, dtype=bytes).reshape(-1, len(_FACET))
    for column, word in enumerate(_FACET):
        if word is not None and (grid[:, column] != word).any():
            row = int(np.flatnonzero(grid[:, column] != word)[0])
            raise InputError(f"{path}: not a readable STL file (facet {row}: expected "
                             f"{word.decode()!r}, found {grid[row, column].decode(errors='replace')!r})")
    try:
        xyz = grid[:, _CORNERS].astype(float)
    except ValueError:
        raise InputError(f"{path}: not a readable STL file (a vertex coordinate is not a "
                         f"number)") from None
    return xyz.reshape(-1, 3)


def _welded(corners):
    """Vertices (first appearance order) and triangles of an (3m,3) corner list."""
    if not len(corners):
        return Mesh(vertices=np.zeros((0, 3)), face_sizes=np.zeros(0, dtype=np.int64),
                    face_vertices=np.zeros(0, dtype=np.int64))
    _, first, inverse = np.unique(corners, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    faces = rank[inverse.ravel()].astype(np.int64)
    return Mesh(vertices=np.asarray(corners[first[order]], dtype=float),
                face_sizes=np.full(len(faces) // 3, 3, dtype=np.int64), face_vertices=faces)


def format_stl(mesh: Mesh) -> bytes:
    """Binary STL bytes of the mesh's triangles (polygons fanned), deterministic header."""
    F = mesh.triangles()[0]
    tri = mesh.vertices[F]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    normal = np.divide(normal, length, out=np.zeros_like(normal), where=length > 0)
    record = np.zeros(len(F), dtype=_RECORD)
    record["n"], record["v"] = normal, tri
    header = b"binary STL written by srarap".ljust(80, b" ")
    return header + np.uint32(len(F)).tobytes() + record.tobytes()
