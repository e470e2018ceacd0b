"""Handle files that ask for no deformation at all: every vertex held (the targets are the
result; nothing is solved) or every handle at its rest position (only fixed groups: the
result is the rest shape). Both solve at once to a perfect-looking result, and a golden made
from one guards nothing: say what happened."""
import numpy as np

from ..io.handles import Constraints
from ..runtime.warning_codes import note


def still_request_warnings(V: np.ndarray, constraints: Constraints) -> list[str]:
    """One warning when ``constraints`` hold every vertex of ``V`` or move none of them.

    Parameters
    ----------
    V : (n, 3) float array, the rest positions
    constraints : Constraints, ids (k,) and targets (k, 3), groups by name

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> base = Constraints(ids=np.array([0]), targets=V[[0]], groups={"base": np.array([0])})
    >>> still_request_warnings(V, base)[0][:62]
    "every handle keeps its rest position (group(s) 'base'): the re"
    >>> every = Constraints(ids=np.arange(3), targets=V + 1, groups={})
    >>> still_request_warnings(V, every)[0][:45]
    'every vertex is constrained (3 of 3): the res'
    """
    ids = np.unique(constraints.ids)
    if not ids.size:
        return []
    if ids.size == len(V):
        return [note("all-held", f"every vertex is constrained ({ids.size} of {len(V)}): the "
                     "result is the targets themselves and nothing is solved (leave the "
                     "vertices free that should follow)")]
    diagonal = float(np.linalg.norm(np.ptp(V, axis=0)))
    moved = np.linalg.norm(constraints.targets - V[constraints.ids], axis=1)
    if moved.max() > 1e-9 * max(diagonal, 1e-300):
        return []
    names = ", ".join(map(repr, constraints.groups))
    of = f" (group(s) {names})" if names else ""
    return [note("no-motion", f"every handle keeps its rest position{of}: the result is the "
                 "rest shape (a moving group forgotten, or a motion of zero?)")]
