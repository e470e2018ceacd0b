"""energy_hessian: half the SR-ARAP energy's Hessian, against finite differences of the energy
and the invariances it must have."""
import numpy as np
import pytest
from helpers import bent_tube

from srarap_cli.solver.hessian import energy_hessian, rotor_gradient
from srarap_cli.solver.quaternion import IDENTITY, from_rotation_vectors, multiply


@pytest.fixture(scope="module")
def state():
    """A bent tube's solve, then every position and rotor perturbed (so the residual terms of
    the Hessian, which vanish on an exact fit, are exercised)."""
    d, _, r = bent_tube()
    V = d.V
    rng = np.random.default_rng(3)
    P = r.positions + 0.05 * rng.standard_normal(V.shape)
    R = multiply(from_rotation_vectors(0.2 * rng.standard_normal((len(V), 3))), r.rotors)
    return d, P, R, rng


def quadratic(d, H, u, w):
    """``x^T H x`` for x = (u, w) from the blocks (H = 2 Q; Q_uu = 2 K per coordinate)."""
    Ku = d.graph.laplacian @ u
    return 2.0 * (2.0 * np.sum(u * Ku) + 2.0 * np.sum(w * H.coupling(u))
                  + np.sum(w * H.rotations(w)))


@pytest.mark.parametrize("part", ["positions", "rotors", "both"])
def test_second_derivatives_match_finite_differences_of_the_energy(state, part):
    d, P, R, rng = state
    H = energy_hessian(d.graph, d.edges, P, R, d.bending_weight)
    n = len(P)
    for _ in range(3):
        u = rng.standard_normal((n, 3)) * (part != "rotors")
        w = rng.standard_normal((n, 3)) * (part != "positions")

        def energy(t, u=u, w=w):
            return d.energy(P + t * u, multiply(from_rotation_vectors(t * w), R))["total"]

        h = 1e-4
        second = (energy(h) - 2 * energy(0.0) + energy(-h)) / h ** 2
        assert quadratic(d, H, u, w) == pytest.approx(second, rel=1e-5)


def test_the_bending_part_matches_finite_differences_of_the_bending_energy(state):
    """A bending weight of 0 (classic ARAP) leaves the membrane alone: the difference is the
    bending term's curvature."""
    d, P, R, rng = state
    membrane = energy_hessian(d.graph, d.edges, P, R, 0.0)
    full = energy_hessian(d.graph, d.edges, P, R, d.bending_weight)
    w = rng.standard_normal((len(P), 3))
    bending = full.rotations(w) - membrane.rotations(w)
    h = 1e-4
    values = [d.bending(multiply(from_rotation_vectors(t * w), R)) for t in (-h, 0.0, h)]
    second = (values[0] - 2 * values[1] + values[2]) / h ** 2
    assert 2.0 * np.sum(w * bending) == pytest.approx(second, rel=1e-5)


def test_products_are_symmetric(state):
    d, P, R, rng = state
    H = energy_hessian(d.graph, d.edges, P, R, d.bending_weight)
    a, b = rng.standard_normal((2, len(P), 3))
    assert np.sum(a * H.rotations(b)) == pytest.approx(np.sum(b * H.rotations(a)), rel=1e-12)
    assert np.sum(a * H.coupling(b)) == pytest.approx(np.sum(b * H.coupling_t(a)), rel=1e-12)


def test_rigid_motions_of_the_rest_shape_cost_nothing(state):
    """At rest (E = 0, a minimum), turning and moving everything together is a null
    direction: u = omega x V + t, w = omega."""
    d, _, _, rng = state
    V = d.V
    H = energy_hessian(d.graph, d.edges, V, np.tile(IDENTITY, (len(V), 1)), d.bending_weight)
    omega, shift = rng.standard_normal(3), rng.standard_normal(3)
    u = np.cross(omega, V) + shift
    w = np.tile(omega, (len(V), 1))
    scale = np.abs(H.rotations(w)).max()
    on_rotors = H.rotations(w) + H.coupling(u)
    on_positions = H.coupling_t(w) + 2.0 * (d.graph.laplacian @ u)
    assert np.abs(on_rotors).max() < 1e-12 * scale
    assert np.abs(on_positions).max() < 1e-12 * scale


def test_edge_blocks_give_the_same_products(state, monkeypatch):
    """Large meshes build and apply the Hessian a block of edges at a time."""
    from srarap_cli.runtime import parallel

    d, P, R, rng = state
    whole = energy_hessian(d.graph, d.edges, P, R, d.bending_weight)
    monkeypatch.setitem(parallel.PLANS, "edges", parallel.Plan(47, even=False))
    assert len(d.graph.edge_blocks()) > 5
    blocked = energy_hessian(d.graph, d.edges, P, R, d.bending_weight)
    u, w = rng.standard_normal((2, len(P), 3))
    for name, x in (("rotations", w), ("coupling", u), ("coupling_t", w)):
        a, b = getattr(whole, name)(x), getattr(blocked, name)(x)
        assert np.allclose(a, b, rtol=0, atol=1e-12 * np.abs(a).max()), name


def test_the_rotor_gradient_matches_finite_differences_of_the_energy(state):
    """Half the energy's slope along any turn of the rotors (membrane and bending)."""
    d, P, R, rng = state
    g = rotor_gradient(d.graph, d.edges, P, R, d.bending_weight)
    for _ in range(3):
        w = rng.standard_normal((len(P), 3))

        def energy(t, w=w):
            return d.energy(P, multiply(from_rotation_vectors(t * w), R))["total"]

        h = 1e-5
        slope = (energy(h) - energy(-h)) / (2 * h)
        assert 2.0 * np.sum(w * g) == pytest.approx(slope, rel=1e-7)


def test_the_rotor_gradient_vanishes_at_rest_and_is_blind_to_a_rotor_sign(state):
    d, P, R, rng = state
    V = d.V
    rest = rotor_gradient(d.graph, d.edges, V, np.tile(IDENTITY, (len(V), 1)), d.bending_weight)
    assert np.abs(rest).max() < 1e-13
    flipped = R.copy()
    flipped[::3] *= -1
    assert np.allclose(rotor_gradient(d.graph, d.edges, P, flipped, d.bending_weight),
                       rotor_gradient(d.graph, d.edges, P, R, d.bending_weight), atol=1e-13)


def test_the_blocks_are_the_products(state):
    """The 3x3 blocks, put in a sparse matrix by hand, multiply as the products do."""
    import scipy.sparse as sp

    d, P, R, rng = state
    H = energy_hessian(d.graph, d.edges, P, R, d.bending_weight)
    g, n = d.graph, len(P)
    key = g.I * n + g.J
    reverse = np.array([int(np.flatnonzero(key == j * n + i)[0]) for i, j in zip(g.I, g.J)])
    ww_diagonal, ww_edges, wu_diagonal, wu_edges = H.blocks(reverse)

    def assemble(diagonal, edges):
        M = np.zeros((3 * n, 3 * n))
        for i in range(n):
            M[3 * i:3 * i + 3, 3 * i:3 * i + 3] += diagonal[i]
        for e, (i, j) in enumerate(zip(g.I, g.J)):
            M[3 * i:3 * i + 3, 3 * j:3 * j + 3] += edges[e]
        return sp.csr_matrix(M)

    u, w = rng.standard_normal((2, n, 3))
    ww, wu = assemble(ww_diagonal, ww_edges), assemble(wu_diagonal, wu_edges)
    assert np.allclose(ww @ w.ravel(), H.rotations(w).ravel(), atol=1e-12)
    assert np.allclose(wu @ u.ravel(), H.coupling(u).ravel(), atol=1e-12)
    assert np.allclose(wu.T @ w.ravel(), H.coupling_t(w).ravel(), atol=1e-12)
