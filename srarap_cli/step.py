"""One local/global iteration (paper sections 5-6) for one set of targets: state -> state."""
import numpy as np

from .energy import accurate_enough, membrane_energy, membrane_from_covariance
from .quaternion import to_matrix
from .state import State


class LocalGlobalStep:
    """The fixed-point map ``G``: local step (new rotors from the state's covariances), then
    the global step (a Poisson solve for the positions of those rotors).

    Built per solve by :meth:`Deformer.step_for`; drivers call it, starts use
    :meth:`positions` and :meth:`state`.

    Parameters
    ----------
    deformer : Deformer, the precomputed setup
    targets : (k, 3) float array, in the order of ``deformer.constrained``
    tol : float, the stopping tolerance: energies are evaluated accurately enough for it
    """

    def __init__(self, deformer, targets, tol):
        self.deformer = deformer
        self.tol = tol
        self.targets = np.asarray(targets, dtype=float).reshape(-1, 3)
        self.fixed_targets = deformer.fixed_targets(self.targets)
        self._poisson = deformer.poisson.bind(self.fixed_targets)

    def __call__(self, state):
        R = self.deformer.local_step.step(state.covariances, state.stretch, state.rotors)
        Rm = to_matrix(R)
        return self.state(self.positions(R, Rm), R, Rm, state.iteration + 1)

    def positions(self, R, Rm=None):
        """Global step: the positions (n, 3) that best fit rotors ``R`` (n, 4)."""
        return self._poisson(self.deformer.edges.rotated_divergence(R, Rm))

    def state(self, P, R, Rm=None, iteration=0):
        """The :class:`State` of positions ``P`` with rotors ``R`` (energy included)."""
        d = self.deformer
        S = d.edges.cross(P)
        if d.local_step.needs_stretch:
            s = d.edges.stretch(P)
            stretch_total = float(s.sum())
        else:
            s, stretch_total = None, d.edges.stretch_total(P)
        Rm = to_matrix(R) if Rm is None else Rm
        membrane = membrane_from_covariance(S, stretch_total, Rm)
        if not accurate_enough(membrane, stretch_total, self.tol):
            # near-rigid shapes or tol 0: the cancelling form is too coarse, sum residuals
            membrane = membrane_energy(d.graph, d.edges.q, P, R)
        return State(P, R, Rm, S, s, membrane, d.bending(R), iteration)
