"""The surface-mesh formats meshio reads and writes (VTK, VTU, Gmsh, XDMF, Nastran, ...),
registered in the format table when meshio is installed (``pip install 'srarap-cli[meshio]'``).

srarap's own readers keep OBJ, OFF, PLY and STL. A meshio file's triangles and quads are read
(2-D points get z = 0), with its 1-d point data as per-vertex properties; what no writer
keeps (volume cells, lines, cell data, point data of several components) is named in the
output's warning, and a file with no surface cell is refused in one line. Writes go through
a temporary file (meshio writes files, not bytes) and are committed like every output.
Without meshio these extensions are refused with a line that names the extra.
"""
import importlib.util
import os
import tempfile

import numpy as np

from ...runtime.errors import InputError
from .formats import MeshFormat, Written, register_format
from .mesh import Mesh

#: meshio's name -> (display name, extensions, whether per-vertex data comes back whole): the
#: formats whose triangles and quads meshio 5.3 writes and reads back exactly (the format
#: test round-trips each, with its point data where kept). Left out: SU2, Nastran, UGRID and
#: FLAC3D (meshio fails on triangle surfaces), XDMF, MED and Exodus (they need h5py or
#: netCDF4, not tried here), formats whose
#: extension another claims (Ansys' .msh, Tecplot's .dat, Dolfin's .xml), volume-only ones
#: (TetGen) and pictures (SVG, WKT)
TABLE = {
    "vtu": ("VTU", (".vtu",), True), "vtk": ("VTK", (".vtk",), True),
    "gmsh": ("Gmsh", (".msh",), True), "mdpa": ("Kratos MDPA", (".mdpa",), False),
    "abaqus": ("Abaqus", (".inp",), False), "avsucd": ("AVS-UCD", (".avs",), False),
    "medit": ("Medit", (".mesh", ".meshb"), False),
}
#: what meshio calls the writer of a format, where it differs (Gmsh 2.2 writes triangles and
#: quads together without the entity tables 4.1 asks for)
WRITERS = {"gmsh": "gmsh22"}
EXTRA = "pip install 'srarap-cli[meshio]'"
SURFACE = {"triangle": 3, "quad": 4}


def needs(extension: str) -> str | None:
    """For an extension a meshio format claims but that is not registered here: what to
    install for it (a one-line hint), else None.

    Examples
    --------
    >>> needs(".obj") is None
    True
    """
    for display, exts, _ in TABLE.values():
        if extension.lower() in exts and importlib.util.find_spec("meshio") is None:
            return f"{display} files need meshio: {EXTRA}"
    return None


def register_meshio_formats() -> list[str]:
    """Register every format of :data:`TABLE` whose modules are installed; returns their
    names. meshio itself is imported only when such a file is read or written."""
    if importlib.util.find_spec("meshio") is None:
        return []
    for name, (display, exts, keeps) in TABLE.items():
        register_format(MeshFormat(
            name, exts, _reader(name), _writer(name, exts[0], display, keeps), 20, _never,
            _description(display, keeps), signature_rank=100, keeps_vertex_data=keeps))
    return list(TABLE)


def _description(display, keeps):
    return (f"{display} through meshio (`srarap-cli[meshio]`): triangles and quads"
            + (", 1-d point data" if keeps else ""))


def _never(head: bytes, size: int | None) -> bool:
    return False  # told by extension only: the native formats keep what standard input takes


def _reader(name):
    def read(path: str) -> Mesh:
        import meshio

        try:
            m = meshio.read(path, file_format=name)
        except (meshio.ReadError, ValueError, KeyError, IndexError, EOFError) as exc:
            raise InputError(f"{path}: not a readable {name} file ({str(exc)[:120]})") from None
        return _surface(m, path)
    return read


def _surface(m, path):
    """The triangles and quads of a meshio.Mesh as a :class:`Mesh`."""
    faces = [np.asarray(b.data, np.int64) for b in m.cells if b.type in SURFACE]
    if not faces:
        kinds = ", ".join(sorted({b.type for b in m.cells})) or "none"
        raise InputError(f"{path}: no triangle or quad cells (cells: {kinds}); srarap deforms "
                         "surfaces: extract the boundary first")
    points = np.asarray(m.points, float)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise InputError(f"{path}: points of shape {points.shape}, not 2-d or 3-d")
    V = np.column_stack([points, np.zeros(len(points))]) if points.shape[1] == 2 else points
    mesh = Mesh(vertices=V, face_sizes=np.concatenate([np.full(len(f), f.shape[1]) for f in faces]),
                face_vertices=np.concatenate([f.ravel() for f in faces]))
    for key, values in m.point_data.items():
        if ":" in key:  # the format's own bookkeeping (gmsh:dim_tags), not the user's data
            continue
        values = np.asarray(values)
        if values.shape == (len(V),) and values.dtype.kind in "fiu":
            mesh.vertex_data[key] = values.astype(float)
        else:
            mesh.unkept.append(f"point data {key!r} of shape {values.shape}")
    other = sorted({b.type for b in m.cells} - set(SURFACE))
    if other:
        mesh.unkept.append(f"{', '.join(other)} cells")
    data = sorted(k for k in m.cell_data if ":" not in k)
    if data:
        mesh.unkept.append(f"cell data ({', '.join(data)})")
    return mesh


def _writer(name, extension, display, keeps):
    def write(mesh: Mesh, ascii: bool) -> Written:
        import meshio

        cells, lost = _cells(mesh)
        data = {k: np.asarray(v) for k, v in mesh.vertex_data.items()} if keeps else {}
        if mesh.vertex_data and not keeps:
            lost.append(f"per-vertex data ({', '.join(sorted(mesh.vertex_data))}) not written: "
                        f"{display} keeps positions and faces; write .vtu to keep it")
        out = meshio.Mesh(mesh.vertices, cells, point_data=data)
        with tempfile.TemporaryDirectory(prefix="srarap-meshio-") as folder:
            path = os.path.join(folder, "mesh" + extension)
            meshio.write(path, out, file_format=WRITERS.get(name, name))
            with open(path, "rb") as fh:
                return fh.read(), lost
    return write


def _cells(mesh):
    """Triangles, then quads (a mixed mesh's faces come back in that order); larger
    polygons split into triangles, with a warning."""
    sizes, lost = mesh.face_sizes, []
    if (sizes > 4).any():
        lost.append("polygons of more than 4 corners written as triangles")
        tris = mesh.triangles()[0]
        return [("triangle", tris)], lost
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    cells = []
    for size, kind in ((3, "triangle"), (4, "quad")):
        rows = np.flatnonzero(sizes == size)
        if rows.size:
            idx = offsets[rows][:, None] + np.arange(size)
            cells.append((kind, mesh.face_vertices[idx]))
    return cells, lost


def markdown_table() -> str:
    """The formats as the README's Markdown table: the registered ones, then every meshio
    format whether installed or not (a test keeps the two equal)."""
    from .formats import FORMATS

    rows = ["| format | extensions | reads and writes |", "|---|---|---|"]
    native = [f for f in FORMATS.values() if f.name not in TABLE]
    for fmt in native:
        rows.append(f"| `{fmt.name}` | {', '.join(f'`{e}`' for e in fmt.extensions)} | "
                    f"{fmt.description} |")
    for name, (display, exts, keeps) in TABLE.items():
        rows.append(f"| `{name}` | {', '.join(f'`{e}`' for e in exts)} | "
                    f"{_description(display, keeps)} |")
    return "\n".join(rows) + "\n"


register_meshio_formats()
