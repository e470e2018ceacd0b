"""Preconditioned conjugate gradients whose vector work runs in blocks on the solve's threads.

SciPy's ``cg`` runs each vector operation of an iteration as one numpy call on one core: on
the 1.2M-vertex cylinder's rotor system (4.8M unknowns) about fifteen passes over 38 MB
vectors an iteration, a tenth of an iteration's time beside the sparse product and the
preconditioner. Here the same iteration (same recurrences, same stopping test) fuses them
into five passes by blocks of the vector, side by side on the threads of
:mod:`~srarap_cli.runtime.parallel`; each dot product is a sum of per-block partial sums
added in block order, so the iterates are the same bit for bit at any thread count.
"""
from collections.abc import Callable
from functools import partial

import numpy as np

from ...runtime.parallel import blocks as cut_blocks
from ...runtime.parallel import map_blocks, ordered_sum


def conjugate_gradients(product: Callable[[np.ndarray, np.ndarray], float],
                        precondition: Callable[[np.ndarray], np.ndarray], b: np.ndarray,
                        rtol: float, atol: float, maxiter: int) -> tuple[np.ndarray, int]:
    """Solve ``A x = b`` from ``x = 0`` for a symmetric positive definite ``A``.

    Parameters
    ----------
    product : callable ``(p, q) -> p . (A p)``, writing ``A p`` into ``q`` (both (m,) float
        arrays): the matrix's product fused with the dot product it feeds
    precondition : callable, ``r -> M^-1 r`` ((m,) float arrays)
    b : (m,) float array
    rtol, atol : float, stop once ``|r| < max(atol, rtol |b|)`` (SciPy's ``cg`` test)
    maxiter : int, iterations at most

    Returns
    -------
    x : (m,) float array
    info : int, 0 when converged, else ``maxiter`` (as SciPy's ``cg``)

    Examples
    --------
    >>> A = np.array([[4.0, 1.0], [1.0, 3.0]])
    >>> def product(p, q):
    ...     q[:] = A @ p
    ...     return float(p @ q)
    >>> x, info = conjugate_gradients(product, lambda r: r / np.diag(A), np.array([1.0, 2.0]),
    ...                               1e-12, 0.0, 10)
    >>> info, np.allclose(A @ x, [1.0, 2.0])
    (0, True)
    """
    blocks = cut_blocks(b.size, "values")
    b_norm = np.sqrt(_dot(b, b, blocks))
    tol = max(float(atol), float(rtol) * b_norm)
    x = np.zeros_like(b)
    if b_norm == 0.0:
        return x, 0
    r, p, q = b.copy(), np.empty_like(b), np.empty_like(b)
    rr, rho_prev = b_norm * b_norm, 0.0
    for iteration in range(maxiter):
        if np.sqrt(rr) < tol:
            return x, 0
        z = precondition(r)
        rho = _dot(r, z, blocks)
        _update(p, z, rho / rho_prev if iteration else None, blocks)
        alpha = rho / product(p, q)
        rr = _step(x, r, p, q, alpha, blocks)
        rho_prev = rho
    return x, maxiter


def _dot(a, b, blocks):
    """``a . b`` as per-block sums added in block order."""
    return ordered_sum(partial(_dot_block, a, b), blocks)


def _dot_block(a, b, s):
    return float(a[s] @ b[s])


def _update(p, z, beta, blocks):
    """``p = z + beta p``; ``p = z`` for ``beta`` None (the first iteration)."""
    map_blocks(partial(_update_block, p, z, beta), blocks)


def _update_block(p, z, beta, s):
    if beta is not None:
        p[s] *= beta
        p[s] += z[s]
    else:
        p[s] = z[s]


def _step(x, r, p, q, alpha, blocks):
    """``x += alpha p``, ``r -= alpha q`` in one pass; returns ``r . r``."""
    return ordered_sum(partial(_step_block, x, r, p, q, alpha), blocks)


def _step_block(x, r, p, q, alpha, s):
    x[s] += alpha * p[s]
    r[s] -= alpha * q[s]
    return float(r[s] @ r[s])
