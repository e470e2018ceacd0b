"""The one table of mesh formats: name, extensions, reader, writer, read-memory factor and a
content signature. The command line's choices and help, the memory guard, ``read_mesh``,
``write_mesh``, standard input's format detection and the README's format table all come
from :data:`FORMATS`; a new format is one :func:`register_format` call (from any module,
inside the package or not) and nothing else.
"""
import re
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...runtime.warning_codes import coded
from .keeps import drops
from .mesh import Mesh
from .normals import recompute_normals
from .obj import format_obj, obj_frames, read_obj
from .off import format_off, read_off
from .ply import format_ply, per_vertex
from .ply_read import read_ply
from .stl import format_stl, read_stl

#: what a writer returns: the file's bytes and a warning per kind of data the format lost
Written = tuple[bytes, list[str]]


@dataclass(frozen=True)
class MeshFormat:
    """One mesh file format.

    Attributes
    ----------
    name : str, the value of ``--input-format`` and ``--format`` (``obj``)
    extensions : tuple of str, lower-case with the dot (``(".obj",)``); the first is the
        one this format is known by
    read : callable(path) -> Mesh, raising InputError for a bad file
    write : callable(mesh, ascii) -> (bytes, warnings); ``ascii`` asks for a text variant
        where the format has one (``has_ascii``)
    read_factor : float, bytes of memory parsing holds per byte of file (the memory guard
        refuses a file whose parse would not fit)
    signature : callable(head, size) -> bool, whether content starting with the bytes
        ``head`` (up to :data:`HEAD_BYTES`) in a file of ``size`` bytes is of this format;
        ``size`` is None for a stream not read to its end (the format is decided from the
        first bytes, before the rest is spooled)
    description : str, one line for the README's table
    signature_rank : int, signatures are asked in this order (lowest first): an exact test
        (binary STL's size, PLY's magic line) before one on first words (OFF, OBJ)
    has_ascii : bool, ``--ascii`` applies
    keeps : frozenset of str, the kinds of :data:`.keeps.KINDS` the format writes (quads,
        polygons, texture coordinates, normals, per-vertex data, OBJ statements); what a
        mesh holds of the others is said in a warning (:meth:`encode`), so a format that
        does not declare a kind cannot drop it silently
    frames : callable(mesh) -> callable(positions) -> bytes, optional; the bytes of
        ``mesh`` with other positions, faster than ``write`` per frame (animations)
    """

    name: str
    extensions: tuple[str, ...]
    read: Callable[[str], Mesh]
    write: Callable[[Mesh, bool], Written]
    read_factor: float
    signature: Callable[[bytes, int | None], bool]
    description: str = ""
    signature_rank: int = 50
    has_ascii: bool = False
    keeps: frozenset[str] = frozenset()
    frames: Callable[[Mesh], Callable[[np.ndarray], bytes]] | None = None

    @property
    def extension(self) -> str:
        return self.extensions[0]

    @property
    def keeps_vertex_data(self) -> bool:
        """Other per-vertex properties (``Mesh.vertex_data``) are written
        (``--write-distortion`` applies)."""
        return "vertex_data" in self.keeps

    def encode(self, mesh: Mesh, ascii: bool = False) -> Written:
        """``write``'s bytes and warnings: the writer's own, one per kind ``mesh`` holds that
        the format does not keep (:func:`.keeps.drops`, from :attr:`keeps`), and what the
        file ``mesh`` was read from held and no writer keeps (:attr:`Mesh.unkept`); each one
        coded ``format-drops``, so ``strict`` catches it."""
        data, lost = self.write(mesh, ascii)
        keepers = {kind: fmt.extension for fmt in reversed(FORMATS.values())
                   for kind in fmt.keeps}
        lost = drops(mesh, self.name.upper(), self.keeps, keepers) + lost
        if mesh.unkept:
            lost = lost + [f"not written: {'; '.join(mesh.unkept)} of the input (srarap "
                           "keeps vertices, faces and per-vertex properties)"]
        return data, [coded(w, "format-drops") for w in lost]

    def frame_writer(self, mesh: Mesh) -> Callable[[np.ndarray], bytes]:
        """``frame(positions) -> bytes``: the file of ``mesh`` with other positions (n, 3)."""
        if self.frames is not None:
            return self.frames(mesh)
        return lambda positions: self.write(mesh.with_vertices(positions), False)[0]


#: bytes of a file's start that the signatures look at
HEAD_BYTES = 4096
FORMATS: dict[str, MeshFormat] = {}


def register_format(fmt: MeshFormat) -> MeshFormat:
    """Add ``fmt`` to :data:`FORMATS` (replacing a format of the same name). Raises
    ValueError when another format already claims one of its extensions."""
    for other in FORMATS.values():
        taken = set(other.extensions) & set(fmt.extensions)
        if other.name != fmt.name and taken:
            raise ValueError(f"extension {sorted(taken)[0]} is already {other.name}'s")
    FORMATS[fmt.name] = fmt
    return fmt


def extensions() -> list[str]:
    """Every registered extension (``.obj``, ...)."""
    return [ext for fmt in FORMATS.values() for ext in fmt.extensions]


def suffix_of(path: str) -> str:
    """``path``'s extension, lower-case: the longest one a format claims (``.vol.gz``),
    else the last one (``.txt``; "" for none).

    Examples
    --------
    >>> suffix_of("out/Part.OBJ"), suffix_of("notes.txt"), suffix_of("README")
    ('.obj', '.txt', '')
    """
    name = re.split(r"[/\\]", str(path))[-1].lower()
    claimed = [ext for ext in extensions() if name.endswith(ext) and len(name) > len(ext)]
    match = re.search(r"\.[^.]+$", name)
    return max(claimed, key=len) if claimed else (match.group(0) if match else "")


def by_extension(path: str) -> MeshFormat | None:
    """The format of ``path``'s extension (any case), or None."""
    ext = suffix_of(path)
    return next((fmt for fmt in FORMATS.values() if ext in fmt.extensions), None)


def by_content(head: bytes, size: int | None) -> MeshFormat | None:
    """The format whose signature accepts ``head`` (a file's first bytes) and ``size``,
    asked by ``signature_rank``, or None."""
    ranked = sorted(FORMATS.values(), key=lambda fmt: fmt.signature_rank)
    return next((fmt for fmt in ranked if fmt.signature(head, size)), None)


def _first_words(head: bytes) -> list[bytes]:
    """The first word of each of the first lines of ``head`` that hold anything but a
    comment (``#``), a byte-order mark skipped."""
    text = head.removeprefix(b"\xef\xbb\xbf")
    words = []
    for line in text.splitlines()[:-1] or text.splitlines():
        line = line.split(b"#", 1)[0].split()
        if line:
            words.append(line[0])
    return words


def _is_ply(head: bytes, size: int | None) -> bool:
    return re.match(rb"(\xef\xbb\xbf)?ply\r?\n", head) is not None


def is_binary_stl(head: bytes, size: int | None) -> bool:
    """Whether content starting with ``head`` is binary STL: its size is 84 + 50 x its
    triangle count, or, on a stream (``size`` None), its first records are numbers."""
    if len(head) < 84 or (size is not None and size < 84):
        return False
    count = int(np.frombuffer(head[80:84], "<u4")[0])
    if size is not None:
        return 84 + 50 * count == size
    # a stream, whose size is not known yet: not text (a record's attribute bytes and the
    # low bytes of round numbers are zeros), and the triangles in ``head`` numbers a mesh
    # holds (random bytes give a NaN or a huge value in nearly every record)
    if min(head[84:], default=0) >= 9:
        return False
    numbers = _stl_numbers(head, min(count, (len(head) - 84) // 50))
    return count > 0 and bool(np.isfinite(numbers).all() and (np.abs(numbers) < 1e30).all())


def _stl_numbers(head: bytes, whole: int) -> np.ndarray:
    """The 12 numbers (normal, three corners) of each of the first ``whole`` records."""
    rows = np.frombuffer(head, np.uint8, count=50 * whole, offset=84).reshape(whole, 50)
    return np.ascontiguousarray(rows[:, :48]).view("<f4")


def _is_ascii_stl(head: bytes, size: int | None) -> bool:
    words = _first_words(head)
    # on a stream (size None) either variant is STL: the reader tells them apart by the size
    return bool(words) and words[0].lower() == b"solid" and (
        size is None or not is_binary_stl(head, size))


def _is_stl(head: bytes, size: int | None) -> bool:
    return is_binary_stl(head, size) or _is_ascii_stl(head, size)


def _is_off(head: bytes, size: int | None) -> bool:
    words = _first_words(head)
    return bool(words) and words[0].upper().endswith(b"OFF")


_OBJ_WORDS = {b"v", b"vt", b"vn", b"vp", b"f", b"l", b"p", b"o", b"g", b"s", b"mtllib",
              b"usemtl", b"cstype", b"deg", b"curv", b"surf"}


def _is_obj(head: bytes, size: int | None) -> bool:
    words = _first_words(head)
    return bool(words) and all(w in _OBJ_WORDS for w in words[:8])


def _write_obj(mesh: Mesh, ascii: bool) -> Written:
    return format_obj(mesh).encode("utf-8"), []


def _write_stl(mesh: Mesh, ascii: bool) -> Written:
    return format_stl(mesh), []


def _per_vertex_normals(mesh: Mesh) -> Mesh:
    """``mesh`` as a format with at most one normal per vertex holds it: per-corner normals
    averaged per vertex."""
    if mesh.normals is None or per_vertex(mesh, mesh.normals, mesh.face_normals) is not None:
        return mesh
    out = Mesh(**{k: getattr(mesh, k) for k in mesh.__dataclass_fields__})
    out.normals = np.zeros_like(mesh.vertices)
    out.face_normals = mesh.face_vertices
    out.normals = recompute_normals(out)
    return out


def _write_off(mesh: Mesh, ascii: bool) -> Written:
    return format_off(_per_vertex_normals(mesh)).encode("ascii"), []


def _write_ply(mesh: Mesh, ascii: bool) -> Written:
    return format_ply(_per_vertex_normals(mesh), ascii), []


# Measured on this project's machines (README, "Limits"): parsing text meshes holds about 17x
# the file size; binary ones a few times. The factors carry a safety margin.
register_format(MeshFormat(
    "obj", (".obj",), read_obj, _write_obj, 20, _is_obj,
    "polygons, texture coordinates, normals and statements (`mtllib`, `usemtl`, `g`, `s`) "
    "kept", signature_rank=90, frames=obj_frames,
    keeps=frozenset({"quads", "polygons", "uv", "uv_seams", "normals", "statements"})))
register_format(MeshFormat(
    "off", (".off",), read_off, _write_off, 20, _is_off,
    "ASCII, with the NOFF/COFF/STOFF prefixes; per-vertex normals kept", signature_rank=80,
    keeps=frozenset({"quads", "polygons", "normals"})))
register_format(MeshFormat(
    "ply", (".ply",), read_ply, _write_ply, 6, _is_ply,
    "binary (default) or ASCII (`--ascii`); per-vertex normals, texture coordinates and "
    "other per-vertex properties kept", signature_rank=10, has_ascii=True,
    keeps=frozenset({"quads", "polygons", "uv", "normals", "vertex_data"})))
register_format(MeshFormat(
    "stl", (".stl",), read_stl, _write_stl, 6, _is_stl,
    "binary or ASCII in, binary out; corners welded into shared vertices on reading, "
    "triangles only", signature_rank=0))
