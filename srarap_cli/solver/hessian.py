"""Second derivatives of the SR-ARAP energy at one state, as matrix-free products or as 3x3
blocks, and its first derivative in the rotors (:func:`rotor_gradient`).

The variables are the positions' increments ``u`` (n, 3) and the rotors' increments ``w``
(n, 3), a rotor moving as ``R -> exp(w / 2) R`` (its rotation turned by the vector ``w``
after ``R``). Half the Hessian, ``Q = H / 2``, has three blocks:

- ``Q_uu = 2 K`` per coordinate, ``K`` the cotangent Laplacian (the membrane is quadratic in
  the positions), so its inverse is one Poisson solve;
- ``Q_wu``: a directed edge ``i -> j`` with rotated rest edge ``a = R_i q_ij R_i~`` couples
  ``w_i`` with ``u_i - u_j`` through ``c_ij [a]x``;
- ``Q_ww``: per cell a 3x3 block of the membrane, ``sum_j c_ij ((|a|^2 - r.a) I - a a^T +
  (r a^T + a r^T) / 2)`` with the residual ``r = a - p_ij``, and the bending term's graph
  coupling: an edge with weight ``beta`` and relative rotor ``D = R_j R_i~`` (hemisphere
  aligned) adds ``beta (D)_w / 4`` to both diagonals and ``-beta vec(v D) / 4`` to row ``i``
  for ``v = w_j`` (its transpose, ``-beta vec(v D~) / 4``, to row ``j`` for ``v = w_i``).

These follow from expanding ``exp(w) a = a + w x a + w x (w x a) / 2`` in the membrane and
``|R_i' - R_j'|^2 = 2 - 2 R_i'.R_j'`` with ``exp(w / 2) = (1 - |w|^2 / 8, w / 2)`` in the
bending term to second order; tests/test_hessian.py checks them against finite differences of
:func:`~srarap_cli.solver.energy.membrane_energy` and
:func:`~srarap_cli.solver.energy.bending_energy`.
"""
from dataclasses import dataclass

import numpy as np

from .group_rotations import label_sum
from .operators import CellGraph
from .quaternion import rotate, to_matrix
from .rest_edges import RestEdges


@dataclass
class EnergyHessian:
    """Products with the blocks ``Q_ww`` and ``Q_wu`` of half the energy's Hessian at one
    state (see the module's text), and with ``Q_wu``'s transpose.

    Per-edge values are kept as (3, m) rows: the products gather, cross and sum contiguous
    rows (three times faster than on (m, 3) arrays at 69k edges), a block of edges at a time
    (:meth:`CellGraph.edge_blocks`: whole, the temporaries took 290 bytes an edge, 317 MB at
    184k vertices).

    Attributes
    ----------
    n : int, vertices
    """

    n: int
    _I: np.ndarray
    _J: np.ndarray
    _blocks: list          # slices of edges
    _ca: np.ndarray        # (3, m) c_ij a_ij
    _ca_sums: np.ndarray   # (n, 3) sum_j c_ij a_ij
    _cells: np.ndarray     # (n, 3, 3) membrane blocks plus the bending diagonal
    _beta_w: np.ndarray    # (m,) bending weight / 4 times D's scalar part
    _beta_v: np.ndarray    # (3, m) bending weight / 4 times D's vector part

    def rotations(self, v: np.ndarray) -> np.ndarray:
        """``Q_ww v`` for rotor increments ``v`` (n, 3): (n, 3)."""
        out = np.einsum("nab,nb->na", self._cells, v)
        rows = np.ascontiguousarray(v.T)
        for e in self._blocks:
            I, J, w, d = self._I[e], self._J[e], self._beta_w[e], self._beta_v[:, e]
            # vec(v D) = d_w v + v x d for a pure quaternion v, vec(v D~) = d_w v - v x d
            vj = np.take(rows, J, axis=1)
            out -= self._sum(w * vj + _cross(vj, d), I)
            vi = np.take(rows, I, axis=1)
            out -= self._sum(w * vi - _cross(vi, d), J)
        return out

    def coupling(self, u: np.ndarray) -> np.ndarray:
        """``Q_wu u`` for position increments ``u`` (n, 3): (n, 3) on the rotors."""
        rows = np.ascontiguousarray(u.T)
        out = np.cross(self._ca_sums, u)
        for e in self._blocks:
            out -= self._sum(_cross(self._ca[:, e], np.take(rows, self._J[e], axis=1)),
                             self._I[e])
        return out

    def coupling_t(self, v: np.ndarray) -> np.ndarray:
        """``Q_uw v`` for rotor increments ``v`` (n, 3): (n, 3) on the positions."""
        rows = np.ascontiguousarray(v.T)
        out = -np.cross(self._ca_sums, v)
        for e in self._blocks:
            out += self._sum(_cross(self._ca[:, e], np.take(rows, self._I[e], axis=1)),
                             self._J[e])
        return out

    def _sum(self, rows, labels):
        """Per-vertex sums (n, 3) of per-edge rows (3, k) by ``labels``."""
        return label_sum(rows.T, labels, self.n)

    def blocks(self, reverse: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The 3x3 blocks of ``Q_ww`` and ``Q_wu``: per vertex (its diagonal block) and per
        directed edge ``i -> j`` (the block of row ``i``, column ``j``).

        Parameters
        ----------
        reverse : (m,) int array, the edge ``j -> i`` of each edge ``i -> j``

        Returns
        -------
        ww_diagonal : (n, 3, 3); ww_edges : (m, 3, 3); wu_diagonal : (n, 3, 3);
        wu_edges : (m, 3, 3)
        """
        w, d = self._beta_w, self._beta_v.T
        ww_edges = _skew(d - d[reverse])
        ww_edges -= (w + w[reverse])[:, None, None] * np.eye(3)
        return self._cells, ww_edges, _skew(self._ca_sums), -_skew(self._ca.T)


def energy_hessian(graph: CellGraph, edges: RestEdges, P: np.ndarray, R: np.ndarray, bending_weight: float
                   ) -> EnergyHessian:
    """Half the Hessian of the SR-ARAP energy at positions ``P`` and rotors ``R``.

    The membrane blocks are per-cell sums, formed from per-cell moments instead of per
    edge: with ``A_i = sum_j c a a^T = R_i T_i R_i^T`` (``T_i`` the rest moment
    ``sum_j c q q^T``) and ``C_i = sum_j c r a^T = A_i - S_i R_i^T`` (``S_i`` the covariance
    of :meth:`RestEdges.cross`), a block is ``(s_i - tr C_i) I - A_i + (C_i + C_i^T) / 2``.

    Parameters
    ----------
    graph : CellGraph
    edges : RestEdges of the graph
    P : (n, 3) float array
    R : (n, 4) float array, unit quaternions
    bending_weight : float, ``alpha * A`` (0: classic ARAP)

    Returns
    -------
    EnergyHessian

    Examples
    --------
    >>> from srarap_cli.solver.operators import cell_graph
    >>> from srarap_cli.solver.rest_edges import RestEdges
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> g = cell_graph(V, np.array([[0, 1, 2]]), "uniform")
    >>> H = energy_hessian(g, RestEdges(g, V), V, np.tile([1., 0, 0, 0], (3, 1)), 1.0)
    >>> u = np.tile([0.3, -0.1, 0.2], (3, 1))   # a translation costs nothing
    >>> bool(np.abs(H.coupling(u)).max() < 1e-15)
    True
    """
    n, m = graph.n, graph.I.size
    Rm = to_matrix(R)
    A = Rm @ edges.rest_moment @ Rm.transpose(0, 2, 1)
    C = A - edges.cross(P) @ Rm.transpose(0, 2, 1)
    trace = np.einsum("nii->n", C)
    cells = (edges.rest_scale - trace)[:, None, None] * np.eye(3) - A + 0.5 * (
        C + C.transpose(0, 2, 1))
    rows, rest = np.ascontiguousarray(R.T), np.ascontiguousarray(edges.rest_positions.T)
    ca, beta_w, beta_v = np.empty((3, m)), np.empty(m), np.empty((3, m))
    blocks = graph.edge_blocks()
    for e in blocks:
        Ri, ca[:, e] = _rotated_edges(graph, e, rows, rest)
        scalar, vector = _relative_rotors(Ri, np.take(rows, graph.J[e], axis=1))
        beta = bending_weight / 4.0 / np.take(graph.degree, graph.I[e])
        beta_w[e], beta_v[:, e] = beta * scalar, beta * vector
    cells += (np.bincount(graph.I, beta_w, n) + np.bincount(graph.J, beta_w, n))[
        :, None, None] * np.eye(3)
    return EnergyHessian(n, graph.I, graph.J, blocks, ca,
                         np.einsum("nab,nb->na", Rm, edges.sum_cq), cells, beta_w, beta_v)


def rotor_gradient(graph: CellGraph, edges: RestEdges, P: np.ndarray, R: np.ndarray,
                   bending_weight: float) -> np.ndarray:
    """Half the gradient of the SR-ARAP energy in the rotors' increments ``w`` (a rotor
    moving as ``R -> exp(w / 2) R``) at positions ``P`` and rotors ``R``: (n, 3).

    The membrane part of row ``i`` is ``-sum_j c_ij a_ij x p_ij`` (``a_ij = R_i q_ij R_i~``,
    ``p_ij = p_j - p_i``); an edge ``i -> j`` of the bending term, weight ``B = bending_weight
    / deg_i`` and relative rotor ``D = s R_j R_i~`` (hemisphere aligned), adds ``-B vec(D) / 2``
    to row ``i`` and ``B vec(D) / 2`` to row ``j``.

    Parameters
    ----------
    graph : CellGraph; edges : RestEdges of the graph
    P : (n, 3) float array; R : (n, 4) float array, unit quaternions
    bending_weight : float, ``alpha * A``

    Examples
    --------
    >>> from srarap_cli.solver.operators import cell_graph
    >>> from srarap_cli.solver.rest_edges import RestEdges
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> g = cell_graph(V, np.array([[0, 1, 2]]), "uniform")
    >>> R = np.tile([1., 0, 0, 0], (3, 1))   # the rest shape is the minimum
    >>> bool(np.abs(rotor_gradient(g, RestEdges(g, V), V, R, 1.0)).max() < 1e-15)
    True
    """
    n = graph.n
    rows, rest = np.ascontiguousarray(R.T), np.ascontiguousarray(edges.rest_positions.T)
    positions = np.ascontiguousarray(P.T)
    out = np.zeros((n, 3))
    for e in graph.edge_blocks():
        I, J = graph.I[e], graph.J[e]
        Ri, ca = _rotated_edges(graph, e, rows, rest)
        p = np.take(positions, J, axis=1) - np.take(positions, I, axis=1)
        out -= label_sum(_cross(ca, p).T, I, n)
        if bending_weight:
            _, vector = _relative_rotors(Ri, np.take(rows, J, axis=1))
            half = vector * (bending_weight / 2.0 / np.take(graph.degree, I))
            out += label_sum(half.T, J, n) - label_sum(half.T, I, n)
    return out


def _rotated_edges(graph, e, rows, rest):
    """For the edges ``e`` (a slice): their source rotors ``R_i`` (4, k) and ``c_ij R_i q_ij
    R_i~`` (3, k), from rotors and rest positions stored as rows (4, n), (3, n)."""
    Ri = np.take(rows, graph.I[e], axis=1)
    q = np.take(rest, graph.J[e], axis=1) - np.take(rest, graph.I[e], axis=1)
    return Ri, graph.c[e] * rotate(Ri.T, q.T).T


def _relative_rotors(Ri, Rj):
    """``D = s R_j R_i~`` with ``s`` the sign that aligns each pair (rotors as (4, k) rows):
    its scalar part ``|R_i.R_j|`` (k,) and vector part ``s (w_i v_j - w_j v_i + v_i x v_j)``
    (3, k)."""
    dots = np.einsum("km,km->m", Ri, Rj)
    vector = Ri[0] * Rj[1:] - Rj[0] * Ri[1:] + _cross(Ri[1:], Rj[1:])
    return np.abs(dots), vector * np.where(dots < 0, -1.0, 1.0)


def _skew(v):
    """``[v]x`` (k, 3, 3) of vectors ``v`` (k, 3)."""
    out = np.zeros((len(v), 3, 3))
    out[:, 0, 1], out[:, 0, 2], out[:, 1, 2] = -v[:, 2], v[:, 1], -v[:, 0]
    out[:, 1, 0], out[:, 2, 0], out[:, 2, 1] = v[:, 2], -v[:, 1], v[:, 0]
    return out


def _cross(a, b):
    """``a x b`` of vectors stored as (3, m) rows."""
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])
