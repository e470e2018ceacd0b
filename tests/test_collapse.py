"""Half-edge collapses: a subset of the vertices, a valid surface, the same shape."""
import igl
import numpy as np
import pytest

from srarap_cli.solver.multires.collapse import PASSES, _Best, _independent, _Rings, collapse_to
from srarap_cli.solver.multires.simplify import _octahedron
from srarap_cli.solver.multires.topology import topology_summary


def grid(k):
    """A flat k x k vertex grid on the unit square, triangles facing +z."""
    x, y = np.meshgrid(np.linspace(0, 1, k), np.linspace(0, 1, k))
    V = np.column_stack([x.ravel(), y.ravel(), np.zeros(k * k)])
    i = np.arange(k - 1)
    a = (i[:, None] * k + i[None, :]).ravel()
    F = np.vstack([np.column_stack([a, a + 1, a + k + 1]), np.column_stack([a, a + k + 1, a + k])])
    return V, F


def normals(V, F):
    return np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])


def test_a_flat_square_keeps_its_outline_orientation_and_area():
    V, F = grid(15)
    G = collapse_to(V, F, 40, np.zeros(len(V), bool))
    kept = np.unique(G)
    assert len(kept) <= 40
    n = normals(V, G)
    assert np.all(n[:, 2] > 0) and np.allclose(n[:, :2], 0)  # nothing flipped or tilted
    # borders slide only along themselves: the four corners stay and the area is exact
    corners = [0, 14, 210, 224]
    assert np.isin(corners, kept).all()
    assert np.isclose(0.5 * n[:, 2].sum(), 1.0, rtol=1e-12)
    before, after = topology_summary(F, len(V)), topology_summary(G, len(V))
    assert before == after


def test_frozen_vertices_survive_and_the_rest_is_a_subset():
    V, F = igl.loop(*igl.loop(*_octahedron()))
    frozen = np.zeros(len(V), bool)
    frozen[[7, 30, 55]] = True
    G = collapse_to(V, F, 12, frozen)
    kept = np.unique(G)
    assert np.isin([7, 30, 55], kept).all() and len(kept) <= 12
    assert G.min() >= 0 and G.max() < len(V)
    assert topology_summary(G, len(V))["euler"] == 2


def test_asking_for_too_little_stops_at_a_valid_closed_surface():
    V, F = igl.loop(*_octahedron())
    G = collapse_to(V, F, 1, np.zeros(len(V), bool))
    summary = topology_summary(G, len(V))
    assert summary["euler"] == 2 and summary["edge_manifold"] and summary["components"] == 1
    assert 4 <= len(np.unique(G)) < len(V)
    assert np.all(np.einsum("ij,ij->i", normals(V, G), V[G].mean(axis=1)) > 0)


@pytest.mark.parametrize("seed", [0, 1])
def test_every_coarse_triangle_faces_the_way_the_surface_does(seed):
    V, F = igl.loop(*igl.loop(*igl.loop(*_octahedron())))
    rng = np.random.default_rng(seed)
    V = V / np.linalg.norm(V, axis=1)[:, None] * (1 + 0.05 * rng.random((len(V), 1)))
    G = collapse_to(V, F, 40, np.zeros(len(V), bool))
    centroid = V[G].mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", normals(V, G), centroid) > 0)  # outward, like F
    assert topology_summary(G, len(V)) == topology_summary(F, len(V))


def soup(V, F):
    """Every face with vertices of its own (what a loader that splits at seams gives)."""
    return V[F.ravel()], np.arange(F.size).reshape(-1, 3)


def test_no_part_of_the_surface_vanishes_whole():
    """A lone triangle passes the link condition, but collapsing one of its edges would delete
    it and leave its other vertices in no face: such parts stay, and the rest simplifies."""
    V, F = grid(12)
    lone = np.array([[5.0, 0, 0], [6, 0, 0], [5, 1, 0]])
    V2 = np.vstack([V, lone])
    F2 = np.vstack([F, len(V) + np.array([[0, 1, 2]])])
    G = collapse_to(V2, F2, 30, np.zeros(len(V2), bool))
    assert [len(V), len(V) + 1, len(V) + 2] in G.tolist()
    assert np.unique(G[G.max(axis=1) < len(V)]).size <= 30
    Vs, Fs = soup(V, F)
    assert np.array_equal(collapse_to(Vs, Fs, 30, np.zeros(len(Vs), bool)), Fs)


def _rings_of(F, n):
    ring = [{i} for i in range(n)]
    for a, b, c in F:
        for x, y in ((a, b), (b, c), (c, a)):
            ring[x].add(y)
            ring[y].add(x)
    return ring


def _independent_by_pairs(ring, u, v):
    """The passes of ``_independent`` written out pair by pair (proposals in rank order)."""
    def interfere(i, j):
        return bool({u[j], v[j]} & ring[u[i]] or {u[i], v[i]} & ring[u[j]])

    won = []
    for _ in range(PASSES):
        open_ = [i for i in range(len(u))
                 if i not in won and not any(interfere(i, w) for w in won)]
        new = [i for i in open_ if not any(interfere(i, j) for j in open_ if j < i)]
        if not open_:
            break
        won += new
    return sorted(won)


@pytest.mark.parametrize("seed", range(6))
def test_independent_collapses_match_the_pairwise_rule_and_share_no_ring(seed):
    rng = np.random.default_rng(seed)
    V, F = grid(9)
    n = len(V)
    ring = _rings_of(F, n)
    u = rng.permutation(n)[:40]
    v = np.array([rng.choice(sorted(ring[x] - {x})) for x in u])
    edges = np.unique(np.sort(np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1),
                      axis=0)
    won = _independent(_Rings(edges, F, n), u, v, n)
    assert won.tolist() == _independent_by_pairs(ring, u, v)
    for a in won:
        for b in won:
            assert a == b or not ({u[b], v[b]} & ring[u[a]])


@pytest.mark.parametrize("case", ["sphere", "square", "tube"])
def test_proposals_kept_between_rounds_give_what_pricing_every_vertex_gives(case, monkeypatch):
    """Only vertices near a collapse are priced again each round; pricing all of them every
    round (the slow way) must give the same triangles, frozen vertices, borders and the
    retry of banned proposals included."""
    rng = np.random.default_rng(3)
    if case == "sphere":
        V, F = igl.loop(*igl.loop(*igl.loop(*_octahedron())))
        V = V * (1 + 0.05 * rng.random((len(V), 1)))
    elif case == "square":
        V, F = grid(14)
        V[:, 2] = 0.1 * rng.random(len(V))
    else:  # an open tube: two border loops
        t, z = np.meshgrid(2 * np.pi * np.arange(12) / 12, np.linspace(0, 4, 21))
        V = np.column_stack([np.cos(t.ravel()), np.sin(t.ravel()), z.ravel()])
        a = (np.arange(20)[:, None] * 12 + np.arange(12)[None, :]).ravel()
        b = a - a % 12 + (a + 1) % 12
        F = np.vstack([np.column_stack([a, b, b + 12]), np.column_stack([a, b + 12, a + 12])])
    frozen = np.zeros(len(V), bool)
    frozen[::17] = True
    sizes = (40, 3)
    fast = [collapse_to(V, F, size, frozen) for size in sizes]
    monkeypatch.setattr(_Best, "changed", lambda self, *args: self.dirty.fill(True))
    slow = [collapse_to(V, F, size, frozen) for size in sizes]
    for a, b in zip(fast, slow):
        assert np.array_equal(a, b)
