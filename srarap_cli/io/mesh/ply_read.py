"""PLY reader (ASCII and binary): the header is checked against the data before anything is
allocated, and every face is checked before any native code sees it.

Written by hand because meshio's reader trusts the header: a file claiming 10^8 faces
allocated gigabytes before failing, a header without ``end_header`` spun forever, and a face
with no corners reached libigl and crashed the process.
"""

from typing import Any

import numpy as np

from ...runtime.errors import InputError, excerpt
from ..input_files import read_input_bytes
from .mesh import Mesh

#: The header must end within this many bytes (real headers are a few hundred).
MAX_HEADER = 65536
_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
          "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
          "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4", "double": "f8",
          "float64": "f8"}
_FACE_LISTS = ("vertex_indices", "vertex_index")
_UV_NAMES = (("s", "t"), ("u", "v"), ("texture_u", "texture_v"))


def read_ply(path: str) -> Mesh:
    """Read a PLY file into a :class:`Mesh` (vertex properties kept, polygons kept).

    Raises
    ------
    InputError : naming the file and what is wrong
    """
    data = read_input_bytes(path)
    fmt, elements, start = _header(data, path)
    body = data[start:]
    values = {}
    if fmt == "ascii":
        lines = body.decode("ascii", errors="replace").splitlines()
        at = 0
        for name, count, props in elements:
            values[name], at = _ascii_element(lines, at, name, count, props, path)
    else:
        order = "<" if fmt == "binary_little_endian" else ">"
        at = 0
        for name, count, props in elements:
            values[name], at = _binary_element(body, at, order, name, count, props, path)
    return _mesh(values, elements, path)


def _header(data, path):
    """(format, [(element, count, [(name, type) or (name, (count type, item type))]]), body
    offset)."""
    if not data.startswith(b"ply"):
        raise InputError(f"{path}: not a PLY file (no 'ply' magic line)")
    end = data.find(b"end_header", 0, MAX_HEADER)
    if end < 0:
        raise InputError(f"{path}: no 'end_header' in the first {MAX_HEADER} bytes")
    stop = data.find(b"\n", end)
    start = len(data) if stop < 0 else stop + 1
    fmt: str | None = None
    elements: list[Any] = []
    for raw in data[:end].decode("ascii", errors="replace").splitlines()[1:]:
        words = raw.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format" and len(words) == 3 and words[1] in (
                "ascii", "binary_little_endian", "binary_big_endian"):
            fmt = words[1]
        elif words[0] == "element" and len(words) == 3 and words[2].isdigit():
            if any(words[1] == e[0] for e in elements):
                raise InputError(f"{path}: PLY element {excerpt(words[1])!r} declared twice")
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property" and elements:
            prop = _property(words, path)
            if any(prop[0] == p[0] for p in elements[-1][2]):
                raise InputError(f"{path}: property {excerpt(prop[0])!r} of PLY element "
                                 f"{excerpt(elements[-1][0])!r} declared twice")
            elements[-1][2].append(prop)
        else:
            raise InputError(f"{path}: bad PLY header line {excerpt(raw)!r}")
    if fmt is None:
        raise InputError(f"{path}: PLY header has no valid 'format' line")
    return fmt, elements, start


def _property(words, path):
    if len(words) == 5 and words[1] == "list" and words[2] in _TYPES and words[3] in _TYPES:
        if _TYPES[words[2]][0] == "f":
            raise InputError(f"{path}: list property {excerpt(words[4])!r} has a float count")
        return words[4], (_TYPES[words[2]], _TYPES[words[3]])
    if len(words) == 3 and words[1] in _TYPES:
        return words[2], _TYPES[words[1]]
    raise InputError(f"{path}: bad PLY property line {excerpt(' '.join(words))!r}")


def _ascii_element(lines, at, name, count, props, path):
    if at + count > len(lines):
        raise InputError(f"{path}: element '{excerpt(name)}' declares {count} lines, the file "
                         f"holds {len(lines) - at}")
    rows = [line.split() for line in lines[at:at + count]]
    if not any(isinstance(t, tuple) for _, t in props):
        width = len(props)
        bad = next((k for k, r in enumerate(rows) if len(r) != width), None)
        if bad is not None:
            raise InputError(f"{path}: {name} {bad} has {len(rows[bad])} values, the header "
                             f"declares {width}")
        try:
            table = np.array(rows, dtype=float).reshape(count, width)
        except ValueError:
            raise InputError(f"{path}: element '{excerpt(name)}' has a non-numeric value") from None
        return {p: _cast(table[:, k], t, name, p, path) for k, (p, t) in enumerate(props)}, \
            at + count
    out: dict[str, list] = {p: [] for p, _ in props}
    for k, row in enumerate(rows):
        pos = 0
        try:
            for p, t in props:
                if isinstance(t, tuple):
                    n = int(row[pos])
                    if n < 0 or pos + 1 + n > len(row):
                        raise ValueError
                    out[p].append(row[pos + 1:pos + 1 + n])
                    pos += 1 + n
                else:
                    out[p].append(row[pos])
                    pos += 1
            if pos != len(row):
                raise ValueError
        except (ValueError, IndexError):
            raise InputError(f"{path}: {name} {k} does not match the header's properties") \
                from None
    return {p: (_ragged(out[p], t[1], name, p, path) if isinstance(t, tuple)
                else _cast(np.array(out[p], dtype=float), t, name, p, path))
            for p, t in props}, at + count


def _cast(column, kind, element, prop, path):
    if kind[0] in "iu" and not np.all(np.isfinite(column) & (column == np.round(column))):
        raise InputError(f"{path}: {element} property '{excerpt(prop)}' holds a non-integer")
    return column.astype(kind) if kind[0] in "iu" else column


def _ragged(items, kind, element, prop, path):
    """(sizes, flat values) of ASCII list entries."""
    sizes = np.array([len(x) for x in items], dtype=np.int64)
    try:
        flat = np.array([v for x in items for v in x], dtype=float)
    except ValueError:
        raise InputError(f"{path}: {element} list '{excerpt(prop)}' has a non-numeric entry") \
            from None
    return sizes, _cast(flat, kind, element, prop, path)


def _binary_element(body, at, order, name, count, props, path):
    lists = [p for p, t in props if isinstance(t, tuple)]
    if not lists:
        dtype = np.dtype([(p, order + t) for p, t in props])
        need = count * dtype.itemsize
        if at + need > len(body):
            raise InputError(f"{path}: element '{excerpt(name)}' declares {count} entries "
                             f"({need} bytes), the file holds {len(body) - at} bytes")
        table = np.frombuffer(body, dtype=dtype, count=count, offset=at)
        return {p: table[p].astype(table[p].dtype.newbyteorder("=")) for p, _ in props}, \
            at + need
    least = sum(np.dtype(t[0] if isinstance(t, tuple) else t).itemsize for _, t in props)
    if at + count * least > len(body):
        raise InputError(f"{path}: element '{excerpt(name)}' declares {count} entries, the file "
                         f"is too short to hold them")
    uniform = _uniform_rows(body, at, order, count, props)
    if uniform is not None:
        return uniform
    return _binary_rows(body, at, order, name, count, props, path)


def _uniform_rows(body, at, order, count, props):
    """Fast path: every list of the element has the same length as in its first entry."""
    fields, pos = [], at
    for p, t in props:
        if isinstance(t, tuple):
            if pos + np.dtype(t[0]).itemsize > len(body):
                return None
            n = int(np.frombuffer(body, order + t[0], 1, pos)[0])
            if n < 0 or pos + n * np.dtype(t[1]).itemsize > len(body):
                return None  # the entry-by-entry reader names the entry cut off
            fields += [(p + "#n", order + t[0]), (p, order + t[1], (n,))]
            pos += np.dtype(t[0]).itemsize + n * np.dtype(t[1]).itemsize
        else:
            fields.append((p, order + t))
            pos += np.dtype(t).itemsize
    dtype = np.dtype(fields)
    if count == 0 or at + count * dtype.itemsize > len(body):
        return None
    table = np.frombuffer(body, dtype=dtype, count=count, offset=at)
    out = {}
    for p, t in props:
        if isinstance(t, tuple):
            n = dtype[p].shape[0]
            if np.any(table[p + "#n"] != n):
                return None
            out[p] = (np.full(count, n, dtype=np.int64),
                      table[p].reshape(-1).astype(np.dtype(t[1]).newbyteorder("=")))
        else:
            out[p] = table[p].astype(np.dtype(t).newbyteorder("="))
    return out, at + count * dtype.itemsize


def _binary_rows(body, at, order, name, count, props, path):
    """Entries one at a time (lists of mixed lengths)."""
    out: dict[str, list] = {p: [] for p, _ in props}
    sizes: dict[str, list] = {p: [] for p, t in props if isinstance(t, tuple)}
    pos = at
    for k in range(count):
        for p, t in props:
            kind = t[0] if isinstance(t, tuple) else t
            width = np.dtype(kind).itemsize
            if pos + width > len(body):
                raise InputError(f"{path}: {name} {k} is cut off by the end of the file")
            value = np.frombuffer(body, order + kind, 1, pos)[0]
            pos += width
            if not isinstance(t, tuple):
                out[p].append(value)
                continue
            n, width = int(value), np.dtype(t[1]).itemsize
            if n < 0 or pos + n * width > len(body):
                raise InputError(f"{path}: {name} {k} is cut off by the end of the file")
            out[p].append(np.frombuffer(body, order + t[1], n, pos))
            sizes[p].append(n)
            pos += n * width
    result: dict[str, Any] = {}
    for p, t in props:
        if isinstance(t, tuple):
            flat = np.concatenate(out[p]) if out[p] else np.zeros(0, t[1])
            result[p] = (np.array(sizes[p], dtype=np.int64),
                         flat.astype(np.dtype(t[1]).newbyteorder("=")))
        else:
            result[p] = np.array(out[p], dtype=np.dtype(t).newbyteorder("="))
    return result, pos


def _mesh(values, elements, path):
    vertex = values.get("vertex")
    if vertex is None or not all(k in vertex for k in "xyz"):
        raise InputError(f"{path}: PLY has no vertex element with x, y and z")
    if any(isinstance(vertex[k], tuple) for k in vertex):
        raise InputError(f"{path}: PLY vertex element has a list property")
    data = dict(vertex)
    V = np.column_stack([data.pop(k) for k in "xyz"]).astype(float)
    face = values.get("face", {})
    lists = [k for k in _FACE_LISTS if isinstance(face.get(k), tuple)]
    if not lists:
        raise InputError(f"{path}: PLY has no face element with a vertex_indices list")
    sizes, corners = face[lists[0]]
    if corners.dtype.kind not in "iu":
        raise InputError(f"{path}: PLY face indices must be integers")
    small = np.flatnonzero(sizes < 3)
    if small.size:
        raise InputError(f"{path}: face {int(small[0])} has {int(sizes[small[0]])} corners; "
                         "a face needs at least 3")
    mesh = Mesh(vertices=V, face_sizes=sizes.astype(np.int64),
                face_vertices=corners.astype(np.int64))
    if all(k in data for k in ("nx", "ny", "nz")):
        mesh.normals = np.column_stack([data.pop(k) for k in ("nx", "ny", "nz")]).astype(float)
        mesh.face_normals = mesh.face_vertices.copy()
    for a, b in _UV_NAMES:
        if a in data and b in data:
            mesh.uv = np.column_stack([data.pop(a), data.pop(b)]).astype(float)
            mesh.face_uv = mesh.face_vertices.copy()
            break
    mesh.vertex_data = data
    mesh.unkept = _unkept(elements, lists[0])
    return mesh


def _unkept(elements, face_list):
    """What of the file's elements no writer keeps: face properties besides the corners,
    and elements other than vertex and face."""
    out = []
    for name, count, props in elements:
        if name == "face":
            extra = [p for p, _ in props if p != face_list]
            if extra:
                out.append(f"face properties {', '.join(extra)}")
        elif name != "vertex":
            out.append(f"element {name!r} ({count})")
    return out
