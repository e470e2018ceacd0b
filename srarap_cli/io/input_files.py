"""Open the user's input files only when they are regular files.

A FIFO, ``/dev/zero``, ``/dev/urandom`` or a socket given as a mesh file would block forever
or read without bound; the size checks that guard memory mean nothing for them. The file is
opened without blocking and checked on the open descriptor, so nothing can swap it between the
check and the read. (A mesh from a stream goes through ``mesh.stream``, a handle file from one
through ``documents.document_bytes``: each bounded in size, and in waiting.)

A UTF-8 byte order mark at the start of any input is skipped, so a file saved by an editor
that writes one reads exactly like the same file without it.
"""
import os
import stat
from typing import IO, Any

from ..runtime.errors import InputError

BOM = b"\xef\xbb\xbf"


def open_input(path: str | os.PathLike, mode: str = "r", **kwargs: Any) -> IO[Any]:
    """``open(path, mode, **kwargs)`` for reading, refusing anything but a regular file; in
    binary mode the stream starts after a leading UTF-8 byte order mark, in text mode
    ``utf-8`` is read as ``utf-8-sig`` (the same).

    Raises
    ------
    InputError : missing, a folder, not a regular file, or unreadable

    Examples
    --------
    >>> open_input("/dev/null")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    srarap_cli.runtime.errors.InputError: /dev/null: not a regular file (...); give a file
    """
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder, not a file") from None
    except UnicodeEncodeError:
        raise InputError(f"{path!a}: the name cannot be encoded in this locale's file-name "
                         "encoding (set LC_ALL=C.UTF-8 or PYTHONUTF8=1)") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    try:
        kind = os.fstat(fd).st_mode
        if stat.S_ISDIR(kind):
            raise InputError(f"{path}: is a folder, not a file")
        if not stat.S_ISREG(kind):
            raise InputError(f"{path}: not a regular file (a device, FIFO or socket); give a file")
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        if "b" in mode:
            fh = os.fdopen(fd, mode, **kwargs)
            if fh.read(len(BOM)) != BOM:
                fh.seek(0)
            return fh
        if kwargs.get("encoding", "utf-8").lower().replace("_", "-") in ("utf-8", "utf8"):
            kwargs["encoding"] = "utf-8-sig"
        return os.fdopen(fd, mode, **kwargs)
    except BaseException:
        os.close(fd)
        raise


def read_input_bytes(path: str | os.PathLike) -> bytes:
    """The whole content of a regular file, less a leading byte order mark (see
    :func:`open_input`)."""
    with open_input(path, "rb") as fh:
        return fh.read()
