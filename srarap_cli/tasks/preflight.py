"""What a command checks before any work: outputs that could not be written, outputs that
are inputs, and the inputs every job reads the same way (a mesh from a path or standard
input, a handle file at a pose)."""
import dataclasses
import os
import stat
import sys
from collections.abc import Sequence

import numpy as np

from ..io.handles import Constraints, load_handles, referenced_files
from ..io.mesh import MeshFormat, open_mesh
from ..io.mesh.formats import suffix_of
from ..io.mesh.mesh import Mesh
from ..io.mesh.meshio_formats import needs
from ..io.mesh.stream import read_mesh_stream
from ..runtime.errors import InputError, OutputError, UsageProblem
from ..runtime.paths import refuse_overwriting_inputs


def check_output_path(path: str, allowed: Sequence[str] | None, what: str) -> None:
    """Fail before any work when an output could not be written (``allowed``: its
    extensions; None when the format is given otherwise). A missing folder is not a failure:
    every command makes the missing folders of its outputs when it writes them. A device or
    a descriptor (``/dev/stdout``, ``/dev/null``) is written through whatever its name."""
    ext = suffix_of(path)
    if allowed is not None and ext not in allowed and (hint := needs(path)):
        raise InputError(f"{path}: {hint}")
    if allowed is not None and ext not in allowed and not _device(path):
        raise UsageProblem(f"{what} {path!r}: extension must be one of {', '.join(allowed)}")
    folder = os.path.dirname(os.path.abspath(path))
    existing = folder
    while not os.path.exists(existing):  # missing folders are made when the files are written
        existing = os.path.dirname(existing)
    if not os.path.isdir(existing):
        raise OutputError(f"{path}: {existing} is a file, not a folder")
    if not os.access(existing, os.W_OK) and not _device(path):
        raise OutputError(f"{path}: folder {existing} is not writable")
    if os.path.isdir(path):
        raise OutputError(f"{path}: is a folder")


def _device(path: str) -> bool:
    """Whether ``path`` exists and is not a regular file or folder (a device, a pipe, a
    terminal, an open descriptor's name): written through, never replaced."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


def refuse_overwrite(outputs: Sequence[str | None], *, mesh: str | None = None,
                     handles: str | None = None,
                     others: Sequence[tuple[str, str]] = ()) -> None:
    """Fail (exit 4) before any work when an output is one of the run's inputs: the mesh, the
    handle file, the files it names, or ``others`` ((what, path) pairs)."""
    if mesh == "-" and handles == "-":
        raise UsageProblem("MESH and HANDLES cannot both be '-': standard input holds one; "
                           "give the other as a file or a pipe (<(...))")
    inputs = [("mesh", mesh)] if mesh not in (None, "-") else []
    if handles is not None:
        inputs.append(("handle file", handles))
        inputs += [("file the handle file names", p) for p in referenced_files(handles)]
    refuse_overwriting_inputs([o for o in outputs if o not in (None, "-")],
                              inputs + list(others))


def read_any_mesh(path: str, input_format: MeshFormat | None = None
                  ) -> tuple[Mesh, MeshFormat]:
    """``(mesh, format)``: standard input for ``-`` (as ``input_format``, or the format its
    bytes show), else the file ``path`` (by its extension, or by its bytes where no format
    claims the extension: no extension, ``.txt``, ``/dev/stdin``, a pipe)."""
    if path == "-":
        return read_mesh_stream(sys.stdin.buffer if sys.stdin else None, input_format)
    return open_mesh(path)


def load_posed(handles: str, V: np.ndarray, fps: float | None, frame: float) -> Constraints:
    """The constraints of ``handles`` with keyframed groups at ``frame``. Frame 0 is time 0
    at any frame rate, so its pose needs no ``--fps`` even where keys give times."""
    constraints = load_handles(handles, V, fps=fps, any_rate=frame == 0)
    if frame == 0 or not constraints.tracks:
        return constraints
    return dataclasses.replace(constraints, targets=constraints.targets_at(frame))
