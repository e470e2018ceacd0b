"""Read and write meshes, keeping vertex order, polygons, UVs and normals.

All four formats are parsed here: meshio fails on common variants of OBJ and OFF, trusts PLY
headers and does not check ASCII STL (:mod:`.stl` welds STL corners as meshio does). Writers
are deterministic (no timestamps) and atomic (temporary file in the target folder, then
rename), so a failed run never leaves a partial file behind.
"""
from ...runtime.commit import atomic_write
from .files import (
    format_mesh,
    frame_formatter,
    open_mesh,
    read_frames,
    read_mesh,
    reading_beside,
    write_mesh,
)
from .formats import FORMATS, HEAD_BYTES, MeshFormat, register_format
from .mesh import Mesh

__all__ = ["FORMATS", "HEAD_BYTES", "Mesh", "MeshFormat", "atomic_write", "format_mesh",
           "frame_formatter", "open_mesh", "read_frames", "read_mesh", "reading_beside", "register_format",
           "write_mesh"]
