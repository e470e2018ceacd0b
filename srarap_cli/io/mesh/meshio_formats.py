"""The surface-mesh formats meshio reads and writes (VTK, VTU, Gmsh, XDMF, Exodus, MED, ...),
registered in the format table when meshio is installed (``pip install 'srarap-cli[meshio]'``,
which brings h5py and netCDF4 for the HDF5 and NetCDF formats too).

srarap's own readers keep OBJ, OFF, PLY and STL. A meshio file's triangles and quads are read
(2-D points get z = 0; a quad with a repeated corner, how Tecplot and other FE formats store
a triangle, is a triangle), with its 1-d point data as per-vertex properties; what no writer
keeps (volume cells, lines, cell data, point data of several components) is named in the
output's warning, and a file with no surface cell is refused in one line. Writes go through
a temporary file (meshio writes files, not bytes) and are committed like every output; a
format that stamps the time into its files gets a fixed stamp, so outputs stay
byte-identical. Without the modules a format needs, its extensions are refused with a line
that names the extra.
"""
import contextlib
import gzip
import importlib.util
import io
import os
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ...runtime.bounded import OutOfMemory, OutOfTime, run_bounded, time_bound
from ...runtime.errors import InputError, OutputError
from ...runtime.limits import available_memory, memory_note
from .formats import MeshFormat, Written, register_format
from .mesh import Mesh


@dataclass(frozen=True)
class Spec:
    """How srarap uses one meshio format.

    Attributes
    ----------
    display : str, the format's name in messages and the README
    extensions : tuple of str, lower-case with the dot; the first is written
    keeps_data : bool, 1-d point data is written and comes back whole
    needs : tuple of str, modules besides meshio that its reader and writer import
    quads : bool, the format keeps quads (else they are written as two triangles, said)
    options : dict, keyword arguments of meshio's writer
    meshio : str, meshio's name of the format, where it differs from srarap's
    writer : str, meshio's name of the writer, where it differs from the reader's
    gzip : bool, the file is gzip-compressed (srarap compresses with no time stamp)
    settle : callable(path), optional: after meshio wrote ``path``, put fixed values where
        the writer stamped the time
    own_data : tuple of str, point data the writer adds itself (not read back as the user's)
    """

    display: str
    extensions: tuple[str, ...]
    keeps_data: bool
    needs: tuple[str, ...] = ()
    quads: bool = True
    options: dict = field(default_factory=dict)
    meshio: str = ""
    writer: str = ""
    gzip: bool = False
    settle: Callable[[str], None] | None = None
    own_data: tuple[str, ...] = ()


def _exodus_title(path):
    import netCDF4

    with netCDF4.Dataset(path, "a") as root:  # meshio writes "Created by meshio, <now>"
        root.title = "Created by srarap through meshio"


def _h5m_history(path):
    import h5py

    with h5py.File(path, "r+") as root:  # meshio writes [module, version, <now>]
        root["tstt/history"][2] = b"-"


#: meshio's name -> how srarap uses it: the formats whose triangles and quads meshio 5.3
#: writes and reads back exactly (the format test round-trips each, with its point data
#: where kept). Left out: Nastran (meshio asserts on a negative coordinate at full
#: precision, and rounds the rest to 12 digits), SU2 (a 3-D surface there is a boundary
#: marker; meshio's writer fails on one), UGRID and CGNS (meshio cannot read back its own
#: triangle file), FLAC3D and TetGen (volume cells only), Ansys' .msh (Gmsh's extension),
#: SVG and WKT (pictures, not meshes)
TABLE = {
    "vtu": Spec("VTU", (".vtu",), True), "vtk": Spec("VTK", (".vtk",), True),
    "gmsh": Spec("Gmsh", (".msh",), True, writer="gmsh22"),
    "xdmf": Spec("XDMF", (".xdmf", ".xmf"), True, ("h5py",), options={"data_format": "XML"}),
    "exodus": Spec("Exodus", (".e", ".exo", ".ex2"), True, ("netCDF4",), settle=_exodus_title),
    "med": Spec("MED", (".med",), True, ("h5py",)),
    "hmf": Spec("HMF", (".hmf",), True, ("h5py",)),
    "h5m": Spec("MOAB H5M", (".h5m",), True, ("h5py",), quads=False, settle=_h5m_history,
                own_data=("GLOBAL_ID",)),
    "tecplot": Spec("Tecplot", (".dat", ".tec"), True),
    "mdpa": Spec("Kratos MDPA", (".mdpa",), False),
    "abaqus": Spec("Abaqus", (".inp",), False), "avsucd": Spec("AVS-UCD", (".avs",), False),
    "medit": Spec("Medit", (".mesh", ".meshb"), False),
    "permas": Spec("PERMAS", (".post", ".dato"), False),
    "permas-gz": Spec("gzipped PERMAS", (".post.gz", ".dato.gz"), False, meshio="permas",
                      gzip=True),
    "netgen": Spec("Netgen", (".vol",), False),
    "netgen-gz": Spec("gzipped Netgen", (".vol.gz",), False, meshio="netgen", gzip=True),
    "dolfin-xml": Spec("DOLFIN XML", (".xml",), False, quads=False),
}
EXTRA = "pip install 'srarap-cli[meshio]'"
SURFACE = {"triangle": 3, "quad": 4}


def _installed(spec: Spec) -> bool:
    return all(importlib.util.find_spec(m) is not None for m in ("meshio",) + spec.needs)


def needs(path: str) -> str | None:
    """For a path whose extension a meshio format claims but that is not registered here
    (its modules are missing): what to install for it (a one-line hint), else None.

    Examples
    --------
    >>> needs("part.obj") is None
    True
    """
    name = os.path.basename(str(path)).lower()
    for spec in TABLE.values():
        if any(name.endswith(e) for e in spec.extensions) and not _installed(spec):
            modules = ", ".join(("meshio",) + spec.needs)
            return f"{spec.display} files need {modules}: {EXTRA}"
    return None


def register_meshio_formats() -> list[str]:
    """Register every format of :data:`TABLE` whose modules are installed; returns their
    names. meshio itself is imported only when such a file is read or written."""
    added = [name for name, spec in TABLE.items() if _installed(spec)]
    for name in added:
        spec = TABLE[name]
        register_format(MeshFormat(
            name, spec.extensions, _reader(spec.meshio or name, spec),
            _writer(spec.meshio or name, spec), 20, _never, _description(spec),
            signature_rank=100,
            keeps=frozenset({"quads"} if spec.quads else set())
            | ({"vertex_data"} if spec.keeps_data else set())))
    return added


def _description(spec):
    faces = "triangles and quads" if spec.quads else "triangles (quads written as two)"
    return (f"{spec.display} through meshio (`srarap-cli[meshio]`): {faces}"
            + (", 1-d point data" if spec.keeps_data else ""))


def _never(head: bytes, size: int | None) -> bool:
    return False  # told by extension only: the native formats keep what standard input takes


def _reader(name, spec):
    def read(path: str) -> Mesh:
        seconds = time_bound(os.path.getsize(path))
        try:
            return run_bounded(_read, name, spec, path, seconds=seconds,
                               memory=available_memory(), preload=("meshio",))
        except OutOfTime:
            raise InputError(f"{path}: meshio's {spec.display} reader did not finish in "
                             f"{seconds:.0f} s; stopped (a truncated or damaged file?)") from None
        except OutOfMemory:
            raise InputError(f"{path}: reading it needs more memory than srarap may use "
                             f"({memory_note()}): a count the file declares is too large "
                             "for it (a damaged file?)") from None
    return read


def _read(name, spec, path):
    """The file read by meshio's reader of ``name`` (in a bounded child process: see
    :mod:`srarap_cli.runtime.bounded`), as a :class:`Mesh`."""
    # the format's own reader (dolfin-xml's is meshio.dolfin): meshio.read prints and exits
    # the process when it fails
    reader = importlib.import_module(f"meshio.{name.removesuffix('-xml')}").read
    try:
        with _quiet():
            m = _gunzipped(reader, path, spec) if spec.gzip else reader(path)
        return _surface(m, path, spec.own_data)  # what it read may hold anything too
    except (MemoryError, FileNotFoundError, PermissionError, IsADirectoryError, InputError):
        raise
    except Exception as exc:  # meshio's parsers fail on a bad file with any error at all
        raise InputError(f"{path}: not a readable {spec.display} file "
                         f"({type(exc).__name__}: {str(exc)[:120]})") from None


def _quiet():
    """meshio prints notes on its own bookkeeping to the console ("Appending zeros to
    replace the missing physical tag data", "DOLFIN XML is a legacy format"): not the user's
    data, which srarap's own warnings account for, and not one line per problem."""
    return contextlib.redirect_stderr(io.StringIO())


#: a compressed mesh may decompress to this many times its size at most (text meshes
#: compress 3-10 times; gzip's own limit is about 1000)
MAX_RATIO, MIN_UNPACKED = 100, 64 << 20


def _gunzipped(reader, path, spec):
    """``reader`` of the decompressed file (meshio's PERMAS reader reads no gzip), its size
    bounded (a 2 MiB file wrote 2 GiB into the temporary folder)."""
    bound = max(MIN_UNPACKED, MAX_RATIO * os.path.getsize(path))
    with gzip.open(path, "rb") as packed, tempfile.TemporaryDirectory(prefix="srarap-") as dir:
        plain = os.path.join(dir, "mesh" + spec.extensions[0].removesuffix(".gz"))
        with open(plain, "wb") as out:
            while chunk := packed.read(1 << 20):
                if out.tell() + len(chunk) > bound:
                    raise InputError(f"{path}: decompresses to more than {bound >> 20} MiB "
                                     f"({MAX_RATIO} times its size): not a mesh srarap reads "
                                     "(a damaged or hostile file?)")
                out.write(chunk)
        return reader(plain)


def _surface(m, path, own_data=()):
    """The triangles and quads of a meshio.Mesh as a :class:`Mesh`: triangles first, then
    quads (the order srarap writes them in); a quad with a repeated corner is a triangle."""
    blocks = sorted((b for b in m.cells if b.type in SURFACE), key=lambda b: SURFACE[b.type])
    if not blocks:
        kinds = ", ".join(sorted({b.type for b in m.cells})) or "none"
        raise InputError(f"{path}: no triangle or quad cells (cells: {kinds}); srarap deforms "
                         "surfaces: extract the boundary first")
    points = np.asarray(m.points, float)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise InputError(f"{path}: points of shape {points.shape}, not 2-d or 3-d")
    V = np.column_stack([points, np.zeros(len(points))]) if points.shape[1] == 2 else points
    sizes, corners = zip(*(_corners(np.asarray(b.data, np.int64)) for b in blocks))
    mesh = Mesh(vertices=V, face_sizes=np.concatenate(sizes),
                face_vertices=np.concatenate(corners))
    for key, values in m.point_data.items():
        if ":" in key or key in own_data:  # the format's bookkeeping (gmsh:dim_tags, ...)
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


def _corners(faces):
    """(sizes, flat corners) of one block of faces, in order; a quad whose corners repeat
    one next to another (cyclically) loses the repeat and is a triangle."""
    if faces.shape[1] != 4:
        return np.full(len(faces), faces.shape[1]), faces.ravel()
    repeat = faces == np.roll(faces, -1, axis=1)
    keep = ~repeat
    keep[repeat.sum(axis=1) != 1] = True  # two repeats or none: leave it to the mesh checks
    return keep.sum(axis=1), faces[keep]


def _writer(name, spec):
    def write(mesh: Mesh, ascii: bool) -> Written:
        import meshio

        cells = _cells(mesh, spec.quads)  # what it drops is said from the format's keeps
        data = {k: np.asarray(v) for k, v in mesh.vertex_data.items()} if spec.keeps_data else {}
        out = meshio.Mesh(mesh.vertices, cells, point_data=data)
        extension = spec.extensions[0].removesuffix(".gz")
        try:
            with tempfile.TemporaryDirectory(prefix="srarap-meshio-") as folder:
                path = os.path.join(folder, "mesh" + extension)
                with _quiet():
                    meshio.write(path, out, file_format=spec.writer or name, **spec.options)
                if spec.settle is not None:
                    spec.settle(path)
                with open(path, "rb") as fh:
                    content = fh.read()
        except OSError as exc:  # meshio writes a file: a full TMPDIR said only "No space left"
            raise OutputError(f"{tempfile.gettempdir()}: cannot write the {spec.display} file "
                              f"meshio makes there ({exc.strerror or exc}); set TMPDIR to a "
                              "folder with room") from None
        return (gzip.compress(content, mtime=0) if spec.gzip else content), []
    return write


def _cells(mesh, quads=True):
    """Triangles, then quads (a mixed mesh's faces come back in that order); the larger
    polygons alone, and quads where the format keeps none, split into triangles (a fan from
    each one's first corner, after the mesh's own triangles): one pentagon among quads
    turned every quad into two triangles."""
    sizes = mesh.face_sizes
    largest = 4 if quads else 3
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    split = np.flatnonzero(sizes > largest)
    triangles = [_faces_of(mesh, offsets, np.flatnonzero(sizes == 3), 3)]
    for size in np.unique(sizes[split]):
        rows = split[sizes[split] == size]
        corners = _faces_of(mesh, offsets, rows, int(size))
        triangles += [corners[:, [0, k, k + 1]] for k in range(1, int(size) - 1)]
    cells = []
    tris = np.concatenate(triangles) if len(triangles) > 1 else triangles[0]
    if len(tris):
        cells.append(("triangle", tris))
    if quads and (sizes == 4).any():
        cells.append(("quad", _faces_of(mesh, offsets, np.flatnonzero(sizes == 4), 4)))
    return cells


def _faces_of(mesh, offsets, rows, size):
    """(len(rows), size) corners of the faces ``rows``, all of ``size`` corners."""
    return mesh.face_vertices[offsets[rows][:, None] + np.arange(size)].reshape(-1, size)


def markdown_table() -> str:
    """The formats as the README's Markdown table: the registered ones, then every meshio
    format whether installed or not (a test keeps the two equal)."""
    from .formats import FORMATS

    rows = ["| format | extensions | reads and writes |", "|---|---|---|"]
    native = [f for f in FORMATS.values() if f.name not in TABLE]
    for fmt in native:
        rows.append(f"| `{fmt.name}` | {', '.join(f'`{e}`' for e in fmt.extensions)} | "
                    f"{fmt.description} |")
    for name, spec in TABLE.items():
        rows.append(f"| `{name}` | {', '.join(f'`{e}`' for e in spec.extensions)} | "
                    f"{_description(spec)} |")
    return "\n".join(rows) + "\n"


register_meshio_formats()
