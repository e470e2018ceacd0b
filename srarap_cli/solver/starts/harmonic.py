"""Rotation-aware start: the handles' rotations spread harmonically, then one Poisson solve.

Laplacian editing starts every cell at the identity, far off for any twist or bend. Here each
handle group's best-fit rotation (rest to target, identity for a fixed group) is spread over
the mesh by the cotangent Laplace equation ``L R = 0`` with those rotors as Dirichlet values
(four right-hand sides, then normalized: the paper's section 7.1 interpolation applied to the
handles), and the positions follow from one global step. When every constrained vertex moves
by one rigid motion the start is that motion exactly.
"""
import numpy as np

from ..group_rotations import group_rotors, label_sum
from ..quaternion import IDENTITY, align_hemisphere, normalize
from ..state import State
from ..step import LocalGlobalStep


def harmonic_start(step: LocalGlobalStep, initial: object = None) -> State:
    """Start from the handles' rotations, harmonically interpolated.

    Parameters
    ----------
    step : LocalGlobalStep
    initial : ignored

    Returns
    -------
    State
    """
    R = spread_handle_rotors(step, step.deformer.V)
    return step.state(step.positions(R), R)


def spread_handle_rotors(step: LocalGlobalStep, P: np.ndarray) -> np.ndarray:
    """Rotors (n, 4): each handle group's best-fit rotation from its vertices' positions in
    ``P`` (n, 3) to the step's targets, spread harmonically (immovable vertices keep the
    identity) and normalized."""
    d = step.deformer
    held = np.tile(IDENTITY, (d.fixed.size, 1))
    held[d.constrained_slots] = handle_rotors(P[d.constrained], step.targets, d.labels)
    # the Poisson factorization is the Dirichlet Laplacian of the held vertices: reuse it
    R = d.poisson.bind(held)(np.zeros((len(d.V), 4)))
    return normalize(R, np.broadcast_to(IDENTITY, R.shape))


def handle_rotors(rest: np.ndarray, targets: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """One rotor per constrained vertex: its group's best-fit rotation, on the hemisphere
    ``w >= 0`` (so that rotations spread the short way from the identity). A group whose
    rest points are collinear fixes no rotation: it takes the mean of the determined groups'
    rotors (weighted by size), or the identity if there is none.

    Parameters
    ----------
    rest, targets : (k, 3) float arrays
    labels : (k,) int array

    Returns
    -------
    (k, 4) float array

    Examples
    --------
    >>> rest = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> turned = rest @ np.array([[0., -1, 0], [1, 0, 0], [0, 0, 1]]).T  # 90 degrees about z
    >>> np.round(handle_rotors(rest, turned, np.zeros(3, int))[0], 6).tolist()
    [0.707107, 0.0, 0.0, 0.707107]
    """
    n_groups = int(labels.max(initial=-1)) + 1
    R, determined = group_rotors(rest, targets, labels, n_groups)
    if not determined.all():
        mean = label_sum(R[determined], np.zeros(int(determined.sum()), np.int64), 1)[0]
        fallback = mean if np.linalg.norm(mean) > 0 else IDENTITY
        R[~determined] = fallback / np.linalg.norm(fallback)
    return align_hemisphere(R, np.broadcast_to(IDENTITY, R.shape))
