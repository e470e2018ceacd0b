"""The SR-ARAP energy: one definition for every method, the log and the tests.

``E = sum_i [ sum_{j in N(i)} c_ij |R_i q_ij R_i~ - p_ij|^2
              + alpha * A * sum_{j in N(i)} (1 / deg_i) * min(|R_i - R_j|^2, |R_i + R_j|^2) ]``

``q_ij``/``p_ij`` are rest/deformed edge vectors, ``c_ij`` the edge weights, ``A`` the total
surface area, ``deg_i`` the number of neighbours. The ``min`` makes the bending term blind to
the sign of a quaternion (``q`` and ``-q`` are the same rotation).
"""

from functools import partial

import numpy as np

from ..runtime.parallel import blocks, ordered_sum
from .operators import CellGraph
from .quaternion import rotate


def membrane_energy(graph: CellGraph, rest_edges: np.ndarray, P: np.ndarray, R: np.ndarray) -> float:
    """``sum_i sum_j c_ij |R_i q_ij R_i~ - p_ij|^2``, from per-edge residuals.

    Parameters
    ----------
    graph : CellGraph
    rest_edges : (m, 3) float array
    P : (n, 3) float array, deformed positions
    R : (n, 4) float array, unit rotors

    Summing residuals (rather than expanding ``|q|^2 + |p|^2 - 2 p.Rq``) keeps the value
    accurate down to the rounding of the positions, so convergence near a rigid motion is
    still measurable.
    """
    p = np.take(P, graph.J, axis=0) - np.take(P, graph.I, axis=0)
    residual = rotate(np.take(R, graph.I, axis=0), rest_edges) - p
    return float(graph.c @ np.einsum("ij,ij->i", residual, residual))


def membrane_from_covariance(S: np.ndarray, stretch_total: float, Rm: np.ndarray) -> float:
    """The membrane energy from cell covariances: ``sum_i s_i - 2 trace(R_i^T S_i)``.

    Exact algebra (``|Rq - p|^2 = |q|^2 + |p|^2 - 2 p.Rq``), nearly free once ``S`` and
    ``sum_i s_i`` are known, but it cancels: its rounding error is about
    ``1e-16 * sum_i s_i``, so it is only trustworthy when the energy is far above that (see
    :func:`accurate_enough`).

    Parameters
    ----------
    S : (n, 3, 3) from RestEdges.cross; stretch_total : float, RestEdges.stretch_total;
    Rm : (n, 3, 3) rotation matrices
    """
    total = ordered_sum(partial(_traces, Rm, S), blocks(len(S)))
    return float(stretch_total - 2.0 * total)


def _traces(Rm, S, rows):
    """``sum_i trace(R_i^T S_i)`` over a block of cells."""
    return float(np.einsum("nab,nab->", Rm[rows], S[rows]))


def accurate_enough(value: float, scale: float, tol: float) -> bool:
    """Whether a cancelling evaluation of size ``value`` (rounding ~1e-16 * ``scale``) is
    accurate to 1% of the relative tolerance ``tol`` the caller will test it against.
    (``value`` is negative only when negative cotangent weights make the energy unbounded.)"""
    return tol > 0 and abs(value) * tol >= 1e-14 * scale


def bending_energy(graph: CellGraph, R: np.ndarray, alpha: float, area: float) -> float:
    """``alpha * area * sum_i sum_j min(|R_i - R_j|^2, |R_i + R_j|^2) / deg_i``.

    ``area`` is passed, not read from ``graph``, so that a solve restricted to a region of
    interest keeps the whole mesh's ``A`` and the same meaning of ``alpha``.
    """
    if alpha == 0:
        return 0.0
    sq = np.einsum("ij,ij->i", R, R)
    total = ordered_sum(partial(_bending_part, graph, R, sq), graph.edge_blocks())
    return float(alpha * area * total)


def _bending_part(graph, R, sq, e):
    """The bending sum over a block ``e`` of edges (``sq``: each rotor's squared norm)."""
    I, J = graph.I[e], graph.J[e]
    dots = np.einsum("ij,ij->i", np.take(R, I, axis=0), np.take(R, J, axis=0))
    # |a -+ b|^2 = |a|^2 + |b|^2 -+ 2 a.b ; the min takes the sign that agrees
    dist = np.take(sq, I) + np.take(sq, J) - 2.0 * np.abs(dots)
    return float(np.maximum(dist, 0.0) @ (1.0 / np.take(graph.degree, I)))
