"""Anderson acceleration, the harmonic start and coarse-to-fine, against the plain iteration
and rigid motions (math that does not depend on the accelerated code)."""
import numpy as np
import pytest
from helpers import diagonal, ends, tube, twist

from srarap_cli import Deformer
from srarap_cli.solver.drivers.anderson import ROUNDING
from srarap_cli.solver.multires import MultiresDeformer
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix


def bend(V, ids, length):
    T = V[ids].copy()
    top = T[:, 2] > length / 2
    R = to_matrix(from_axis_angle([0, 1, 0], 70))
    T[top] = (T[top] - [0, 0, length]) @ R.T + [0.4 * length, 0, 0.8 * length]
    return T


@pytest.fixture(scope="module")
def long_tube():
    V, F = tube(length=6.0, rings=24, segments=12)
    return V, F, ends(V, 6.0)


@pytest.mark.parametrize("method", ["sr-linear-sym", "sr-relax", "arap"])
def test_accepted_accelerated_iterates_never_raise_the_energy(long_tube, method):
    """Every row logged as ``anderson`` is at or below the row before it (fallback rows are
    plain steps: they can rise when the iterate lies below the fixed point's energy)."""
    V, F, ids = long_tube
    d = Deformer(V, F, ids, method=method, weights="cotan-clamped")
    r = d.solve(twist(V, ids, 6.0, 150), accel="anderson", tol=1e-8, max_iter=500)
    kinds = [row["step"] for row in r.log]
    assert kinds.count("anderson") >= 3 and r.converged
    slack = ROUNDING * d.edges.stretch_total(r.positions) * 10
    for before, row in zip(r.log, r.log[1:]):
        if row["step"] == "anderson":
            assert row["total"] <= before["total"] + slack, row


@pytest.mark.slow
@pytest.mark.parametrize("method", ["sr-linear-sym", "sr-linear", "arap"])
def test_accelerated_and_plain_iterations_reach_the_same_shape(method):
    """Both reach the plain map's fixed point: the plain iteration run 4000 steps without a
    stopping test (it has stopped moving), the accelerated one stopped by tol 1e-10, agree
    to 1e-6 of the diagonal. (Plain runs stopped by the same tol are further off: classic
    ARAP's crawl moves less than tol per step long before it arrives.)"""
    V, F = tube(length=6.0, rings=12, segments=8)
    ids = ends(V, 6.0)
    d = Deformer(V, F, ids, method=method)
    T = bend(V, ids, 6.0)
    plain = d.solve(T, accel="none", start="laplacian", tol=0, max_iter=4000)
    fast = d.solve(T, accel="anderson", tol=1e-10, max_iter=2000)
    assert fast.converged and fast.iterations < 200
    assert plain.log[-1]["max_move"] < 1e-12 * diagonal(V)
    assert np.abs(fast.positions - plain.positions).max() < 1e-6 * diagonal(V)
    assert np.array_equal(fast.positions[ids], T)


def test_harmonic_start_is_a_rigid_motion_of_all_handles_at_iteration_0(long_tube):
    V, F, ids = long_tube
    Rm = to_matrix(from_axis_angle([0.3, -1, 0.5], 130))
    t = np.array([1.0, 2.0, -3.0])
    d = Deformer(V, F, ids)  # two handle groups (the ends), found as connected patches
    assert np.unique(d.labels).size == 2
    r = d.solve(V[ids] @ Rm.T + t, max_iter=0)
    assert r.iterations == 0
    assert np.abs(r.positions - (V @ Rm.T + t)).max() < 1e-10 * diagonal(V)


def test_harmonic_start_is_far_closer_than_laplacian_editing_for_a_twist(long_tube):
    V, F, ids = long_tube
    d = Deformer(V, F, ids)
    T = twist(V, ids, 6.0, 120)
    best = d.solve(T, tol=1e-9, max_iter=2000).energy
    harmonic = d.solve(T, max_iter=0, start="harmonic").energy
    laplacian = d.solve(T, max_iter=0, start="laplacian").energy
    assert harmonic < 1.5 * best < laplacian


def test_collinear_and_single_vertex_groups_take_the_determined_groups_rotation():
    V, F = tube(length=6.0, rings=12, segments=8)
    ids = ends(V, 6.0)
    Rm = to_matrix(from_axis_angle([0, 0, 1], 60))
    labels = np.where(V[ids, 2] > 3, 0, 1)
    labels[0] = 2  # one bottom vertex alone: its rotation is not determined by itself
    d = Deformer(V, F, ids, labels=labels)
    r = d.solve(V[ids] @ Rm.T, max_iter=0)
    assert np.abs(r.positions - V @ Rm.T).max() < 1e-10 * diagonal(V)


def test_accelerated_solves_are_deterministic(long_tube):
    V, F, ids = long_tube
    d = Deformer(V, F, ids)
    T = twist(V, ids, 6.0, 100)
    a, b = d.solve(T), d.solve(T)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.rotors, b.rotors)
    assert [r["step"] for r in a.log] == [r["step"] for r in b.log]


def test_coarse_to_fine_reaches_the_direct_solve():
    """On a bar of ~2,000 vertices: the refined multires result has the direct solve's
    energy within the stopping tolerance's reach and its shape within 1e-3 of the diagonal;
    the transfer alone (the paper's approximation) is visibly worse."""
    V, F = tube(length=10.0, rings=60, segments=32)
    ids = ends(V, 10.0)
    T = twist(V, ids, 10.0, 120)
    direct = Deformer(V, F, ids).solve(T, tol=1e-9, max_iter=3000)
    refined = MultiresDeformer(V, F, ids, size=300).solve(T, tol=1e-6)
    approx = MultiresDeformer(V, F, ids, size=300, multires_mode="transfer").solve(T, tol=1e-6)
    assert refined.converged and not refined.approximate
    assert refined.energy <= direct.energy * (1 + 1e-4)
    assert np.abs(refined.positions - direct.positions).max() < 1e-3 * diagonal(V)
    assert approx.energy > refined.energy * (1 + 1e-3)
    assert {"coarse-start", "start"} <= {row["step"] for row in refined.log}


def test_cli_options_choose_the_driver_and_an_unconverged_run_says_what_to_try(tmp_path):
    import csv

    from click.testing import CliRunner
    from helpers import ROOT

    from srarap_cli.cli import main
    bar_obj = f"{ROOT}/sample_meshes/bar.obj"
    twist_yaml = f"{ROOT}/configs/bar-twist.yaml"
    log = tmp_path / "log.csv"
    r = CliRunner().invoke(main, ["deform", bar_obj, twist_yaml, "-o", str(tmp_path / "o.obj"),
                                  "--log", str(log), "--accel", "none", "--start", "laplacian",
                                  "--max-iter", "3"])
    assert r.exit_code == 3
    assert "try: raise --max-iter (was 3), use --accel anderson, --start harmonic" in r.stderr
    assert "relative change" in r.stderr and "per step over the last 3 > tol 1e-06" in r.stderr
    r = CliRunner().invoke(main, ["deform", bar_obj, twist_yaml, "-o", str(tmp_path / "o.obj"),
                                  "--max-iter", "0"])
    assert r.exit_code == 3 and "no iteration ran" in r.stderr and "nan" not in r.stderr
    with open(log) as fh:
        assert {row["step"] for row in csv.DictReader(fh)} == {"start", "plain"}
    r = CliRunner().invoke(main, ["deform", bar_obj, twist_yaml, "-o", str(tmp_path / "o.obj"),
                                  "--log", str(log)])
    assert r.exit_code == 0, r.output
    with open(log) as fh:
        assert "anderson" in {row["step"] for row in csv.DictReader(fh)}
