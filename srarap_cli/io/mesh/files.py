"""Read and write mesh files by format; see the package's docstring."""
import contextlib
import os
from collections.abc import Callable, Iterator, Sequence
from dataclasses import replace

import numpy as np

from ...runtime.bounded import OutOfMemory, OutOfTime, map_forked, start_bounded, time_bound
from ...runtime.commit import atomic_write
from ...runtime.errors import InputError, OutputError
from ...runtime.limits import MAX_COORDINATE, check_read
from .formats import HEAD_BYTES, MeshFormat, by_content, by_extension, extensions, suffix_of
from .mesh import Mesh
from .meshio_formats import needs
from .obj import obj_faces_and_positions
from .sniff import not_a_mesh
from .stream import read_mesh_stream


def _listed():
    return ", ".join(extensions())


def read_mesh(path: str | os.PathLike, fmt: MeshFormat | None = None) -> Mesh:
    """Read any registered format (OBJ, OFF, PLY, STL, ...; see :mod:`.formats`) into a
    :class:`Mesh`: as ``fmt``, by the file's extension, or, for a name whose extension no
    format claims (none, ``.txt``, ``/dev/stdin``, a pipe), by its first bytes.

    Raises
    ------
    InputError : the file is missing, unreadable, of another format or invalid.
    TypeError : ``path`` is not a path.
    """
    return open_mesh(path, fmt)[0]


def read_frames(paths: Sequence[str], parts: int = 1) -> list[Mesh]:
    """The meshes of an animation's frames, in ``parts`` processes (a parse holds the GIL):
    the first read whole, and each later OBJ frame whose face lines are the first's by its
    positions alone (:func:`.obj.obj_faces_and_positions`; checked as :func:`read_mesh`
    checks positions), its faces, texture coordinates and statements the first's and its
    normals left out; any other frame read whole.

    Raises InputError as :func:`read_mesh` does, naming the frame's file.
    """
    first = read_mesh(paths[0])
    simple = obj_faces_and_positions(paths[0]) if suffix_of(paths[0]) == ".obj" else None
    faces = None if simple is None else simple[0]

    def one(path):
        got = obj_faces_and_positions(path) if faces and suffix_of(path) == ".obj" else None
        if got is None or got[0] != faces or len(got[1]) != len(first.vertices):
            return read_mesh(path)
        _validate(replace(first, vertices=got[1]), path)
        return got[1]
    seconds = time_bound(sum(os.path.getsize(p) for p in paths if os.path.isfile(p)))
    rest = map_forked(one, list(paths[1:]), parts, seconds)
    return [first] + [replace(first, vertices=r, normals=None, face_normals=None)
                      if isinstance(r, np.ndarray) else r for r in rest]


@contextlib.contextmanager
def reading_beside(path: str | None) -> Iterator[Callable[[], Mesh | None]]:
    """``read_mesh(path)`` in a child process while this one reads another file: the block
    gets a function that waits for the mesh (None for no ``path``) or raises what
    :func:`read_mesh` raises. Leaving the block early stops the child. Two 738k-vertex OBJ
    files, one each side, take the time of one (a parse holds the GIL: threads would not).
    Read here, at the call, where this process may not fork (other threads run: see
    :mod:`srarap_cli.runtime.forking`) or where ``SRARAP_BOUNDED=0``.
    """
    if path is None:
        yield lambda: None
        return
    try:
        seconds = time_bound(os.path.getsize(path))
    except (OSError, TypeError, ValueError):
        seconds = time_bound(0)  # read_mesh says what is wrong with the path
    with start_bounded(read_mesh, path, seconds=seconds, memory=None,
                       need="beside") as call:
        def result() -> Mesh | None:
            try:
                return call.result()
            except OutOfTime:
                raise InputError(f"{path}: not read in {seconds:.0f} s; stopped (a damaged "
                                 "file?)") from None
            except OutOfMemory as exc:
                raise MemoryError(f"{path}: {exc}") from None

        yield result


def open_mesh(path: str | os.PathLike, fmt: MeshFormat | None = None
              ) -> tuple[Mesh, MeshFormat]:
    """``(mesh, format)`` of the file ``path``, read as :func:`read_mesh` reads it."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"path must be a file path (str or os.PathLike), got "
                        f"{type(path).__name__}")
    path = os.fsdecode(path)
    if os.path.isdir(path):
        raise InputError(f"{path}: is a folder, not a mesh file")
    fmt = fmt or by_extension(path)
    if fmt is None and (hint := needs(path)):
        raise InputError(f"{path}: {hint}")
    if fmt is None:
        if not os.path.isfile(path):  # a pipe, a device, a process substitution: one pass
            return _read_stream(path)
        fmt = _by_content(path)
    check_read(path, fmt.read_factor)
    try:
        mesh = fmt.read(path)
    except InputError:
        raise
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read: {getattr(exc, 'strerror', None) or exc}") \
            from None
    _validate(mesh, path)
    return mesh, fmt


def _by_content(path):
    """The format of the regular file ``path`` from its first bytes."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(HEAD_BYTES)
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    fmt = by_content(head, os.path.getsize(path))
    if fmt is None:
        raise InputError(not_a_mesh(path, head))
    return fmt


def _read_stream(path):
    try:
        stream = open(path, "rb")
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    with stream:
        mesh, fmt = read_mesh_stream(stream, name=path)
    _validate(mesh, path)
    return mesh, fmt


def _validate(mesh, path):
    n = len(mesh.vertices)
    if n == 0 or mesh.face_sizes.size == 0:
        raise InputError(f"{path}: mesh has no {'vertices' if n == 0 else 'faces'}")
    if not np.isfinite(mesh.vertices).all():
        bad = int(np.flatnonzero(~np.isfinite(mesh.vertices).all(axis=1))[0])
        raise InputError(f"{path}: vertex {bad} has a NaN or infinite coordinate")
    huge = np.abs(mesh.vertices).max(axis=1) > MAX_COORDINATE
    if huge.any():
        raise InputError(f"{path}: vertex {int(np.flatnonzero(huge)[0])} has a coordinate "
                         f"beyond {MAX_COORDINATE:g} (its square would overflow); rescale the mesh")
    fv = mesh.face_vertices
    if fv.min() < 0 or fv.max() >= n:
        raise InputError(f"{path}: a face references vertex "
                         f"{int(fv.min() if fv.min() < 0 else fv.max())}, "
                         f"but the mesh has vertices 0..{n - 1}")


def frame_formatter(mesh: Mesh, suffix: str) -> Callable[[np.ndarray], bytes]:
    """``frame(positions) -> bytes``: the file of ``mesh`` with other positions (n, 3) in the
    format of ``suffix``, as :func:`format_mesh` writes it; an OBJ's faces, statements and
    texture coordinates are formatted once for every frame (a 50k-vertex tube with uvs:
    about 0.09 s of each frame's 0.14 s of formatting)."""
    return _writable(suffix).frame_writer(mesh)


def format_mesh(mesh: Mesh, suffix: str, ascii: bool = False) -> tuple[bytes, list[str]]:
    """File content for ``mesh`` in the format of the extension ``suffix`` (``.obj``; a text
    variant with ``ascii`` where the format has one), with warnings for lost data."""
    return _writable(suffix).encode(mesh, ascii)


def _writable(suffix):
    fmt = by_extension("x" + suffix)
    if fmt is None and (hint := needs("x" + suffix)):
        raise InputError(f"{suffix}: {hint}")
    if fmt is None:
        raise OutputError(f"cannot write {suffix or 'files without extension'}; "
                          f"use one of {_listed()}")
    return fmt


def write_mesh(path: str | os.PathLike, mesh: Mesh) -> list[str]:
    """Write ``mesh`` to ``path`` (format from the extension) atomically.

    Parameters
    ----------
    path : str or PathLike, with a registered extension (``.obj``, ``.off``, ``.ply``,
        ``.stl``, ...)
    mesh : Mesh, or anything :func:`srarap_cli.solver.api_checks.mesh_like` takes (a
        ``(V, F)`` pair, a trimesh or meshio mesh)

    Returns
    -------
    list of str : warnings about data the format cannot hold
    """
    if not isinstance(path, (str, os.PathLike)):
        swapped = " (the arguments are (path, mesh))" if isinstance(mesh, (str, os.PathLike)) \
            else ""
        raise TypeError(f"path must be a file path, got {type(path).__name__}{swapped}")
    if not isinstance(mesh, Mesh):
        from ...solver.api_checks import mesh_like

        mesh = Mesh.from_arrays(*mesh_like(mesh))
    fmt = by_extension(str(path))
    if fmt is None and (hint := needs(str(path))):
        raise InputError(f"{path}: {hint}")
    if fmt is None:
        suffix = suffix_of(str(path))
        raise OutputError(f"{path}: cannot write {suffix or 'files without extension'}; "
                          f"use one of {_listed()}")
    data, lost = fmt.encode(mesh)
    atomic_write(path, data)
    return lost
