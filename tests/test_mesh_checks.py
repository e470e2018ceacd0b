"""Fans around each vertex (non-manifold vertices) against a per-vertex union-find written out
here and against libigl's ``is_vertex_manifold``; the one-way edge adjacency against the
symmetric one; the extent check over used vertices."""
import numpy as np
import pytest
import scipy.sparse as sp
from helpers import torus, tube_mesh

from srarap_cli.solver.group_rotations import connected_groups
from srarap_cli.solver.libigl import igl
from srarap_cli.solver.mesh_checks import (
    edge_adjacency,
    fans_per_vertex,
    geometry_problem,
    mesh_warnings,
    solvable_faces,
)


def root(group, i):
    while group[i] != i:
        i = group[i]
    return i


def fans_by_hand(F, n):
    """Per vertex: its faces, merged whenever two share an edge at the vertex."""
    out = np.zeros(n, dtype=np.int64)
    for v in range(n):
        faces = [set(f.tolist()) for f in F if v in f]
        group = list(range(len(faces)))
        for a in range(len(faces)):
            for b in range(a):
                if (faces[a] & faces[b]) - {v}:
                    group[root(group, a)] = root(group, b)
        out[v] = len({root(group, i) for i in range(len(faces))})
    return out


def double_cone():
    """Two closed cones sharing their apex 0: every ring around the apex is a closed cycle,
    so counting edges and neighbours cannot see that there are two of them."""
    k = 6
    ring = [1 + i for i in range(k)], [1 + k + i for i in range(k)]
    F = []
    for r, tip in zip(ring, (2 * k + 1, 2 * k + 2)):
        for i in range(k):
            a, b = r[i], r[(i + 1) % k]
            F += [[0, a, b], [tip, b, a]]
    return np.array(F), 2 * k + 3


def glued(seed):
    """A torus with random vertex pairs merged: pinches, non-manifold edges, borders."""
    rng = np.random.default_rng(seed)
    V, F = torus(rings=8, segments=6)
    n = len(V)
    label = np.arange(n)
    pairs = rng.choice(n, size=(4, 2), replace=False)
    label[pairs[:, 1]] = pairs[:, 0]
    F = solvable_faces(label[F])
    F = F[rng.random(len(F)) > 0.1]  # holes, so fans end at borders too
    first = np.unique(np.sort(F, axis=1), axis=0, return_index=True)[1]
    return F[np.sort(first)], n  # without duplicate faces, as the checks pass them


CASES = [(np.array([[0, 1, 2], [0, 3, 4]]), 5), double_cone(),
         (np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]]), 5),
         (tube_mesh(rings=3, segments=5).triangles()[0], 24)]


@pytest.mark.parametrize("F, n", CASES + [glued(s) for s in range(6)])
def test_fans_match_union_find_and_libigl(F, n):
    fans = fans_per_vertex(F, n)
    assert np.array_equal(fans, fans_by_hand(F, n))
    used = np.zeros(n, dtype=bool)
    used[F.ravel()] = True
    manifold = np.asarray(igl.is_vertex_manifold(F), dtype=bool).ravel()
    assert np.array_equal((fans == 1)[:manifold.size][used[:manifold.size]],
                          manifold[used[:manifold.size]])


def test_glued_tori_have_pinched_vertices():
    """The random cases exercise what they are for: vertices of two and more fans."""
    counts = np.concatenate([fans_per_vertex(*glued(s)) for s in range(6)])
    assert (counts >= 2).sum() >= 6 and (counts == 0).sum() >= 4


def test_double_cone_apex_is_reported():
    F, n = double_cone()
    assert fans_per_vertex(F, n)[0] == 2
    assert fans_per_vertex(np.zeros((0, 3), int), 2).tolist() == [0, 0]  # (libigl: bad_alloc)
    V = np.random.default_rng(0).normal(size=(n, 3))
    assert any("1 non-manifold vertices" in w for w in mesh_warnings(V, F))


@pytest.mark.parametrize("seed", range(4))
def test_one_way_adjacency_groups_handles_as_the_symmetric_one(seed):
    """Patches of random vertex subsets: an edge between two chosen vertices whose third face
    vertex is not chosen must still join them."""
    F, n = glued(seed)
    both = sp.csr_matrix((np.ones(2 * F.size), (np.r_[F.ravel(), F[:, [1, 2, 0]].ravel()],
                                                 np.r_[F[:, [1, 2, 0]].ravel(), F.ravel()])),
                         shape=(n, n))
    ids = np.sort(np.random.default_rng(seed).choice(n, size=n // 3, replace=False))
    assert np.array_equal(connected_groups(edge_adjacency(F, n), ids),
                          connected_groups(both, ids))


def test_geometry_span_counts_only_vertices_faces_use():
    F = np.array([[0, 1, 2]])
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1e200, 0, 0]])  # the last one unused
    assert geometry_problem(V, F) is None
    assert "too small or too large" in geometry_problem(V * 1e-120, F)


def test_solvable_faces_drop_repeated_vertices_and_share_the_faces_when_none_repeats():
    F = np.array([[0, 1, 2], [2, 2, 3], [1, 3, 2], [4, 5, 4], [5, 6, 6]])
    assert solvable_faces(F).tolist() == [[0, 1, 2], [1, 3, 2]]
    whole = F[[0, 2]]
    same = solvable_faces(whole)
    # the solve holds them as long as it runs: a copy would be a second array of the faces
    assert np.shares_memory(same, whole) and np.array_equal(same, whole)
    with pytest.raises(ValueError):
        same[0, 0] = 7  # and nothing downstream writes the caller's faces
    assert whole[0, 0] == 0
