"""Object File Format (OFF, with the NOFF/COFF/STOFF prefixes).

Written by hand because meshio's reader rejects common headers (for example a double space
in the count line) and libigl's triangulates polygons away.
"""

from typing import Any

import numpy as np

from ...runtime.errors import InputError, excerpt
from ..input_files import open_input
from .mesh import Mesh
from .numbers import parse_numbers


def _tokens(path):
    with open_input(path, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            line = line.split("#", 1)[0].split()
            if line:
                yield line


def read_off(path: str) -> Mesh:
    """Read an OFF file into a :class:`Mesh` (vertex normals and ST texture coords kept)."""
    with open_input(path, encoding="utf-8", errors="replace") as fh:
        plain = _read_plain(fh.read())
    return plain if plain is not None else _read_general(path)


def _read_plain(text):
    """The mesh of a plain OFF file (keyword ``OFF``, no comments, three numbers on every
    vertex line, ``k`` and ``k`` indices on every face line), parsed in bulk by numpy's C
    parser: a 738k-vertex file in a fraction of the line-by-line time. None for anything
    else, which :func:`_read_general` reads or reports."""
    if "#" in text:
        return None
    lines = text.splitlines()
    head = lines[0].split() if lines else []
    if not head or head[0] != "OFF":
        return None
    start = 1 if len(head) > 1 else 2
    counts = head[1:] if len(head) > 1 else (lines[1].split() if len(lines) > 1 else [])
    try:
        nv, nf = int(counts[0]), int(counts[1])
    except (IndexError, ValueError):
        return None
    vertex_lines = lines[start:start + nv]
    face_lines = lines[start + nv:start + nv + nf]
    if len(vertex_lines) != nv or len(face_lines) != nf or nf == 0 \
            or any(line.strip() for line in lines[start + nv + nf:]):
        return None
    widths = np.fromiter((len(line.split()) for line in face_lines), dtype=np.int64, count=nf)
    if any(len(line.split()) != 3 for line in vertex_lines) or (widths < 4).any():
        return None
    V, values = parse_numbers(vertex_lines), parse_numbers(face_lines, dtype=np.int64)
    if V is None or values is None:
        return None
    first = np.cumsum(widths) - widths
    sizes = values[first] if values.size == widths.sum() else None
    if V.size != 3 * nv or sizes is None or not np.array_equal(sizes, widths - 1):
        return None
    keep = np.ones(values.size, dtype=bool)
    keep[first] = False
    corners = values[keep]
    if (corners < 0).any() or (corners >= nv).any():
        return None
    return Mesh(vertices=V.reshape(nv, 3), face_sizes=sizes, face_vertices=corners)


def _read_general(path):
    lines = _tokens(path)
    try:
        header = next(lines)
    except StopIteration:
        raise InputError(f"{path}: empty file") from None
    keyword = header[0].upper()
    if not keyword.endswith("OFF"):
        raise InputError(f"{path}: not an OFF file (first word {excerpt(header[0], 20)!r})")
    prefix = keyword[:-3]
    counts: list[Any] = header[1:] or next(lines, [])
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
    need = 3 + 3 * ("N" in prefix) + 2 * ("ST" in prefix)
    short = next((k for k, r in enumerate(vrows) if len(r) < need), None)
    if short is not None:
        raise InputError(f"{path}: vertex {short} has {len(vrows[short])} numbers; a "
                         f"{excerpt(header[0], 20)} vertex needs {need}")
    try:
        if "N" in prefix:
            mesh.normals = np.array([r[3:6] for r in vrows], dtype=float)
            mesh.face_normals = corners.copy()
        if "ST" in prefix:
            mesh.uv = np.array([r[-2:] for r in vrows], dtype=float)
            mesh.face_uv = corners.copy()
    except (ValueError, OverflowError):
        raise InputError(f"{path}: non-numeric vertex normal or texture coordinate") from None
    return mesh


def format_off(mesh: Mesh) -> str:
    """OFF text for ``mesh`` (``NOFF`` when it has per-vertex normals)."""
    normals = mesh.normals
    per_vertex_normals = (normals is not None and len(normals) == len(mesh.vertices)
                          and mesh.face_normals is not None
                          and np.array_equal(mesh.face_normals, mesh.face_vertices))
    head = "NOFF" if per_vertex_normals else "OFF"
    cols = np.hstack([mesh.vertices, normals]) if normals is not None and per_vertex_normals \
        else mesh.vertices
    parts = [f"{head}\n{len(mesh.vertices)} {mesh.face_sizes.size} 0\n"]
    if len(cols):
        parts.append((("%.17g " * (cols.shape[1] - 1) + "%.17g\n") * len(cols))
                     % tuple(cols.ravel()))
    sizes = mesh.face_sizes
    if sizes.size and (sizes == sizes[0]).all():  # one format for all rows, not one per face
        k = int(sizes[0])
        rows = np.column_stack([sizes, mesh.face_vertices.reshape(-1, k)])
        parts.append((("%d " * k + "%d\n") * len(rows)) % tuple(rows.ravel().tolist()))
        return "".join(parts)
    offsets = mesh.face_offsets
    fv = mesh.face_vertices.astype(str)
    parts.extend(f"{sizes[i]} " + " ".join(fv[offsets[i]:offsets[i + 1]]) + "\n"
                 for i in range(sizes.size))
    return "".join(parts)
