"""A mesh from a stream (standard input): its format told from its bytes, its size held to
the same memory guard as a file's."""
import os
import tempfile
from typing import BinaryIO

from ...runtime import descriptors
from ...runtime.errors import InputError
from ...runtime.limits import available_memory, check_read_size
from .formats import FORMATS, HEAD_BYTES, MeshFormat, by_content
from .mesh import Mesh

CHUNK = 1 << 20


def read_mesh_stream(stream: BinaryIO | None, fmt: MeshFormat | None = None,
                     name: str = "<stdin>") -> tuple[Mesh, MeshFormat]:
    """The mesh on ``stream`` and its format: ``fmt``, or the registered format whose
    signature the bytes match (see :func:`.formats.by_content`).

    The bytes are spooled to a temporary file for the format's reader, chunk by chunk; the
    read stops with InputError as soon as parsing what came would not fit in memory (the
    guard a named file gets before it is read; until the format is known, with the least
    memory any format needs per byte). A closed stream, an empty one, content of no known
    format and a temporary folder that cannot take the bytes are InputErrors naming ``name``.
    """
    if stream is None or descriptors.closed(0):
        raise InputError(f"{name}: standard input is closed; give a mesh file instead of '-'")
    have = available_memory()
    factor = fmt.read_factor if fmt else min(f.read_factor for f in FORMATS.values())
    with tempfile.TemporaryDirectory(prefix="srarap-stdin-") as folder:
        path = os.path.join(folder, "stdin")
        try:
            head, size = _spool(stream, path, factor, have, name)
        except OSError as exc:
            raise InputError(f"{name}: cannot keep standard input in a temporary file "
                             f"({exc.strerror or exc}); set TMPDIR to a folder with room") \
                from None
        fmt = fmt or _detect(head, size, name)
        check_read_size(name, fmt.read_factor * size, have)
        try:
            return fmt.read(path), fmt
        except InputError as exc:
            raise InputError(str(exc).replace(path, name)) from None


def _spool(stream, path, factor, have, name):
    """Copy ``stream`` to ``path``; returns its first HEAD_BYTES and its size."""
    head, total = b"", 0
    with open(path, "wb") as out:
        while chunk := _read(stream, CHUNK, name):
            total += len(chunk)
            check_read_size(name, factor * total, have)
            if len(head) < HEAD_BYTES:
                head += chunk[:HEAD_BYTES - len(head)]
            out.write(chunk)
    return head, total


def _read(stream, size, name):
    try:
        return stream.read(size)
    except ValueError:  # a stream closed under us
        raise InputError(f"{name}: standard input is closed; give a mesh file instead of "
                         "'-'") from None


def _detect(head, size, name):
    if not size:
        raise InputError(f"{name}: standard input is empty")
    fmt = by_content(head, size)
    if fmt is None:
        raise InputError(f"{name}: cannot tell the mesh format from its content; give "
                         f"--input-format {'|'.join(FORMATS)}")
    return fmt
