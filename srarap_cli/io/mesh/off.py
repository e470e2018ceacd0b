"""Object File Format (OFF, with the NOFF/COFF/STOFF prefixes).

Written by hand because meshio's reader rejects common headers (for example a double space
in the count line) and libigl's triangulates polygons away.
"""
import numpy as np

from ...runtime.errors import InputError, excerpt
from ..input_files import open_input
from .mesh import Mesh


def _tokens(path):
    with open_input(path, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            line = line.split("#", 1)[0].split()
            if line:
                yield line


def read_off(path):
    """Read an OFF file into a :class:`Mesh` (vertex normals and ST texture coords kept)."""
    lines = _tokens(path)
    try:
        header = next(lines)
    except StopIteration:
        raise InputError(f"{path}: empty file") from None
    keyword = header[0].upper()
    if not keyword.endswith("OFF"):
        raise InputError(f"{path}: not an OFF file (first word {excerpt(header[0], 20)!r})")
    prefix = keyword[:-3]
    counts = header[1:] or next(lines, [])
    try:
        nv, nf = int(counts[0]), int(counts[1])
    except (IndexError, ValueError):
        raise InputError(f"{path}: bad count line (expected 'vertices faces edges')") from None
    try:
        vrows = [next(lines) for _ in range(nv)]
        frows = [next(lines) for _ in range(nf)]
    except StopIteration:
        raise InputError(f"{path}: file ends early (header announces {nv} vertices, "
                         f"{nf} faces)") from None
    try:
        V = np.array([r[:3] for r in vrows], dtype=float).reshape(nv, 3)
        sizes = np.array([int(r[0]) for r in frows], dtype=np.int64)
        corners = np.array([int(x) for r, k in zip(frows, sizes) for x in r[1:1 + k]],
                           dtype=np.int64)
    except (ValueError, OverflowError):
        raise InputError(f"{path}: non-numeric or out-of-range vertex or face entry") from None
    if corners.size != sizes.sum() or (sizes < 3).any():
        raise InputError(f"{path}: a face line lists fewer indices than its corner count")
    mesh = Mesh(vertices=V, face_sizes=sizes, face_vertices=corners)
    if "N" in prefix:
        mesh.normals = np.array([r[3:6] for r in vrows], dtype=float)
        mesh.face_normals = corners.copy()
    if "ST" in prefix:
        mesh.uv = np.array([r[-2:] for r in vrows], dtype=float)
        mesh.face_uv = corners.copy()
    return mesh


def format_off(mesh):
    """OFF text for ``mesh`` (``NOFF`` when it has per-vertex normals)."""
    per_vertex_normals = (mesh.normals is not None and len(mesh.normals) == len(mesh.vertices)
                          and np.array_equal(mesh.face_normals, mesh.face_vertices))
    head = "NOFF" if per_vertex_normals else "OFF"
    cols = np.hstack([mesh.vertices, mesh.normals]) if per_vertex_normals else mesh.vertices
    parts = [f"{head}\n{len(mesh.vertices)} {mesh.face_sizes.size} 0\n"]
    if len(cols):
        parts.append((("%.17g " * (cols.shape[1] - 1) + "%.17g\n") * len(cols))
                     % tuple(cols.ravel()))
    offsets = mesh.face_offsets
    fv = mesh.face_vertices.astype(str)
    parts.extend(f"{mesh.face_sizes[i]} " + " ".join(fv[offsets[i]:offsets[i + 1]]) + "\n"
                 for i in range(mesh.face_sizes.size))
    return "".join(parts)
