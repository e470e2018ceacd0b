"""Paper section 6.3: feedback, the pull of each rotor toward its previous value.

The paper adds ``eps`` times the previous rotor to each row, as if it were one more
neighbour: row ``i`` divided by ``deg_i + eps``. Its weight per row comes in two scalings:
the paper's rows multiplied by ``deg_i + eps`` (``sr-linear``), and the proximal term of the
total energy, one neighbour's weight ``1/deg_i`` times ``eps`` (``sr-linear-sym``,
``sr-relax``). Either way the right-hand side gets ``phi_i R_i^prev``.
"""
import numpy as np

from ..operators import CellGraph


def paper_feedback(graph: CellGraph, alpha_area: float, eps: float) -> np.ndarray:
    """``phi_i = alpha A eps`` for every cell (the paper's row times ``deg_i + eps``): (n,)."""
    return np.full(graph.n, alpha_area * eps)


def proximal_feedback(graph: CellGraph, alpha_area: float, eps: float) -> np.ndarray:
    """``phi_i = alpha A eps / deg_i``: the proximal term ``phi_i |R_i - R_i^prev|^2`` (n,)."""
    return alpha_area * eps / graph.degree.clip(min=1)


def feedback_pull(phi: np.ndarray, R_prev: np.ndarray) -> np.ndarray:
    """``phi_i R_i^prev``, the feedback's share of each row's right-hand side: (n, 4)."""
    return phi[:, None] * R_prev
