"""A mesh from a stream (standard input, a pipe, a device): its format told from its first
bytes before anything is kept, its size held to the same memory guard as a file's and to the
room in the temporary folder."""
import os
import shutil
import tempfile
from typing import BinaryIO

import numpy as np

from ...runtime import descriptors
from ...runtime.errors import InputError
from ...runtime.limits import available_memory, check_read_size
from .formats import FORMATS, HEAD_BYTES, MeshFormat, by_content, is_binary_stl
from .mesh import Mesh
from .sniff import not_a_mesh

CHUNK = 1 << 20
#: bytes the temporary folder keeps free whatever a stream holds
TMP_RESERVE = 64 << 20


def read_mesh_stream(stream: BinaryIO | None, fmt: MeshFormat | None = None,
                     name: str = "<stdin>") -> tuple[Mesh, MeshFormat]:
    """The mesh on ``stream`` and its format: ``fmt``, or the registered format whose
    signature its first :data:`~.formats.HEAD_BYTES` match (see :func:`.formats.by_content`).

    The format is decided before the rest is read: content of no known format is refused
    after its first kilobytes. The bytes are then spooled to a temporary file for the
    format's reader, chunk by chunk; the read stops with InputError as soon as parsing what
    came would not fit in memory (the guard a named file gets before it is read), as soon as
    the temporary folder could not keep it, and, for binary STL, past the size its triangle
    count gives. A closed stream, an empty one and content of no known format are
    InputErrors naming ``name``.
    """
    if stream is None or (name == "<stdin>" and descriptors.closed(0)):
        raise InputError(f"{name}: standard input is closed; give a mesh file instead of '-'")
    head = _head(stream, name)
    ended = len(head) < HEAD_BYTES
    fmt = fmt or _detect(head, len(head) if ended else None, name)
    have = available_memory()
    with tempfile.TemporaryDirectory(prefix="srarap-stdin-") as folder:
        path = os.path.join(folder, "stdin")
        try:
            size = _spool(stream, path, head, fmt, have, name)
        except OSError as exc:
            raise InputError(f"{name}: cannot keep the stream in a temporary file "
                             f"({exc.strerror or exc}); set TMPDIR to a folder with room") \
                from None
        check_read_size(name, fmt.read_factor * size, have)
        try:
            return fmt.read(path), fmt
        except InputError as exc:
            raise InputError(str(exc).replace(path, name)) from None


def _head(stream, name):
    """The stream's first HEAD_BYTES (fewer only when it ends before)."""
    head = b""
    while len(head) < HEAD_BYTES and (chunk := _read(stream, HEAD_BYTES - len(head), name)):
        head += chunk
    return head


def _spool(stream, path, head, fmt, have, name):
    """Copy ``head`` and the rest of ``stream`` to ``path``; returns the size."""
    room = shutil.disk_usage(os.path.dirname(path)).free - TMP_RESERVE
    most = _binary_stl_size(head) if fmt.name == "stl" and is_binary_stl(head, None) else None
    total = len(head)
    with open(path, "wb") as out:
        out.write(head)
        while chunk := _read(stream, CHUNK, name):
            total += len(chunk)
            check_read_size(name, fmt.read_factor * total, have)
            if total > room:
                raise InputError(f"{name}: the stream is larger than the temporary folder "
                                 f"{os.path.dirname(os.path.dirname(path))} can keep "
                                 f"({max(room, 0) / 1e9:.2f} GB free); set TMPDIR to a "
                                 "folder with room, or give the mesh as a file")
            if most is not None and total > most:
                raise InputError(f"{name}: not a mesh: longer than the {(most - 84) // 50} "
                                 "triangles a binary STL header there gives")
            out.write(chunk)
    return total


def _binary_stl_size(head):
    """The size a binary STL starting with ``head`` has (its triangle count's), or None."""
    if len(head) < 84:
        return None
    return 84 + 50 * int(np.frombuffer(head[80:84], "<u4")[0])


def _read(stream, size, name):
    try:
        return stream.read(size)
    except ValueError:  # a stream closed under us
        raise InputError(f"{name}: the stream is closed; give a mesh file") from None
    except OSError as exc:
        raise InputError(f"{name}: cannot read: {exc.strerror or exc}") from None


def _detect(head, size, name):
    if not head:
        raise InputError(f"{name}: {'standard input' if name == '<stdin>' else 'the stream'} "
                         "is empty")
    fmt = by_content(head, size)
    if fmt is None:
        raise InputError(not_a_mesh(name, head) + (f"; or give --input-format "
                                                   f"{'|'.join(FORMATS)}"
                                                   if name == "<stdin>" else ""))
    return fmt
