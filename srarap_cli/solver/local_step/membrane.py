"""Per-vertex 4x4 membrane matrices ``M_i`` (paper section 8).

For a unit rotor ``r``, rest edge ``q`` and deformed edge ``p`` (pure quaternions),
``|r q r~ - p|^2 = |r q - p r|^2 = r^T A^T A r`` with ``A = Rmul(q) - Lmul(p)``.
Because ``q`` and ``p`` are pure, ``A^T A = (|p|^2 + |q|^2) I + 2 Lmul(p) Rmul(q)``, which is
linear in the 3x3 tensor ``p q^T``. So a cell needs only ``S_i = sum_j c_ij p_ij q_ij^T`` and
``s_i = sum_j c_ij (|p_ij|^2 + |q_ij|^2)`` (the paper's eq 8.4, in quaternion form), which
:meth:`~srarap_cli.solver.rest_edges.RestEdges.covariance` provides.
"""
import numpy as np

from ..quaternion import PRODUCT_BASIS

# a matrix product: einsum was 10x slower; the 2 folded in (exact) spares a scaled copy of S
_TWICE_BASIS_ROWS = 2.0 * PRODUCT_BASIS.reshape(9, 16)
_DIAG = np.arange(4)


def membrane_matrices(S: np.ndarray, s: np.ndarray) -> np.ndarray:
    """``M_i = s_i I + 2 sum_ab S_i[a, b] Lmul(e_a) Rmul(e_b)``: (n, 4, 4) symmetric PSD.

    Examples
    --------
    >>> q = np.array([[1., 0, 0]]); S = np.einsum('i,j->ij', q[0], q[0])[None]  # p == q
    >>> M = membrane_matrices(S, np.array([2.0]))
    >>> float(np.array([1., 0, 0, 0]) @ M[0] @ np.array([1., 0, 0, 0]))  # identity fits
    0.0
    """
    M = (np.reshape(S, (-1, 9)) @ _TWICE_BASIS_ROWS).reshape(-1, 4, 4)
    M[:, _DIAG, _DIAG] += s[:, None]
    return M
