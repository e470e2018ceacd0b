"""One local/global iteration (paper sections 5-6) for one set of targets: state -> state."""

import numpy as np

from .energy import accurate_enough, membrane_energy, membrane_from_covariance
from .precomputed import Precomputed
from .quaternion import to_matrix
from .state import State

# How inexactly the local step may solve its rotor system: to this fraction of the previous
# rotors' residual, at most, and to ``sqrt(tol)`` for tighter solves (a tol-0 solve is exact).
# Measured, default tol 1e-6: CG iterations per local step Spot 5.35 -> 2.3, bust 9.1 -> 4.0,
# with the same outer iterations to 0.1% of the minimum. The bias this leaves in the fixed
# point, run to tol 1e-13 with the forcing held at 1e-3: 2.6e-7 (bust), 2.1e-7 (Spot), 1.0e-6
# (test tube) of the diagonal, far below a tol-1e-6 stop's own distance to the minimum. Ten
# times looser (1e-2) cut CG to 2.0-2.1 but moved the bust's tight shape by 1.2e-5.
MAX_FORCING = 1e-3


def local_forcing(tol: float) -> float:
    """The local step's forcing for a solve to ``tol``."""
    return min(MAX_FORCING, float(np.sqrt(max(tol, 0.0))))


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

    def __init__(self, deformer: Precomputed, targets: np.ndarray, tol: float) -> None:
        self.deformer = deformer
        self.tol = tol
        self.forcing = local_forcing(tol)
        self.targets = np.asarray(targets, dtype=float).reshape(-1, 3)
        self.fixed_targets = deformer.fixed_targets(self.targets)
        self._poisson = deformer.poisson.bind(self.fixed_targets)

    def __call__(self, state: State) -> State:
        R = self.local(state)
        Rm = to_matrix(R)
        return self.state(self.positions(R, Rm), R, Rm, state.iteration + 1)

    def local(self, state: State) -> np.ndarray:
        """Local step: new rotors (n, 4) for the state's positions (its rotors are the
        previous ones: feedback, constrained rotors, hemispheres)."""
        return self.deformer.local_step.step(state.covariances, state.stretch, state.rotors,
                                             self.forcing)

    def positions(self, R: np.ndarray, Rm: np.ndarray | None = None) -> np.ndarray:
        """Global step: the positions (n, 3) that best fit rotors ``R`` (n, 4)."""
        return self._poisson(self.deformer.edges.rotated_divergence(R, Rm))

    def state(self, P: np.ndarray, R: np.ndarray, Rm: np.ndarray | None = None, iteration: int = 0,
              energy: bool = True) -> State:
        """The :class:`State` of positions ``P`` with rotors ``R``; ``energy=False`` leaves
        the energy terms NaN (a driver that only needs the covariances)."""
        d = self.deformer
        S = d.edges.cross(P)
        if d.local_step.needs_stretch:
            s = d.edges.stretch(P)
            stretch_total = float(s.sum())
        else:
            s, stretch_total = None, d.edges.stretch_total(P)
        if not energy:
            return State(P, R, S, s, stretch_total, float("nan"), float("nan"), iteration)
        return self._evaluate(P, R, to_matrix(R) if Rm is None else Rm, S, s, stretch_total,
                              iteration)

    def with_rotors(self, state: State, R: np.ndarray, iteration: int | None = None) -> State:
        """The state's positions with other rotors ``R``: covariances reused, energy anew."""
        return self._evaluate(state.positions, R, to_matrix(R), state.covariances,
                              state.stretch, state.stretch_total,
                              state.iteration if iteration is None else iteration)

    def _evaluate(self, P, R, Rm, S, s, stretch_total, iteration):
        d = self.deformer
        membrane = membrane_from_covariance(S, stretch_total, Rm)
        if not accurate_enough(membrane, stretch_total, self.tol):
            # near-rigid shapes or tol 0: the cancelling form is too coarse, sum residuals
            membrane = membrane_energy(d.graph, d.edges.q, P, R)
        return State(P, R, S, s, stretch_total, membrane, d.bending(R), iteration)
