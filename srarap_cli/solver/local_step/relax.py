"""``sr-relax``: per-cell relaxation, the state of the art the paper replaces (Levi & Gotsman).

Each cell's rotor becomes the best unit quaternion with its neighbours' rotors held fixed, for
the same total energy as ``sr-linear-sym``: ``R^T M_i R + alpha A sum_j W_ij |R - R_j|^2`` plus
the feedback term, i.e. ``min R^T M_i R - 2 b_i . R`` over ``|R| = 1`` with ``b_i = alpha A
sum_j W_ij R_j + phi_i R_i^prev``. That is solved exactly through the eigenvectors of ``M_i``
and the secular equation of the unit constraint. Sweeps visit the cells colour by colour
(no two neighbours share a colour), so a sweep is a true Gauss-Seidel pass and each colour
is one vectorized update.
"""
import numpy as np
import scipy.sparse as sp

from ..operators import CellGraph
from ..quaternion import align_hemisphere
from ..rest_edges import RestEdges
from .feedback import feedback_pull, proximal_feedback
from .linear_sym import symmetric_weights
from .membrane import membrane_matrices

_NEWTON_STEPS = 40


def colour_classes(graph: CellGraph, seed: int = 0) -> list[np.ndarray]:
    """Vertex colour classes (list of int arrays), neighbours never sharing a colour.

    Jones-Plassmann rounds: every uncoloured vertex whose random priority beats all its
    uncoloured neighbours takes the round's colour; deterministic for a fixed seed.
    """
    A = sp.csr_matrix((np.ones(graph.I.size), (graph.I, graph.J)), shape=(graph.n,) * 2)
    priority = np.random.default_rng(seed).permutation(graph.n).astype(float) + 1
    left = np.ones(graph.n, dtype=bool)
    classes = []
    while left.any():
        live = np.where(left, priority, 0.0)
        best_neighbour = (A.multiply(live[None, :])).max(axis=1).toarray().ravel()
        pick = left & (live > best_neighbour)
        classes.append(np.flatnonzero(pick))
        left &= ~pick
    return classes


def best_unit_rotor(lam: np.ndarray, Q: np.ndarray, b: np.ndarray,
                    fallback: np.ndarray) -> np.ndarray:
    """``argmin_{|R|=1} R^T M R - 2 b . R`` for stacks of ``M = Q diag(lam) Q^T``.

    Parameters
    ----------
    lam : (k, 4) ascending eigenvalues; Q : (k, 4, 4) eigenvectors (columns); b : (k, 4)
    fallback : (k, 4), returned where ``b`` vanishes and no minimizer is defined

    With ``M = Q diag(lam) Q^T`` and ``beta = Q^T b`` the minimizer is ``Q y``,
    ``y = beta / (lam - mu)`` for the ``mu < lam_1`` that makes ``|y| = 1``. Newton on the
    concave ``1/|y(mu)| - 1`` converges monotonically from the pole side (Moré & Sorensen),
    starting at ``mu = lam_1 - |beta_1|`` where ``|y| >= 1``. When ``beta_1`` vanishes (the
    "hard case") the remaining length goes along the first eigenvector.
    """
    beta = np.einsum("kji,kj->ki", Q, b)
    scale = np.abs(lam).max(axis=1) + np.linalg.norm(beta, axis=1) + 1e-300
    mu = lam[:, 0] - np.maximum(np.abs(beta[:, 0]), 1e-14 * scale)
    with np.errstate(divide="ignore", invalid="ignore"):  # zero rows: fallback below
        mu = _secular_newton(lam, beta, mu)
        y = beta / (lam - mu[:, None])
    short = np.sum(y ** 2, axis=1) < 1 - 1e-8  # hard case: top up along the first eigenvector
    sign = np.where(beta[short, 0] < 0, -1.0, 1.0)
    y[short, 0] = sign * np.sqrt(1 - np.sum(y[short, 1:] ** 2, axis=1).clip(max=1))
    R = np.einsum("kij,kj->ki", Q, y)
    with np.errstate(divide="ignore", invalid="ignore"):
        R /= np.linalg.norm(R, axis=1, keepdims=True)
    bad = ~np.isfinite(R).all(axis=1)
    R[bad] = fallback[bad]
    return R


def _secular_newton(lam, beta, mu):
    """Newton iterations on ``1/|beta / (lam - mu)| - 1``, never stepping right."""
    for _ in range(_NEWTON_STEPS):
        gap = lam - mu[:, None]
        ny = np.linalg.norm(beta / gap, axis=1)
        dphi = -np.sum(beta ** 2 / gap ** 3, axis=1) / ny ** 3
        step = (1 / ny - 1) / dphi
        step = np.where(np.isfinite(step) & (step > 0), step, 0.0)
        mu = mu - step
        if not (step > 1e-15 * (np.abs(mu) + np.abs(lam[:, 0]))).any():
            break
    return mu


class RelaxRotorStep:
    """Gauss-Seidel sweeps of exact per-cell rotor fits.

    Parameters
    ----------
    edges : RestEdges
    constrained : (n,) bool array (unused: every cell relaxes; positions carry the constraints)
    alpha_area : float
    feedback : float
    sweeps : int >= 1
    """

    bending = True
    needs_stretch = True
    near_minimum = True

    def __init__(self, edges: RestEdges, constrained: np.ndarray, alpha_area: float,
                 feedback: float, sweeps: int = 2) -> None:
        graph = edges.graph
        W = symmetric_weights(graph)
        self._W = sp.csr_matrix((alpha_area * W, (graph.I, graph.J)), shape=(graph.n,) * 2)
        self._phi = proximal_feedback(graph, alpha_area, feedback)
        self._rows = [(c, self._W[c]) for c in colour_classes(graph)]
        self.sweeps = int(sweeps)

    def step(self, S: np.ndarray, s: np.ndarray | None, R_prev: np.ndarray,
             forcing: float = 0.0) -> np.ndarray:  # exact per-cell fits: forcing unused
        assert s is not None  # needs_stretch: the step passes the stretch
        lam, Q = np.linalg.eigh(membrane_matrices(S, s))
        R = R_prev.copy()
        for _ in range(self.sweeps):
            for cls, W_rows in self._rows:
                b = W_rows @ R + feedback_pull(self._phi[cls], R_prev[cls])
                R[cls] = align_hemisphere(best_unit_rotor(lam[cls], Q[cls], b, R[cls]), R[cls])
        return R
