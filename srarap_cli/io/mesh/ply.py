"""PLY writer (the reader is :mod:`.ply_read`).

meshio stamps the current time into PLY headers it writes; this writer does not, so the
same mesh always gives the same bytes.
"""

import numpy as np

from .mesh import Mesh

_PLY_TYPES = {"u1": "uchar", "i1": "char", "u2": "ushort", "i2": "short", "u4": "uint",
              "i4": "int", "f4": "float", "f8": "double"}


def per_vertex(mesh: Mesh, values: np.ndarray | None, refs: np.ndarray | None
               ) -> np.ndarray | None:
    """``values`` as one row per vertex, or None when corners of a vertex disagree."""
    if values is None or refs is None:
        return None
    n = len(mesh.vertices)
    ok = refs >= 0
    if not ok.all():
        return None
    first = np.full(n, -1)
    first[mesh.face_vertices[::-1]] = refs[::-1]
    if (first[mesh.face_vertices] != refs).any() or (first < 0).any():
        return None
    return values[first]


def format_ply(mesh: Mesh, ascii: bool = False) -> bytes:
    """PLY bytes, binary little-endian (or ``ascii``); per-vertex normals and UVs when they
    are per vertex."""
    n = len(mesh.vertices)
    columns = [("x", mesh.vertices[:, 0]), ("y", mesh.vertices[:, 1]), ("z", mesh.vertices[:, 2])]
    normals = per_vertex(mesh, mesh.normals, mesh.face_normals)
    if normals is not None:
        columns += list(zip(("nx", "ny", "nz"), normals.T))
    uv = per_vertex(mesh, mesh.uv, mesh.face_uv)
    if uv is not None:
        columns += list(zip(("s", "t"), uv[:, :2].T))
    columns += [(k, v) for k, v in sorted(mesh.vertex_data.items())
                if v.dtype.str[1:] in _PLY_TYPES]
    dtype = [(name, "<" + (np.asarray(col).dtype.str[1:] if name in mesh.vertex_data else "f8"))
             for name, col in columns]
    table = np.empty(n, dtype=dtype)
    for name, col in columns:
        table[name] = col
    header = ["ply", f"format {'ascii' if ascii else 'binary_little_endian'} 1.0",
              "comment written by srarap", f"element vertex {n}"]
    header += [f"property {_PLY_TYPES[table.dtype[name].str[1:]]} {name}" for name, _ in columns]
    header += [f"element face {mesh.face_sizes.size}",
               "property list uchar int vertex_indices", "end_header"]
    head = ("\n".join(header) + "\n").encode("ascii")
    if ascii:
        return head + _ascii_rows(table, mesh)
    return head + table.tobytes() + _face_bytes(mesh)


def _ascii_rows(table, mesh):
    """Vertex rows with every value written to round-trip (shortest repr), then faces."""
    cols = [table[name].tolist() for name in table.dtype.names]
    rows = [" ".join(map(repr, values)) for values in zip(*cols)]
    faces = np.split(mesh.face_vertices, mesh.face_offsets[1:-1])
    rows += [" ".join(map(str, [len(f), *f.tolist()])) for f in faces]
    return ("\n".join(rows) + "\n").encode("ascii")


def _face_bytes(mesh):
    """Each polygon as a uint8 corner count followed by int32 vertex ids."""
    sizes = mesh.face_sizes
    if sizes.size and (sizes == sizes[0]).all():  # one record type, no scatter: 1.4 -> 0.16 s
        k = int(sizes[0])
        table = np.empty(sizes.size, dtype=[("n", "u1"), ("ids", "<i4", (k,))])
        table["n"] = k
        table["ids"] = mesh.face_vertices.reshape(-1, k)
        return table.tobytes()
    start = np.concatenate([[0], np.cumsum(1 + 4 * sizes)[:-1]]).astype(np.int64)
    buf = np.zeros(int((1 + 4 * sizes).sum()), dtype=np.uint8)
    buf[start] = sizes.astype(np.uint8)
    local = np.arange(mesh.face_vertices.size) - np.repeat(mesh.face_offsets[:-1], sizes)
    pos = np.repeat(start, sizes) + 1 + 4 * local
    idx = mesh.face_vertices.astype("<i4").view(np.uint8).reshape(-1, 4)
    buf[pos[:, None] + np.arange(4)] = idx
    return buf.tobytes()
