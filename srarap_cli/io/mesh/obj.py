"""Wavefront OBJ: polygons, per-corner texture and normal indices, other lines kept verbatim.

Written by hand because meshio drops ``vt``/``vn`` indices and rejects UV seams and
per-corner normals, and libigl's reader keeps no polygons of mixed size or other statements.
"""
import re

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


def read_obj(path):
    """Read an OBJ file into a :class:`Mesh`, keeping vertex and face order."""
    with open_input(path, encoding="utf-8", errors="replace") as fh:
        text = fh.read().replace("\\\n", " ")
    return _read_plain(text) or _read_general(text, path)


# any line that is not "v ...", "f ..." (no "/" in it), a comment or blank
_NOT_PLAIN = re.compile(r"^(?!v |f [^/\n]*$|#|[ \t\r]*$)", re.M)


def _read_plain(text):
    """The mesh of a file of only ``v x y z`` and ``f i j k ...`` lines (positive indices),
    comments and blank lines, parsed in bulk (a 738k-vertex file in a third of the time);
    None for anything else, which :func:`_read_general` reads or reports."""
    if _NOT_PLAIN.search(text):
        return None
    verts = re.findall(r"^v (.*)$", text, re.M)
    faces = re.findall(r"^f (.*)$", text, re.M)
    V, corners = parse_numbers(verts), parse_numbers(faces, dtype=np.int64)
    if V is None or corners is None:
        return None
    sizes = np.fromiter((len(f.split()) for f in faces), dtype=np.int64, count=len(faces))
    if V.size != 3 * len(verts) or (sizes < 3).any() or corners.size != sizes.sum() \
            or (corners < 1).any() or (corners > len(verts)).any():
        return None
    return Mesh(vertices=V.reshape(-1, 3), face_sizes=sizes, face_vertices=corners - 1,
                statements=[])


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


def _face_lines(mesh):
    """One ``f`` line per polygon; corners as ``v``, ``v/t``, ``v//n`` or ``v/t/n``."""
    v = (mesh.face_vertices + 1).astype(str).astype(object)
    t = mesh.face_uv if mesh.face_uv is not None else np.full(v.size, -1)
    n = mesh.face_normals if mesh.face_normals is not None else np.full(v.size, -1)
    tok = np.where(t >= 0, v + "/" + (t + 1).astype(str).astype(object), v)
    tok = np.where(n >= 0, np.where(t >= 0, tok, tok + "/") + "/"
                   + (n + 1).astype(str).astype(object), tok)
    offsets = mesh.face_offsets
    return ["f " + " ".join(tok[offsets[i]:offsets[i + 1]]) for i in range(mesh.face_sizes.size)]


def _face_block(mesh):
    """All ``f`` lines at once when every face has one size and no uv or normal ids (most
    large meshes: a fifth of the time of :func:`_face_lines`); None otherwise."""
    sizes = mesh.face_sizes
    if mesh.face_uv is not None or mesh.face_normals is not None or sizes.size == 0 \
            or (sizes != sizes[0]).any():
        return None
    return ("f" + " %d" * int(sizes[0]) + "\n") * sizes.size % tuple(
        (mesh.face_vertices + 1).tolist())


def format_obj(mesh):
    """OBJ text for ``mesh``: deterministic, coordinates with 17 significant digits."""
    lead = [s for k, s in mesh.statements if k == 0]
    later = {}
    for k, s in mesh.statements:
        if k > 0:
            later.setdefault(k, []).append(s)
    parts = ["# written by srarap\n"] + [s + "\n" for s in lead]
    parts.append(_rows("v %.17g %.17g %.17g\n", mesh.vertices))
    if mesh.uv is not None:
        parts.append(_rows("vt" + " %.17g" * mesh.uv.shape[1] + "\n", mesh.uv))
    if mesh.normals is not None:
        parts.append(_rows("vn %.17g %.17g %.17g\n", mesh.normals))
    block = None if later else _face_block(mesh)
    if block is not None:
        parts.append(block)
    for i, line in enumerate([] if block is not None else _face_lines(mesh)):
        parts.extend(s + "\n" for s in later.get(i, ()))
        parts.append(line + "\n")
    parts.extend(s + "\n" for s in later.get(mesh.face_sizes.size, ()))
    return "".join(parts)
