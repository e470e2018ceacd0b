"""The one mapping from a failure to its exit code and message line.

``srarap deform``, ``animate``, ``info``, ``compare`` and every job of a batch report the same
failure with the same exit code: they all ask :func:`classify`.
"""
import numpy as np

from . import exit_codes
from .errors import InputError, NumericalError, OutputError, SingularSystemError, UsageProblem
from .limits import is_out_of_memory, memory_note


def classify(exc: BaseException, written: str = "") -> tuple[int, str]:
    """``(exit code, one-line message)`` for the failure ``exc``.

    Parameters
    ----------
    exc : the exception a command or a job stopped with
    written : what the run had committed by then (``"no output written"``), added to the
        messages of failures that can come after a write

    Examples
    --------
    >>> classify(InputError("m.obj: vertex 3 has a NaN coordinate"))
    (4, 'm.obj: vertex 3 has a NaN coordinate')
    >>> classify(SingularSystemError("Factor is exactly singular"))[0]
    5
    """
    tail = f"; {written}" if written else ""
    if isinstance(exc, UsageProblem):
        return exit_codes.USAGE, str(exc)
    if isinstance(exc, InputError):
        return exit_codes.INVALID_INPUT, str(exc)
    if isinstance(exc, MemoryError) or is_out_of_memory(exc):
        return exit_codes.INVALID_INPUT, (
            "out of memory: the mesh is too large for the memory this process may use "
            f"({memory_note()}){tail}")
    if isinstance(exc, OutputError):
        return exit_codes.OUTPUT_ERROR, str(exc)
    if isinstance(exc, NumericalError):
        return exit_codes.NUMERICAL_FAILURE, f"{exc}{tail}"
    if isinstance(exc, SingularSystemError | np.linalg.LinAlgError):
        return exit_codes.NUMERICAL_FAILURE, (
            f"singular system ({exc}): degenerate geometry (coincident or collinear vertices, "
            f"zero-area triangles){tail}")
    if isinstance(exc, OSError):  # a file operation the checks before it did not foresee
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        return exit_codes.OUTPUT_ERROR, f"{where}{exc.strerror or exc}"
    return exit_codes.INTERNAL_ERROR, (f"internal error: {type(exc).__name__}: {exc} "
                                       "(rerun with --debug for the traceback and report it)")
