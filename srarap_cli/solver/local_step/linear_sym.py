"""``sr-linear-sym``: the exact stationarity of the total energy, one symmetric solve.

The paper's row differentiates only cell ``i``'s energy, but each bending pair appears in two
cells. Differentiating the total energy ``sum_i R_i^T M_i R_i + alpha A sum_i sum_j w_ij
|R_i - R_j|^2`` (``w_ij = 1/deg_i``) gives ``M_i R_i + alpha A sum_j (w_ij + w_ji)(R_i - R_j) = 0``.
Feedback adds the proximal term ``alpha A eps / deg_i |R_i - R_i^prev|^2`` (the weight of one
neighbour times eps, as in the paper's row). Same handle-rotor rule and normalization as
``sr-linear``, same energy, so the two are directly comparable.
"""
import numpy as np

from ..operators import CellGraph
from ..rest_edges import RestEdges
from .feedback import proximal_feedback
from .rotor_system import RotorSystem


def symmetric_weights(graph: CellGraph) -> np.ndarray:
    """``w_ij + w_ji = 1/deg_i + 1/deg_j`` per directed edge."""
    inv = 1.0 / graph.degree.clip(min=1)
    return inv[graph.I] + inv[graph.J]


class SymmetricRotorStep(RotorSystem):
    """Total-energy rotor system. Parameters: rest edges, constrained mask, ``alpha*A``, ``eps``."""

    bending = True
    needs_stretch = True
    near_minimum = True

    def __init__(self, edges: RestEdges, constrained: np.ndarray, alpha_area: float,
                 feedback: float) -> None:
        graph = edges.graph
        W = symmetric_weights(graph)
        row_sum = graph.cell_sum(W)
        prox = proximal_feedback(graph, alpha_area, feedback)
        super().__init__(edges, constrained, sigma=np.ones(graph.n),
                         tau=alpha_area * row_sum + prox, phi=prox, omega=alpha_area * W)
