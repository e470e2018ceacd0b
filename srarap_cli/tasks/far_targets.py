"""Targets several mesh diagonals from their rest positions: a units slip (millimetres read
as metres) far more often than a request, and a solve of one runs for minutes before it
stops unconverged. Refused before the setup unless ``allow`` takes ``units``."""
from collections.abc import Sequence

import numpy as np

from ..io.handles import Constraints
from ..runtime.errors import InputError

#: how many bounding-box diagonals a target may lie from its rest position before the
#: request is refused (from one diagonal on it is a ``units`` warning)
FAR_DIAGONALS = 3.0


def refuse_far_targets(V: np.ndarray, constraints: Constraints, allow: Sequence[str],
                       notes: Sequence[str] = ()) -> None:
    """InputError (exit 4) when a target of ``constraints`` lies more than
    :data:`FAR_DIAGONALS` diagonals of ``V``'s bounding box from its rest position, naming the
    handle file's own ``units`` warnings (``notes``) where there are some.

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [3, 0, 0], [0, 4, 0]])  # diagonal 5
    >>> far = Constraints(ids=np.array([1]), targets=np.array([[3., 20, 0]]), groups={})
    >>> refuse_far_targets(V, far, ())
    Traceback (most recent call last):
    ...
    srarap_cli.runtime.errors.InputError: targets move vertices by up to 20, 4 times the \
mesh's bounding-box diagonal (5): check the units [units] (targets more than 3 diagonals \
away are refused; --allow units solves them)
    >>> refuse_far_targets(V, far, ("units",)) is None
    True
    """
    if "units" in allow or not len(constraints.ids):
        return
    diagonal = float(np.linalg.norm(np.ptp(V, axis=0)))
    reach = float(np.linalg.norm(constraints.targets - V[constraints.ids], axis=1).max())
    if not diagonal > 0 or reach <= FAR_DIAGONALS * diagonal:
        return
    said = [str(w) for w in notes if str(w).endswith("[units]")]
    what = "; ".join(said) or (f"targets move vertices by up to {reach:.4g}, "
                               f"{reach / diagonal:.3g} times the mesh's bounding-box diagonal "
                               f"({diagonal:.4g}): check the units [units]")
    raise InputError(f"{what} (targets more than {FAR_DIAGONALS:g} diagonals away are "
                     "refused; --allow units solves them)")
