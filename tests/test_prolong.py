"""The coarse-to-fine start: nearest coarse vertices and the piecewise rigid shape."""
import numpy as np
from helpers import ends, random_rotation, tube, twist

from srarap_cli import Deformer
from srarap_cli.solver.multires import MultiresDeformer
from srarap_cli.solver.multires.prolong import nearest_coarse, prolong
from srarap_cli.solver.operators import cell_graph
from srarap_cli.solver.quaternion import to_matrix
from srarap_cli.solver.rest_edges import RestEdges


def test_nearest_coarse_vertex_follows_the_edges_not_the_straight_line():
    """A U-shaped strip: its right foot lies 1 from coarse vertex 0 (the left foot) in space
    but 11 along the strip, and 5.5 from the other coarse vertex at the top of the U."""
    path = ([[0.0, y] for y in range(6)] + [[0.5, 5.0]] + [[1.0, y] for y in range(5, -1, -1)])
    V = np.array([[x, y, z] for z in (0.0, 0.2) for x, y in path])
    n = len(path)
    F = np.array([t for k in range(n - 1)
                  for t in ([k, k + 1, n + k + 1], [k, n + k + 1, n + k])])
    nearest = nearest_coarse(RestEdges(cell_graph(V, F), V), np.array([0, 6]))
    # along the left arm vertex k is k from the foot and 5.5 - k from the top
    assert nearest[:n].tolist() == [0, 0, 0] + [1] * (n - 3)
    assert np.array_equal(nearest[n:], nearest[:n])


def test_a_part_without_coarse_vertices_is_marked_unreached():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]])
    F = np.array([[0, 1, 2], [3, 4, 5]])
    nearest = nearest_coarse(RestEdges(cell_graph(V, F), V), np.array([1]))
    assert nearest.tolist() == [0, 0, 0, -1, -1, -1]
    P, R = prolong(V, np.array([0, 0, 0, -1, -1, -1]), np.array([1]), np.array([[1.0, 2, 3]]),
                   np.array([[0.0, 0, 0, 1]]))
    assert np.array_equal(P[3:], V[3:]) and np.array_equal(R[3:], np.tile([1.0, 0, 0, 0], (3, 1)))


def test_prolonging_a_rigid_motion_reproduces_it_at_every_vertex():
    rng = np.random.default_rng(3)
    V, F = tube(rings=20, segments=10)
    q1, t = random_rotation(rng), rng.normal(size=3)
    Rm = to_matrix(q1)
    coarse = np.sort(rng.choice(len(V), 15, replace=False))
    q = np.tile(q1, (coarse.size, 1))
    P, R = prolong(V, nearest_coarse(RestEdges(cell_graph(V, F), V), coarse), coarse,
                   V[coarse] @ Rm.T + t, q)
    assert np.abs(P - (V @ Rm.T + t)).max() < 1e-12
    assert np.abs(np.abs(R @ q[0]) - 1).max() < 1e-12


def test_the_refine_start_is_closer_to_the_minimum_than_the_papers_transfer():
    """After its first full-resolution step the coarse-to-fine run is already close to the
    minimum, far below the paper's transferred result (measured on this bar: 8% above the
    minimum against 12.5x)."""
    V, F = tube(length=10.0, rings=60, segments=32)
    ids = ends(V, 10.0)
    T = twist(V, ids, 10.0, 120)
    best = Deformer(V, F, ids).solve(T, tol=1e-9, max_iter=3000).energy
    refined = MultiresDeformer(V, F, ids, size=300).solve(T, tol=1e-6)
    paper = MultiresDeformer(V, F, ids, size=300, multires_mode="transfer").solve(T, tol=1e-6)
    fine = [row for row in refined.log if not row["step"].startswith("coarse")]
    assert fine[1]["total"] < paper.energy
    assert fine[1]["total"] < 1.1 * best


def test_refine_starts_from_the_coarse_result_where_the_handles_give_no_rotation():
    """One end of a tube pushed sideways: the handles only translate, so the harmonic start
    is Laplacian editing; the coarse solution knows the bend (measured: 5.6x the minimum
    energy from the harmonic start, 1.18x from the coarse result)."""
    V, F = tube(length=10.0, rings=60, segments=32)
    ids = ends(V, 10.0)
    T = V[ids].copy()
    T[T[:, 2] > 5] += [4.0, 0, -1.0]
    harmonic = Deformer(V, F, ids).solve(T, max_iter=0).energy
    refined = MultiresDeformer(V, F, ids, size=300).solve(T, tol=1e-6)
    fine = [row for row in refined.log if not row["step"].startswith("coarse")]
    assert fine[0]["total"] < 0.5 * harmonic


def test_refine_reproduces_a_rigid_motion_at_its_first_full_resolution_iterate():
    """Every handle moved by one rigid motion: the harmonic start is exact, and the better
    start is taken even though the coarse result is only close."""
    V, F = tube(length=10.0, rings=60, segments=32)
    ids = ends(V, 10.0)
    q = random_rotation(np.random.default_rng(0))
    moved = V @ to_matrix(q).T + [1.0, 2.0, 3.0]
    refined = MultiresDeformer(V, F, ids, size=300).solve(moved[ids], tol=1e-6)
    fine = [row for row in refined.log if not row["step"].startswith("coarse")]
    assert refined.converged and len(fine) <= 2
    assert np.abs(refined.positions - moved).max() < 1e-10 * np.linalg.norm(np.ptp(V, axis=0))
