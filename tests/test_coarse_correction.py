"""The coarse-grid correction of full-resolution iterates (full approximation scheme):
it vanishes at the full mesh's fixed point, so it cannot move the answer, and it shortens
the way there."""
import numpy as np
import pytest
from helpers import diagonal, ends, tube, twist

from srarap_cli import Deformer
from srarap_cli.solver.drivers.anderson import ROUNDING
from srarap_cli.solver.multires import MultiresDeformer
from srarap_cli.solver.multires.correction import CoarseCorrection
from srarap_cli.solver.quaternion import align_hemisphere


@pytest.fixture(scope="module")
def twisted_bar():
    """A bar of ~2,000 vertices twisted 200 degrees, a 150-vertex coarse mesh."""
    V, F = tube(length=10.0, rings=60, segments=32)
    ids = ends(V, 10.0)
    T = twist(V, ids, 10.0, 200)
    return V, F, ids, T, MultiresDeformer(V, F, ids, size=150)


def fine_rows(result):
    return [row for row in result.log if not row["step"].startswith("coarse-")]


def residual(step, P, R):
    """The rotors the local step gives (P, R), minus R (as the driver forms it)."""
    return align_hemisphere(step.local(step.state(P, R, energy=False)), R) - R


def test_the_correction_vanishes_at_the_fixed_point_and_not_before(twisted_bar):
    V, F, ids, T, md = twisted_bar
    step = md.fine.step_for(T, 1e-12)
    correction = md.coarse_correction(T, 1e-12)
    tight = md.fine.solve(T, tol=1e-12, max_iter=3000)
    assert tight.converged
    early = md.fine.solve(T, tol=1e-12, max_iter=2)
    for result, small in ((tight, True), (early, False)):
        r = residual(step, result.positions, result.rotors)
        delta = correction(step.state(result.positions, result.rotors, energy=False), r)
        assert delta.shape == r.shape and np.isfinite(delta).all()
        if small:
            assert np.abs(r).max() < 1e-6
            assert np.abs(delta).max() < 1e-6
        else:
            assert np.abs(delta).max() > 1e-3


def test_corrected_iterations_reach_the_direct_answer_sooner(twisted_bar, monkeypatch):
    V, F, ids, T, md = twisted_bar
    direct = Deformer(V, F, ids).solve(T, tol=1e-10, max_iter=3000)
    corrected = md.solve(T, tol=1e-6)
    monkeypatch.setattr(CoarseCorrection, "due", lambda self, iteration: False)
    uncorrected = md.solve(T, tol=1e-6)
    fine = fine_rows(corrected)
    assert corrected.converged and uncorrected.converged
    assert "corrected" in {row["step"] for row in fine}
    assert "corrected" not in {row["step"] for row in uncorrected.log}
    assert corrected.energy <= direct.energy * (1 + 1e-5)
    assert np.abs(corrected.positions - direct.positions).max() < 1e-3 * diagonal(V)
    # measured: 12 full-resolution iterations against 17
    assert len(fine) < len(fine_rows(uncorrected))
    slack = ROUNDING * md.fine.edges.stretch_total(corrected.positions) * 10
    for before, row in zip(fine, fine[1:]):
        if row["step"] in ("anderson", "corrected"):
            assert row["total"] <= before["total"] + slack, row


def test_corrected_solves_are_deterministic(twisted_bar):
    V, F, ids, T, md = twisted_bar
    a, b = md.solve(T), md.solve(T)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.rotors, b.rotors)


def test_the_plain_iteration_is_never_corrected(twisted_bar):
    V, F, ids, T, md = twisted_bar
    plain = md.solve(T, accel="none", max_iter=20)
    assert {row["step"] for row in plain.log} <= {"coarse-start", "coarse-plain", "start",
                                                   "plain"}


def test_a_coarse_mesh_above_the_threshold_is_solved_through_a_coarser_one(monkeypatch):
    """Three levels (thresholds lowered so that a test-sized mesh needs them): the middle
    level is itself coarse-to-fine and corrected, and the answer is still the direct one."""
    from srarap_cli.solver.multires import size

    monkeypatch.setattr(size, "AUTO_THRESHOLD", 400)
    monkeypatch.setattr(size, "AUTO_SIZE", 100)
    V, F = tube(length=10.0, rings=60, segments=32)
    ids = ends(V, 10.0)
    T = twist(V, ids, 10.0, 200)
    md = MultiresDeformer(V, F, ids, size=500)
    assert isinstance(md.coarse_deformer, MultiresDeformer)
    assert md.coarse_deformer.coarse.vertices.size <= 110
    assert md.coarse_correction(T).inner is not None
    nested = md.solve(T, tol=1e-6)
    direct = Deformer(V, F, ids).solve(T, tol=1e-10, max_iter=3000)
    steps = {row["step"] for row in nested.log}
    assert {"coarse-coarse-start", "coarse-corrected", "corrected"} <= steps
    assert nested.converged and nested.energy <= direct.energy * (1 + 1e-5)
    assert np.abs(nested.positions - direct.positions).max() < 1e-3 * diagonal(V)
    transfer = MultiresDeformer(V, F, ids, size=500, multires_mode="transfer")
    assert not isinstance(transfer.coarse_deformer, MultiresDeformer)
