"""Constraint files used in the field: Botsch-Sorkine ``.sel``/``.def`` and libigl ``.dmat``."""

import numpy as np

from ...runtime.errors import InputError
from ..input_files import open_input

SEL_STATUS = {"fixed": 0, "free": 1, "handle": 2}


def _numbers(path, dtype):
    try:
        with open_input(path, encoding="utf-8", errors="replace") as fh:
            text = " ".join(line.split("#", 1)[0] for line in fh)
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror}") from None
    try:
        return np.array(text.split(), dtype=dtype)
    except ValueError:
        raise InputError(f"{path}: non-numeric entry") from None


def read_sel(path: str) -> np.ndarray:
    """Per-vertex status of a ``.sel`` file: (n,) int array, 0 fixed, 1 free, 2 handle."""
    status = _numbers(path, float)
    if status.size == 0 or (status != np.round(status)).any() or ~np.isin(status, (0, 1, 2)).all():
        raise InputError(f"{path}: a .sel file holds one status per vertex: 0, 1 or 2")
    return status.astype(np.int64)


def read_def(path: str) -> np.ndarray:
    """The 4x4 handle matrix of a ``.def`` file (row-major, applied to column vectors)."""
    values = _numbers(path, float)
    if values.size != 16 or not np.isfinite(values).all():
        raise InputError(f"{path}: a .def file holds one 4x4 matrix (16 numbers)")
    M = values.reshape(4, 4)
    if not np.allclose(M[3], [0, 0, 0, 1]):
        raise InputError(f"{path}: row 4 must be 0 0 0 1 (an affine transform), found "
                         f"{' '.join(f'{x:g}' for x in M[3])}")
    return M


def read_dmat(path: str) -> np.ndarray:
    """A libigl ``.dmat`` column (ASCII ``cols rows`` header, column-major; or binary).

    Returns
    -------
    (rows,) int array for a one-column file
    """
    with open_input(path, "rb") as fh:
        head = fh.readline().split()
        body = fh.read()
    try:
        cols, rows = int(head[0]), int(head[1])
    except (IndexError, ValueError):
        raise InputError(f"{path}: missing 'cols rows' header of a .dmat file") from None
    if (cols, rows) == (0, 0):  # binary variant: a second header, then raw doubles
        line, _, raw = body.partition(b"\n")
        try:
            cols, rows = (int(w) for w in line.split()[:2])
        except ValueError:
            cols = rows = -1
        if cols < 0 or rows < 0 or len(raw) < 8 * cols * rows:
            raise InputError(f"{path}: binary .dmat needs a 'cols rows' second header and "
                             "8 bytes per value")
        values = np.frombuffer(raw[:8 * cols * rows], dtype="<f8")
    else:
        try:
            values = np.array(body.split(), dtype=float)
        except ValueError:
            raise InputError(f"{path}: non-numeric entry") from None
    if cols < 0 or rows < 0 or not np.isfinite(values).all():
        raise InputError(f"{path}: negative sizes or non-finite values")
    if cols != 1 or values.size != rows:
        raise InputError(f"{path}: expected one column of {rows} values, "
                         f"found {values.size} values in {cols} column(s)")
    if (values != np.round(values)).any():
        raise InputError(f"{path}: group ids must be integers")
    return values.astype(np.int64)
