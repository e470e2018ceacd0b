"""``sr-linear``: the paper's local step, all rotors from ONE sparse solve (sections 6.1-6.3).

Row ``i`` as in the reference implementation:
``(M_i + alpha A I) R_i - alpha A / (deg_i + eps) sum_j R_j = alpha A eps / (deg_i + eps) R_i^prev``.
Handle rotors come first from their own 4x4 rows with the neighbours' previous rotors (6.2);
every rotor is normalized. The reference calls the system non-symmetric and uses sparse LU;
multiplied by ``deg_i + eps`` each row has ``-alpha A I`` off the diagonal: the same system,
symmetric positive definite, solved by :class:`~.rotor_system.RotorSystem`.
"""
import numpy as np

from ..rest_edges import RestEdges
from .feedback import paper_feedback
from .rotor_system import RotorSystem


class LinearRotorStep(RotorSystem):
    """The paper's rotor system. Parameters: rest edges, constrained mask, ``alpha*A``, ``eps``."""

    bending = True
    needs_stretch = True
    # its fixed point sits 1.3% to 5% above the minimum (see docs/background/method.md)
    near_minimum = False

    def __init__(self, edges: RestEdges, constrained: np.ndarray, alpha_area: float,
                 feedback: float) -> None:
        graph = edges.graph
        scale = (graph.degree + feedback).astype(float)
        super().__init__(edges, constrained, sigma=scale, tau=scale * alpha_area,
                         phi=paper_feedback(graph, alpha_area, feedback),
                         omega=np.full(graph.I.size, alpha_area))
