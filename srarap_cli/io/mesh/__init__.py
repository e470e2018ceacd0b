"""Read and write meshes, keeping vertex order, polygons, UVs and normals.

All four formats are parsed here: meshio fails on common variants of OBJ and OFF, trusts PLY
headers and does not check ASCII STL (:mod:`.stl` welds STL corners as meshio does). Writers
are deterministic (no timestamps) and atomic (temporary file in the target folder, then
rename), so a failed run never leaves a partial file behind.
"""
import os
from collections.abc import Callable

import numpy as np

from ...runtime.commit import atomic_write
from ...runtime.errors import InputError, OutputError
from ...runtime.limits import MAX_COORDINATE, check_read
from .mesh import Mesh
from .normals import recompute_normals
from .obj import format_obj, obj_frames, read_obj
from .off import format_off, read_off
from .ply import format_ply, per_vertex
from .ply_read import read_ply
from .stl import format_stl, read_stl

READ_FORMATS = (".obj", ".off", ".ply", ".stl")
WRITE_FORMATS = (".obj", ".off", ".ply", ".stl")

__all__ = ["READ_FORMATS", "WRITE_FORMATS", "Mesh", "atomic_write", "read_mesh", "write_mesh"]


def _suffix(path):
    return os.path.splitext(str(path))[1].lower()


def read_mesh(path: str | os.PathLike) -> Mesh:
    """Read OBJ, OFF, PLY or STL into a :class:`Mesh`.

    Raises
    ------
    InputError : the file is missing, unreadable, of another format or invalid.
    """
    suffix = _suffix(path)
    if suffix not in READ_FORMATS:
        raise InputError(f"{path}: unsupported mesh format {suffix or '(none)'!r}; "
                         f"use one of {', '.join(READ_FORMATS)}")
    if os.path.isdir(path):
        raise InputError(f"{path}: is a folder, not a mesh file")
    check_read(path)
    try:
        if suffix == ".obj":
            mesh = read_obj(path)
        elif suffix == ".off":
            mesh = read_off(path)
        elif suffix == ".ply":
            mesh = read_ply(path)
        else:
            mesh = read_stl(path)
    except InputError:
        raise
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read: {getattr(exc, 'strerror', None) or exc}") \
            from None
    _validate(mesh, path)
    return mesh


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
    if suffix == ".obj":
        return obj_frames(mesh)
    return lambda positions: format_mesh(mesh.with_vertices(positions), suffix)[0]


def format_mesh(mesh: Mesh, suffix: str, ascii: bool = False) -> tuple[bytes, list[str]]:
    """File content for ``mesh`` in the format of ``suffix`` (PLY in ASCII with ``ascii``),
    with warnings for lost data."""
    lost: list[str] = []
    if suffix == ".obj":
        return format_obj(mesh).encode("utf-8"), lost
    if suffix == ".stl":
        if (mesh.face_sizes != 3).any() or mesh.uv is not None or mesh.normals is not None:
            lost.append("STL keeps only triangles in single precision: polygons split, "
                        "texture coordinates and normals not written, vertices not shared")
        return format_stl(mesh), lost
    if mesh.uv is not None and (suffix == ".off" or per_vertex(mesh, mesh.uv, mesh.face_uv) is None):
        lost.append(f"texture coordinates not written: {suffix[1:].upper()} stores at most one "
                    "per vertex; write .obj to keep them")
    if mesh.normals is not None and per_vertex(mesh, mesh.normals, mesh.face_normals) is None:
        mesh = _vertex_normals(mesh)
    if suffix == ".off":
        return format_off(mesh).encode("ascii"), lost
    return format_ply(mesh, ascii), lost


def _vertex_normals(mesh):
    """Per-corner normals (OBJ) become per-vertex normals for formats that only have those."""
    out = Mesh(**{k: getattr(mesh, k) for k in mesh.__dataclass_fields__})
    out.normals = np.zeros_like(mesh.vertices)
    out.face_normals = mesh.face_vertices
    out.normals = recompute_normals(out)
    return out


def write_mesh(path: str | os.PathLike, mesh: Mesh) -> list[str]:
    """Write ``mesh`` to ``path`` (format from the extension) atomically.

    Parameters
    ----------
    path : str or PathLike, ``.obj``, ``.off`` or ``.ply``
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
    suffix = _suffix(path)
    if suffix not in WRITE_FORMATS:
        raise OutputError(f"{path}: cannot write {suffix or 'files without extension'}; "
                          f"use one of {', '.join(WRITE_FORMATS)}")
    data, lost = format_mesh(mesh, suffix)
    atomic_write(path, data)
    return lost
