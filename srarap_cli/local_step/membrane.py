"""Per-vertex 4x4 membrane matrices ``M_i`` (paper section 8).

For a unit rotor ``r``, rest edge ``q`` and deformed edge ``p`` (pure quaternions),
``|r q r~ - p|^2 = |r q - p r|^2 = r^T A^T A r`` with ``A = Rmul(q) - Lmul(p)``.
Because ``q`` and ``p`` are pure, ``A^T A = (|p|^2 + |q|^2) I + 2 Lmul(p) Rmul(q)``, which is
linear in the 3x3 tensor ``p q^T``. So a cell needs only ``S_i = sum_j c_ij p_ij q_ij^T`` and
``s_i = sum_j c_ij (|p_ij|^2 + |q_ij|^2)`` (the paper's eq 8.4, in quaternion form).
"""
import numpy as np

from ..quaternion import multiply


def _product_basis():
    """``T[a, b] = Lmul(e_a) Rmul(e_b)`` for the pure unit quaternions ``e_a, e_b``."""
    eye = np.eye(4)
    T = np.empty((3, 3, 4, 4))
    for a in range(3):
        for b in range(3):
            # column k of Lmul(e_a) Rmul(e_b) is e_a * (e_k * e_b)
            T[a, b] = multiply(eye[1 + a], multiply(eye, eye[1 + b])).T
    return T


_BASIS = _product_basis()


def cell_covariance(graph, rest_edges, rest_sq, P):
    """Cross-covariance ``S_i`` and squared-length sum ``s_i`` of every cell.

    Parameters
    ----------
    graph : CellGraph
    rest_edges : (m, 3) float array, ``q_j - q_i`` per directed edge
    rest_sq : (m,) float array, ``|q_j - q_i|^2``
    P : (n, 3) float array, deformed positions

    Returns
    -------
    S : (n, 3, 3) float array
    s : (n,) float array
    """
    p = P[graph.J] - P[graph.I]
    c = graph.c
    outer = (c[:, None, None] * p[:, :, None]) * rest_edges[:, None, :]
    S = graph.cell_sum(outer)
    s = graph.cell_sum(c * (np.einsum("ij,ij->i", p, p) + rest_sq))
    return S, s


def membrane_matrices(S, s):
    """``M_i = s_i I + 2 sum_ab S_i[a, b] Lmul(e_a) Rmul(e_b)``: (n, 4, 4) symmetric PSD.

    Examples
    --------
    >>> q = np.array([[1., 0, 0]]); S = np.einsum('i,j->ij', q[0], q[0])[None]  # p == q
    >>> M = membrane_matrices(S, np.array([2.0]))
    >>> float(np.array([1., 0, 0, 0]) @ M[0] @ np.array([1., 0, 0, 0]))  # identity fits
    0.0
    """
    return s[:, None, None] * np.eye(4) + 2.0 * np.einsum("nab,abij->nij", S, _BASIS)
