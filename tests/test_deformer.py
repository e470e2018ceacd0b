"""The solver against math derived independently of it."""
import igl
import numpy as np
import pytest
import scipy.sparse as sp
from helpers import ends, random_rotation, symmetric_tube, tube
from scipy.spatial.transform import Rotation

from srarap_cli import Deformer, deform
from srarap_cli.solver.drivers.monitor import WINDOW
from srarap_cli.solver.quaternion import IDENTITY, from_axis_angle, multiply, to_matrix

ALPHA = 0.14


def bend_targets(V, ids, angle=60.0):
    """Top end turned about y around its centre and moved; bottom end fixed."""
    T = V[ids].copy()
    top = T[:, 2] > 1
    R = to_matrix(from_axis_angle([0, 1, 0], angle))
    T[top] = (T[top] - [0, 0, 6]) @ R.T + [2.0, 0, 5.0]
    return T


def independent_energy(V, F, P, R, alpha, clamp=True):
    """SR-ARAP energy from the README's formula, with igl.cotmatrix and scipy rotations."""
    L = sp.coo_matrix(igl.cotmatrix(V, F))
    off = L.row != L.col
    rows, cols, w = L.row[off], L.col[off], L.data[off]
    w = np.maximum(w, 0) if clamp else w
    deg = np.bincount(rows, minlength=len(V))
    rot = Rotation.from_quat(R[:, [1, 2, 3, 0]])
    membrane = bending = 0.0
    area = igl.doublearea(V, F).sum() / 2
    for i, j, c in zip(rows, cols, w):
        r = rot[i].apply(V[j] - V[i]) - (P[j] - P[i])
        membrane += c * r @ r
        d = min(np.sum((R[i] - R[j]) ** 2), np.sum((R[i] + R[j]) ** 2))
        bending += alpha * area * d / deg[i]
    return membrane, bending


@pytest.fixture(scope="module")
def bar():
    V, F = tube()
    return V, F, ends(V)


def test_rigid_motion_of_all_handles_is_reproduced_exactly(bar):
    V, F, ids = bar
    Rm = to_matrix(from_axis_angle([1, 1, 0.3], 170))
    t = np.array([2.0, -1.0, 3.0])
    # exact from the first iteration; its bending energy stays at the rotors' rounding (about
    # 1e-14, above what tol 1e-12 takes for exact): it stops when nothing moves any more
    r = deform(V, F, ids, V[ids] @ Rm.T + t, max_iter=50, tol=1e-12)
    assert r.converged and r.iterations <= WINDOW + 1
    assert np.abs(r.positions - (V @ Rm.T + t)).max() < 1e-8
    scale = np.sum((V[F[:, 1]] - V[F[:, 0]]) ** 2)
    assert r.log[-1]["membrane"] < 1e-12 * scale
    assert r.log[-1]["bending"] < 1e-10 * scale
    # every cell rotor is the motion's rotation (up to the sign of the quaternion)
    q = Rotation.from_matrix(Rm).as_quat()[[3, 0, 1, 2]]
    assert np.abs(np.abs(r.rotors @ q) - 1).max() < 1e-8


def test_identity_targets_give_back_the_rest_shape(bar):
    V, F, ids = bar
    r = deform(V, F, ids, V[ids])
    assert r.converged and r.iterations <= 1
    assert np.abs(r.positions - V).max() < 1e-12
    assert np.abs(np.abs(r.rotors[:, 0]) - 1).max() < 1e-12


def test_constrained_vertices_land_exactly_on_their_targets(bar):
    V, F, ids = bar
    T = bend_targets(V, ids)
    r = deform(V, F, ids, T, max_iter=20)
    assert np.array_equal(r.positions[ids], T)


def test_reported_energy_equals_independent_evaluation(bar):
    V, F, ids = bar
    r = deform(V, F, ids, bend_targets(V, ids), max_iter=30, start="laplacian")
    membrane, bending = independent_energy(V, F, r.positions, r.rotors, ALPHA)
    assert np.isclose(r.log[-1]["membrane"], membrane, rtol=1e-10)
    assert np.isclose(r.log[-1]["bending"], bending, rtol=1e-10)
    assert r.log[-1]["total"] < 0.5 * r.log[0]["total"]  # well below Laplacian editing


def test_mirror_symmetric_input_gives_mirror_symmetric_result(bar):
    """A mesh symmetric under x -> -x, bent in the y-z plane, must stay symmetric."""
    V, F = symmetric_tube()
    ids = ends(V)
    mirrored = V * [-1, 1, 1]
    perm = np.array([np.flatnonzero(np.all(np.isclose(V, m), axis=1))[0] for m in mirrored])
    assert sorted(perm) == list(range(len(V)))
    assert {tuple(sorted(f)) for f in perm[F]} == {tuple(sorted(f)) for f in F}
    T = V[ids].copy()
    top = T[:, 2] > 1
    T[top] = (T[top] - [0, 0, 6]) @ to_matrix(from_axis_angle([1, 0, 0], 50)).T + [0, 2.0, 5]
    r = deform(V, F, ids, T, max_iter=300, tol=1e-9)
    P = r.positions
    assert np.abs(P[perm] - P * [-1, 1, 1]).max() < 1e-8


# 1e-20 and 1e20 put the rotor preconditioner's entries (areas) outside single precision
@pytest.mark.parametrize("scale", [1e-3, 1e-20, 1e20])
def test_scaling_the_problem_scales_the_result(bar, scale):
    V, F, ids = bar
    T = bend_targets(V, ids)
    a = deform(V, F, ids, T, max_iter=40, tol=0)
    b = deform(scale * V, F, ids, scale * T, max_iter=40, tol=0)
    assert np.abs(b.positions - scale * a.positions).max() < 1e-9 * scale
    assert np.isclose(b.energy, scale ** 2 * a.energy, rtol=1e-6)


def pure(v):
    return np.concatenate([np.zeros((len(v), 1)), v], axis=1)


def papers_rotor_step(d, P, R_prev, held, eps=0.2):
    """The paper's (non-symmetric) rotor system, built densely from its formula: the rotors
    of ``held`` vertices from their own rows with the neighbours' previous rotors (section
    6.2), then one solve for all others with those as known values; all normalized."""
    g, V, n, aA = d.graph, d.V, len(d.V), ALPHA * d.area
    M = np.zeros((n, 4, 4))
    for i, j, c in zip(g.I, g.J, g.c):  # M_i = sum c (Rmul(q) - Lmul(p))^T (...)
        q, p = pure((V[j] - V[i])[None]), pure((P[j] - P[i])[None])
        A = np.stack([multiply(e[None], q)[0] - multiply(p, e[None])[0] for e in np.eye(4)], 1)
        M[i] += c * A.T @ A
    expected = R_prev.copy()
    for i in np.flatnonzero(held):
        w = aA / (g.degree[i] + eps)
        rhs = w * (R_prev[g.J[g.I == i]].sum(0) + eps * R_prev[i])
        x = np.linalg.solve(M[i] + aA * np.eye(4), rhs)
        expected[i] = x / np.linalg.norm(x)
    free = np.flatnonzero(~held)
    pos = {v: k for k, v in enumerate(free)}
    A = np.zeros((4 * free.size, 4 * free.size))
    b = np.zeros(4 * free.size)
    for k, i in enumerate(free):
        w = aA / (g.degree[i] + eps)
        A[4 * k:4 * k + 4, 4 * k:4 * k + 4] = M[i] + aA * np.eye(4)
        b[4 * k:4 * k + 4] = w * eps * R_prev[i]
        for j in g.J[g.I == i]:
            if held[j]:
                b[4 * k:4 * k + 4] += w * expected[j]
            else:
                A[4 * k:4 * k + 4, 4 * pos[j]:4 * pos[j] + 4] -= w * np.eye(4)
    x = np.linalg.solve(A, b).reshape(-1, 4)
    expected[free] = x / np.linalg.norm(x, axis=1, keepdims=True)
    return expected


def perturbed(V, rng):
    R_prev = np.array([random_rotation(rng) * 0.1 + IDENTITY for _ in V])
    return V + 0.2 * rng.normal(size=V.shape), R_prev / np.linalg.norm(R_prev, axis=1,
                                                                         keepdims=True)


def test_local_step_solves_the_papers_system(bar):
    V, F, ids = bar
    d = Deformer(V, F, ids, alpha=ALPHA, feedback=0.2, method="sr-linear",
                 handle_rotors="lagged")
    P, R_prev = perturbed(V, np.random.default_rng(7))
    got = d.local_step.step(*d.edges.covariance(P), R_prev)
    held = np.zeros(len(V), bool)
    held[ids] = True
    assert np.abs(got - papers_rotor_step(d, P, R_prev, held)).max() < 1e-7


def test_only_handle_boundary_rotors_come_from_their_own_rows():
    """Default rule: a constrained vertex with a free neighbour takes its rotor from its own
    row; one whose neighbours are all constrained joins the sparse solve."""
    V, F = tube()
    ids = np.flatnonzero((V[:, 2] < 1.2) | (V[:, 2] > 4.8))  # three rings at each end
    d = Deformer(V, F, ids, alpha=ALPHA, feedback=0.2, method="sr-linear")
    constrained = np.zeros(len(V), bool)
    constrained[ids] = True
    g = d.graph
    held = constrained.copy()
    held[ids] = [(~constrained[g.J[g.I == i]]).any() for i in ids]
    assert 0 < held.sum() < constrained.sum()  # the middle rings are interior
    P, R_prev = perturbed(V, np.random.default_rng(9))
    got = d.local_step.step(*d.edges.covariance(P), R_prev)
    assert np.abs(got - papers_rotor_step(d, P, R_prev, held)).max() < 1e-7
    lagged = papers_rotor_step(d, P, R_prev, constrained)
    assert np.abs(got - lagged).max() > 1e-3  # the two rules differ after one step


def test_both_rotor_rules_converge_to_nearby_shapes():
    """The rules differ only in which rotors enter their neighbours' rows normalized: the
    tightly converged shapes of a bent tube with three-ring handles agree to 1e-5 of the
    diagonal (measured 1.4e-6), and the default rule needs fewer plain iterations (59 against
    80)."""
    V, F = tube()
    ids = np.flatnonzero((V[:, 2] < 1.2) | (V[:, 2] > 4.8))
    T = bend_targets(V, ids)
    runs = {rule: Deformer(V, F, ids, handle_rotors=rule).solve(
        T, tol=1e-12, max_iter=3000, accel="none", start="laplacian")
        for rule in ("boundary", "lagged")}
    assert all(r.converged for r in runs.values())
    diag = np.linalg.norm(np.ptp(V, axis=0))
    shift = np.abs(runs["boundary"].positions - runs["lagged"].positions).max() / diag
    assert shift < 1e-5
    assert runs["boundary"].iterations < runs["lagged"].iterations


def test_an_unknown_handle_rotor_rule_is_refused(bar):
    V, F, ids = bar
    with pytest.raises(ValueError, match="handle_rotors must be one of boundary, lagged"):
        Deformer(V, F, ids, handle_rotors="joint")


def test_warm_start_from_a_converged_result_stays_put(bar):
    V, F, ids = bar
    d = Deformer(V, F, ids)
    T = bend_targets(V, ids)
    first = d.solve(T, max_iter=500, tol=1e-9)
    again = d.solve(T, initial=(first.positions, first.rotors), max_iter=5, tol=1e-6)
    assert again.converged and again.iterations == 3  # the stopping test's full window
    assert np.abs(again.positions - first.positions).max() < 1e-5


def test_part_without_constraints_and_unreferenced_vertex_stay_at_rest(bar):
    V, F, ids = bar
    V2 = np.vstack([V, V + [5, 0, 0], [[9.0, 9, 9]]])
    F2 = np.vstack([F, F + len(V)])
    d = Deformer(V2, F2, ids)
    r = d.solve(bend_targets(V, ids), max_iter=10)
    assert np.array_equal(r.positions[len(V):], V2[len(V):])
    assert len(d.warnings) == 2 and d.auto_fixed.size == len(V) + 1


def test_bad_parameters_are_rejected(bar):
    V, F, ids = bar
    with pytest.raises(ValueError, match="alpha"):
        Deformer(V, F, ids, alpha=0)
    with pytest.raises(ValueError, match="weights"):
        Deformer(V, F, ids, weights="mean-value")


@pytest.mark.parametrize("initial, message", [
    ("P", r"initial must be a pair \(positions, rotors\)"),
    (("P3", "R"), r"initial positions must be a \(\d+, 3\) array.*got shape \(3, 3\)"),
    (("P", "R3"), r"initial rotors must be a \(\d+, 4\) array.*got shape \(\d+, 3\)"),
    (("Pnan", "R"), "initial positions has NaN"),
    (("P", "text"), "initial rotors must be an array of numbers"),
])
def test_a_malformed_warm_start_is_named(bar, initial, message):
    V, F, ids = bar
    d = Deformer(V, F, ids)
    R = np.tile(IDENTITY, (len(V), 1))
    values = {"P": V, "P3": V[:3], "Pnan": np.where(V > 0.5, np.nan, V), "R": R,
              "R3": R[:, :3], "text": "rotors"}
    state = values[initial] if isinstance(initial, str) else tuple(values[k] for k in initial)
    with pytest.raises(ValueError, match=message):
        d.solve(V[ids], initial=state)


@pytest.mark.slow
@pytest.mark.parametrize("weights", ["cotan", "uniform"])
def test_other_weight_kinds_reach_rigid_motion(bar, weights):
    V, F, ids = bar
    Rm = to_matrix(from_axis_angle([0, 1, 0], 90))
    r = deform(V, F, ids, V[ids] @ Rm.T, weights=weights, max_iter=3000, tol=1e-12)
    assert np.abs(r.positions - V @ Rm.T).max() < 1e-7


def test_negative_cotangent_weights_are_warned_about():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, 0.1, 0], [0.5, -0.1, 0]])
    F = np.array([[0, 1, 2], [1, 0, 3]])  # both angles opposite edge 0-1 are obtuse
    assert any("negative cotangent" in w for w in Deformer(V, F, [0], weights="cotan").warnings)
    assert not Deformer(V, F, [0]).warnings
