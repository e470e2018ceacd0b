"""Outputs must never land on inputs: the same file, however it is named."""
import os
from collections.abc import Sequence

from .errors import InputError


def _identity(path):
    """(real path, (device, inode) or None) of ``path``."""
    real = os.path.realpath(path)
    try:
        st = os.stat(real)
    except OSError:  # not there yet, or unreachable: the real path alone identifies it
        return real, None
    return real, (st.st_dev, st.st_ino)


def refuse_overwriting_inputs(outputs: Sequence[str], inputs: Sequence[tuple[str, str]]) -> None:
    """Raise :class:`InputError` when any of ``outputs`` is one of ``inputs``: the same real
    path (``./in.obj``, an absolute path, a symbolic link) or the same file (a hard link).

    Parameters
    ----------
    outputs : iterable of str, files the run would write
    inputs : iterable of (what, path), e.g. ``("mesh", "in.obj")``

    Examples
    --------
    >>> refuse_overwriting_inputs(["out.obj"], [("mesh", "in.obj")])
    >>> refuse_overwriting_inputs(["./in.obj"], [("mesh", "in.obj")])
    Traceback (most recent call last):
    ...
    srarap_cli.runtime.errors.InputError: ./in.obj: is the mesh (in.obj); refusing to overwrite an input
    """
    by_path: dict[str, tuple[str, str]] = {}
    by_file: dict[tuple[int, int], tuple[str, str]] = {}
    for what, path in inputs:
        real, key = _identity(path)
        by_path.setdefault(real, (what, path))
        if key is not None:
            by_file.setdefault(key, (what, path))
    for out in outputs:
        real, key = _identity(out)
        hit = by_path.get(real) or (by_file.get(key) if key is not None else None)
        if hit is not None:
            what, path = hit
            raise InputError(f"{out}: is the {what} ({path}); refusing to overwrite an input")


class Held(str):
    """A folder's real path, taken once when a run starts (:func:`hold`). Paths built on it
    do not pass through the name the user gave, so a link put in that name's place later
    redirects nothing; and :func:`leads_out` answers for every path in it once it is no
    longer that real path (the folder, or one above it, swapped for a link mid-run)."""


def hold(folder: str) -> Held:
    """``folder`` held as it is now (see :class:`Held`).

    Examples
    --------
    >>> hold("/") == "/" and isinstance(hold("/"), Held)
    True
    """
    return Held(os.path.realpath(folder))


def leads_out(path: str, folder: str) -> str | None:
    """Where ``path`` would be written when that is outside ``folder`` (its real path,
    symbolic links followed, in the file's name and in every folder above it); None when it
    stays inside. Asked at the moment of writing: a link made while a run goes on counts.

    Examples
    --------
    >>> leads_out("res/a/b.obj", "res") is None
    True
    >>> leads_out("res/../x.obj", "res") is not None
    True
    """
    root = os.path.realpath(folder)
    if isinstance(folder, Held) and root != folder:
        return root  # the held folder itself now leads elsewhere
    target = os.path.realpath(path)
    return None if os.path.commonpath([root, target]) == root else target
