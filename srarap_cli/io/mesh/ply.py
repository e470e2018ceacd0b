"""PLY writer (the reader is :mod:`.ply_read`) and STL through meshio.

meshio stamps the current time into PLY headers it writes; this writer does not, so the
same mesh always gives the same bytes.
"""
import numpy as np

from .mesh import Mesh

_PLY_TYPES = {"u1": "uchar", "i1": "char", "u2": "ushort", "i2": "short", "u4": "uint",
              "i4": "int", "f4": "float", "f8": "double"}


def mesh_from_meshio(m):
    """Convert a ``meshio.Mesh`` read from an STL file to :class:`Mesh` (triangles only)."""
    blocks = [c.data for c in m.cells if c.type in ("triangle", "quad", "polygon")]
    sizes = np.concatenate([np.full(len(b), b.shape[1]) for b in blocks]) if blocks else []
    corners = np.concatenate([b.ravel() for b in blocks]) if blocks else []
    points = np.asarray(m.points, dtype=float)
    if points.ndim != 2 or points.shape[1] < 3:  # an empty or facet-less file
        points = np.zeros((0, 3))
    return Mesh(vertices=points[:, :3], face_sizes=np.asarray(sizes, dtype=np.int64),
                face_vertices=np.asarray(corners, dtype=np.int64))


def per_vertex(mesh, values, refs):
    """``values`` as one row per vertex, or None when corners of a vertex disagree."""
    if values is None:
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


def format_ply(mesh, ascii=False):
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


def format_stl(mesh):
    """Binary STL bytes of the mesh's triangles (polygons fanned), deterministic header."""
    F = mesh.triangles()[0]
    tri = mesh.vertices[F]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    normal = np.divide(normal, length, out=np.zeros_like(normal), where=length > 0)
    record = np.zeros(len(F), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    record["n"], record["v"] = normal, tri
    header = b"binary STL written by srarap".ljust(80, b" ")
    return header + np.uint32(len(F)).tobytes() + record.tobytes()


def _face_bytes(mesh):
    """Each polygon as a uint8 corner count followed by int32 vertex ids."""
    sizes = mesh.face_sizes
    start = np.concatenate([[0], np.cumsum(1 + 4 * sizes)[:-1]]).astype(np.int64)
    buf = np.zeros(int((1 + 4 * sizes).sum()), dtype=np.uint8)
    buf[start] = sizes.astype(np.uint8)
    local = np.arange(mesh.face_vertices.size) - np.repeat(mesh.face_offsets[:-1], sizes)
    pos = np.repeat(start, sizes) + 1 + 4 * local
    idx = mesh.face_vertices.astype("<i4").view(np.uint8).reshape(-1, 4)
    buf[pos[:, None] + np.arange(4)] = idx
    return buf.tobytes()
