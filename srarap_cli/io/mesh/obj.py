"""Wavefront OBJ: polygons, per-corner texture and normal indices, other lines kept verbatim.

Written by hand because meshio drops ``vt``/``vn`` indices and rejects UV seams and
per-corner normals, and libigl's reader keeps no polygons of mixed size or other statements.
"""
import io
import re
import warnings
from collections.abc import Callable

import numpy as np

from ...runtime.errors import InputError, excerpt
from ..input_files import open_input
from .mesh import Mesh
from .numbers import parse_numbers


def _floats(rows, width, path, what):
    try:
        return np.array([r[:width] for r in rows], dtype=float).reshape(len(rows), width)
    except ValueError:
        raise InputError(f"{path}: malformed '{what}' line (expected {width} numbers)") from None


def _corner(token, counts, path, lineno):
    """Parse ``v``, ``v/vt``, ``v//vn`` or ``v/vt/vn`` into 0-based ids (-1 when absent)."""
    out = [-1, -1, -1]
    for k, part in enumerate(token.split("/")[:3]):
        if not part:
            continue
        try:
            idx = int(part)
        except ValueError:
            raise InputError(f"{path}:{lineno}: bad face index {excerpt(token, 20)!r}") from None
        if idx == 0:
            raise InputError(f"{path}:{lineno}: face index 0 (OBJ indices start at 1)")
        if abs(idx) > 2 ** 31:
            raise InputError(f"{path}:{lineno}: face index {idx} out of range")
        out[k] = idx - 1 if idx > 0 else counts[k] + idx
    return out


def read_obj(path: str) -> Mesh:
    """Read an OBJ file into a :class:`Mesh`, keeping vertex and face order."""
    with open_input(path, encoding="utf-8", errors="replace") as fh:
        text = fh.read()
    if "\\" in text:  # a one-character search is a tenth of the replace's time
        text = text.replace("\\\n", " ")
    return _read_bulk(text) or _read_general(text, path)


def obj_faces_and_positions(path: str) -> tuple[str, np.ndarray] | None:
    """The text of an OBJ file's face lines (as one block) and its positions (n, 3), the
    positions alone parsed: an animation's frames share their faces, and a frame whose face
    lines are the first's needs only its positions read (25 frames of a 5.8k-vertex mesh
    with texture coordinates: 2.7 -> 0.5 s). None for a file the bulk reader would not take
    whole (line continuations, other line breaks, a position of other than 3 numbers)."""
    with open_input(path, encoding="utf-8", errors="replace") as fh:
        text = fh.read()
    if "\\" in text or any(c in text for c in _ODD_BREAKS) or \
            ("\r" in text and text.count("\r") != text.count("\r\n")):
        return None
    V = _rows_of(*_block(text, "v"), 3)
    return None if V is None else (_block(text, "f")[0], V)


_HEADS = ("v", "vt", "vn", "f")
# a line that is none of "v ", "vt ", "vn ", "f ", a comment or blank: a statement to keep
_OTHER = re.compile(r"^(?!(?:v|vt|vn|f) |#|[ \t\r]*$).*$", re.M)
# line breaks other than \n (and \r\n) that str.splitlines, and so the general reader, obeys
_ODD_BREAKS = "\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"


def _read_bulk(text):
    """The mesh of a file whose ``f`` corners all have one form (``v``, ``v/t``, ``v//n`` or
    ``v/t/n``) with positive indices in range, parsed in bulk (a 500k-vertex file with
    texture coordinates: 6.8 -> 1.2 s); None for anything else, which
    :func:`_read_general` reads or reports. Statements are kept as that reader keeps them.
    """
    if any(c in text for c in _ODD_BREAKS) or \
            ("\r" in text and text.count("\r") != text.count("\r\n")):
        return None
    verts, uvs, norms, (faces, count) = (_block(text, h) for h in _HEADS)
    statements = _statements(text, verts[1] + uvs[1] + norms[1] + count)
    V = _rows_of(*verts, 3)
    lines = faces.split("\n") if count else []
    sizes = np.fromiter((len(f.split()) for f in lines), dtype=np.int64, count=count)
    corners = _uniform_corners(faces, int(sizes.sum()))
    if statements is None or V is None or corners is None or (sizes < 3).any():
        return None
    mesh = Mesh(vertices=V, face_sizes=sizes, face_vertices=corners[0] - 1,
                statements=statements)
    if (corners[1] is not None and not uvs[1]) or (corners[2] is not None and not norms[1]):
        return None  # references to entries the file lacks: the general reader says so
    if corners[1] is not None and uvs[1]:
        mesh.uv, mesh.face_uv = _rows_of(*uvs, 2), corners[1] - 1
    if corners[2] is not None and norms[1]:
        mesh.normals, mesh.face_normals = _rows_of(*norms, 3), corners[2] - 1
    tables = ((V, mesh.face_vertices), (mesh.uv, mesh.face_uv), (mesh.normals, mesh.face_normals))
    for rows, refs in tables:
        if refs is not None and (rows is None or refs.max() >= len(rows)):
            return None
    return mesh


def _block(text: str, head: str) -> tuple[str, int]:
    """The numbers of every ``head`` line as one text, and how many lines: from one slice
    when those lines come together, as writers put them (a third of a findall's time)."""
    key = f"\n{head} "
    at = 0 if text.startswith(head + " ") else text.find(key) + 1 or None
    if at is None:
        return "", 0
    end = text.find("\n", text.rfind(key) + 1)
    block = text[at:len(text) if end < 0 else end]
    lines = block.count("\n") + 1
    if block.count(key) + 1 == lines:
        return block[len(head) + 1:].replace(key, "\n"), lines
    found = re.findall(rf"^{head} (.*)$", text, re.M)  # other lines among them
    return "\n".join(found), len(found)


def _statements(text, read):
    """The general reader's statements (faces before each, stripped line), or None when a
    line would not be read alike by both readers (leading blanks, a bare head). ``read``:
    the v, vt, vn and f lines found; when they and the comments are every line, there are
    none (counting is faster than the regex search)."""
    comments = text.count("\n#") + text.startswith("#")
    if read + comments + text.endswith("\n") == text.count("\n") + 1:
        return []
    found, faces, last = [], 0, 0
    for match in _OTHER.finditer(text):
        line = match.group()
        if line[:1].isspace() or line.strip().partition(" ")[0] in _HEADS:
            return None
        faces += text.count("\nf ", last, match.start()) + (last == 0 and text[:2] == "f ")
        last = match.start()
        found.append((faces, line.strip()))
    return found


def _rows_of(numbers: str, lines: int, least: int) -> np.ndarray | None:
    """Rows of the first three numbers of ``lines`` lines of text (as the general reader
    takes them) when every line holds the same count of numbers, at least ``least``; None
    otherwise.

    numpy's C ``loadtxt`` checks the count line by line: a count over all lines let one
    line's extra number stand in for another's missing one (``v 0 0`` then ``v 1 0 0 0``
    read as two vertices of three)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            rows = np.loadtxt(io.StringIO(numbers), ndmin=2, comments=None)
    except (ValueError, UserWarning):
        return None
    if rows.shape[0] != lines or rows.shape[1] < least:
        return None
    return np.ascontiguousarray(rows[:, :3])


def _uniform_corners(joined, count):
    """Vertex, uv and normal ids (1-based; None for a part the corners lack) of ``count``
    whitespace-separated corners that all have one form; None otherwise.

    The corners hold ``slashes / count`` slashes each when none holds more (pigeonhole);
    then ids of every slot, ``count`` times the slots per corner, mean none was empty."""
    slashes, doubles = joined.count("/"), joined.count("//")
    per = slashes // count if count else -1
    if per not in (0, 1, 2) or slashes != per * count or doubles not in (0, count) \
            or (doubles and per != 2) or re.search("/" + "[^\\s/]*/" * per, joined):
        return None
    ids = parse_numbers([joined.replace("//", " ").replace("/", " ")], dtype=np.int64)
    slots = per + 1 - bool(doubles)
    if ids is None or ids.size != slots * count or (ids < 1).any():
        return None
    ids = ids.reshape(count, slots).T
    if doubles:
        return ids[0], None, ids[1]
    return ids[0], (ids[1] if per else None), (ids[2] if per == 2 else None)


def _read_general(text, path):
    """Line by line: every OBJ statement, or a one-line error naming the file and line."""
    verts, uvs, norms, sizes, faces, statements = [], [], [], [], [], []
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line or line[0] == "#":
            continue
        head, _, rest = line.partition(" ")
        if head == "v":
            verts.append(rest.split())
        elif head == "vt":
            uvs.append(rest.split())
        elif head == "vn":
            norms.append(rest.split())
        elif head == "f":
            size = len(rest.split())
            if size < 3:
                raise InputError(f"{path}:{lineno}: face with fewer than 3 corners")
            faces.append((lineno, rest, (len(verts), len(uvs), len(norms))))
            sizes.append(size)
        else:
            statements.append((len(sizes), line))
    V = _floats(verts, 3, path, "v")
    c = _face_corners(faces, path)
    mesh = Mesh(vertices=V, face_sizes=np.array(sizes, dtype=np.int64),
                face_vertices=c[:, 0].copy(), statements=statements)
    for refs, rows, what in ((c[:, 1], uvs, "vt"), (c[:, 2], norms, "vn")):
        if not rows and (refs >= 0).any():  # as invalid as an index past the last entry
            raise InputError(f"{path}: face references a '{what}' entry that does not exist "
                             f"(the file has no '{what}' lines)")
    if uvs and (c[:, 1] >= 0).any():
        width = 3 if all(len(r) >= 3 for r in uvs) else 2
        mesh.uv, mesh.face_uv = _floats(uvs, width, path, "vt"), c[:, 1].copy()
    if norms and (c[:, 2] >= 0).any():
        mesh.normals, mesh.face_normals = _floats(norms, 3, path, "vn"), c[:, 2].copy()
    _check_refs(mesh.face_uv, 0 if mesh.uv is None else len(mesh.uv), path, "vt")
    _check_refs(mesh.face_normals, 0 if mesh.normals is None else len(mesh.normals), path, "vn")
    return mesh


def _face_corners(faces, path):
    """(corners, 3) ids: vertex, uv, normal (-1 when absent). Plain positive vertex indices
    (most large files) are parsed in one go; anything else corner by corner."""
    try:
        v = np.array(" ".join(rest for _, rest, _ in faces).split(), dtype=np.int64)
        if v.size and v.min() >= 1:
            return np.column_stack([v - 1, np.full(v.size, -1), np.full(v.size, -1)])
    except (ValueError, OverflowError):
        pass  # "v/vt/vn" corners, bad or huge tokens: the per-corner parser reports them
    corners = [_corner(t, counts, path, lineno)
               for lineno, rest, counts in faces for t in rest.split()]
    return np.array(corners, dtype=np.int64).reshape(-1, 3)


def _check_refs(refs, count, path, what):
    if refs is not None and ((refs < -1) | (refs >= count)).any():
        raise InputError(f"{path}: face references a '{what}' entry that does not exist")


def _rows(fmt, values):
    if len(values) == 0:
        return ""
    return (fmt * len(values)) % tuple(np.asarray(values, dtype=float).ravel())


def _face_lines(mesh, offsets, first, stop):
    """One ``f`` line per polygon ``first:stop``; corners as ``v``, ``v/t``, ``v//n`` or
    ``v/t/n``. ``offsets``: ``mesh.face_offsets``."""
    corners = slice(offsets[first], offsets[stop])
    v = (mesh.face_vertices[corners] + 1).astype(str).astype(object)
    t = mesh.face_uv[corners] if mesh.face_uv is not None else np.full(v.size, -1)
    n = mesh.face_normals[corners] if mesh.face_normals is not None else np.full(v.size, -1)
    tok = np.where(t >= 0, v + "/" + (t + 1).astype(str).astype(object), v)
    tok = np.where(n >= 0, np.where(t >= 0, tok, tok + "/") + "/"
                   + (n + 1).astype(str).astype(object), tok)
    ends = offsets[first:stop + 1] - offsets[first]
    return ["f " + " ".join(tok[ends[i]:ends[i + 1]]) + "\n" for i in range(stop - first)]


_CORNER_FORMS = {(False, False): "%d", (True, False): "%d/%d", (False, True): "%d//%d",
                 (True, True): "%d/%d/%d"}


def _face_block(mesh, offsets, first, stop):
    """The ``f`` lines of polygons ``first:stop``, all of one size, at once when their corners
    have one form (a fifth of the time of :func:`_face_lines`, or less); None otherwise."""
    sizes = mesh.face_sizes[first:stop]
    corners = slice(offsets[first], offsets[stop])
    columns, has = [mesh.face_vertices[corners]], []
    for table in (mesh.face_uv, mesh.face_normals):
        ids = None if table is None else table[corners]
        has.append(ids is not None and bool((ids >= 0).any()))
        if ids is not None and has[-1]:
            if (ids < 0).any():
                return None
            columns.append(ids)
    line = "f" + (" " + _CORNER_FORMS[(has[0], has[1])]) * int(sizes[0]) + "\n"
    return line * sizes.size % tuple((np.column_stack(columns) + 1).ravel().tolist())


def format_obj(mesh: Mesh) -> str:
    """OBJ text for ``mesh``: deterministic, coordinates with 17 significant digits."""
    head, faces = _fixed_text(mesh)
    return head + _vertex_lines(mesh) + _uv_lines(mesh) + _normal_lines(mesh) + faces


def obj_frames(mesh: Mesh) -> Callable[[np.ndarray], bytes]:
    """``frame(positions) -> bytes``: the OBJ file of ``mesh`` with other positions (normals
    recomputed for them), as :func:`format_obj` writes it. What the positions do not change
    (statements, texture coordinates, faces) is formatted once."""
    head, faces = _fixed_text(mesh)
    uv = _uv_lines(mesh)

    def frame(positions):
        moved = mesh.with_vertices(positions)
        return (head + _vertex_lines(moved) + uv + _normal_lines(moved) + faces).encode("utf-8")

    return frame


def _vertex_lines(mesh):
    return _rows("v %.17g %.17g %.17g\n", mesh.vertices)


def _uv_lines(mesh):
    """The ``vt`` lines: each number in the shortest text that reads back as the same float
    (``0.902657`` as read, not ``0.90265700000000004``): texture coordinates come from the
    input unchanged, and that is the text they were read from whenever it was that short."""
    if mesh.uv is None or len(mesh.uv) == 0:
        return ""
    fmt = "vt" + " %r" * mesh.uv.shape[1] + "\n"
    return (fmt * len(mesh.uv)) % tuple(np.asarray(mesh.uv, dtype=float).ravel().tolist())


def _normal_lines(mesh):
    return "" if mesh.normals is None else _rows("vn %.17g %.17g %.17g\n", mesh.normals)


def _fixed_text(mesh):
    """The text before the coordinates (the header, statements before any face) and after
    them (faces, with the statements among them)."""
    later: dict[int, list[str]] = {}
    count = mesh.face_sizes.size
    for k, s in mesh.statements:  # one said to follow more faces than there are goes last
        later.setdefault(min(k, count), []).append(s + "\n")
    head = "".join(["# written by srarap\n", *later.pop(0, ())])
    # faces in runs between the statements among them (usemtl, g, s, ...); when those come
    # every few faces, blocks would cost more than one pass line by line
    offsets = mesh.face_offsets
    bounds = [0, *sorted(later), count]
    lines = _face_lines(mesh, offsets, 0, count) if 8 * len(bounds) > count else None
    parts: list[str] = []
    for first, stop in zip(bounds, bounds[1:]):
        parts.extend(later.get(first, ()))
        if stop > first:
            parts.extend(lines[first:stop] if lines is not None
                         else _face_text(mesh, offsets, first, stop))
    return head, "".join(parts)


def _face_text(mesh, offsets, first, stop):
    """The ``f`` lines of polygons ``first:stop`` (at least one): in blocks of one polygon
    size (a quad mesh's triangle caps, say), or line by line when the sizes alternate too
    often for blocks to pay or the corners' forms differ."""
    changes = first + 1 + np.flatnonzero(np.diff(mesh.face_sizes[first:stop]))
    if 64 * changes.size > stop - first:
        return _face_lines(mesh, offsets, first, stop)
    bounds = [first, *changes.tolist(), stop]
    out: list[str] = []
    for a, b in zip(bounds, bounds[1:]):
        block = _face_block(mesh, offsets, a, b)
        out.extend([block] if block is not None else _face_lines(mesh, offsets, a, b))
    return out
