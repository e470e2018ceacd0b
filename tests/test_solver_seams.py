"""The solver's seams: drivers and starts added from outside the package, one settings
definition behind the handle file, the CLI and the Python API."""
import json
import os

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import ROOT, ends, tube

from srarap_cli import Deformer, deform
from srarap_cli.cli import main
from srarap_cli.io.handles import load_handles
from srarap_cli.runtime.errors import InputError
from srarap_cli.solver.drivers import DRIVERS, register
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix
from srarap_cli.solver.settings import SETTINGS, parse_mapping
from srarap_cli.solver.starts import STARTS
from srarap_cli.solver.starts import register as register_start
from srarap_cli.solver.stop import StopReason


@pytest.fixture(scope="module")
def bent():
    V, F = tube()
    ids = ends(V)
    T = V[ids].copy()
    top = T[:, 2] > 1
    T[top] = (T[top] - [0, 0, 6]) @ to_matrix(from_axis_angle([0, 1, 0], 50)).T + [1.5, 0, 5.5]
    return V, F, ids, T


def at_most_three(step, state, monitor):
    """Plain iteration, but never more than three steps."""
    stop = monitor.record(state)
    for _ in range(3):
        if stop:
            break
        new = step(state)
        stop = monitor.record(new, state)
        state = new
    return state


def test_a_driver_registered_from_a_test_file_runs_through_the_public_api(bent):
    V, F, ids, T = bent
    register("test-at-most-three", at_most_three)
    try:
        d = Deformer(V, F, ids)
        capped = d.solve(T, driver="test-at-most-three", max_iter=50, tol=0)
        plain = d.solve(T, accel="none", max_iter=3, tol=0)
    finally:
        DRIVERS.pop("test-at-most-three")
    assert capped.iterations == 3 and len(capped.log) == 4 and not capped.converged
    assert capped.stop_reason is StopReason.DRIVER and not capped.complete
    # the same three steps as the plain driver capped by max_iter: identical iterates
    assert np.array_equal(capped.positions, plain.positions)
    assert [r["total"] for r in capped.log] == [r["total"] for r in plain.log]


def test_a_start_registered_from_a_test_file_is_used(bent):
    V, F, ids, T = bent
    d = Deformer(V, F, ids)
    solved = d.solve(T, max_iter=400, tol=1e-10, accel="none")

    def from_answer(step, initial):
        return step.state(solved.positions.copy(), solved.rotors.copy())

    register_start("test-answer", from_answer)
    try:
        again = d.solve(T, start="test-answer", accel="none", max_iter=5, tol=1e-8)
    finally:
        STARTS.pop("test-answer")
    assert again.log[0]["total"] == pytest.approx(solved.log[-1]["total"], rel=1e-12)
    assert again.converged and again.iterations <= 3  # one full window of the stopping test


@pytest.mark.parametrize("accel", ["anderson", "none"])
def test_the_drivers_let_go_of_the_start_the_solver_handed_over(bent, accel):
    """The start a solve builds would otherwise live as long as the solve (its caller and
    the call both hold it): the built-in drivers drop its arrays once past it, and a
    registered start's own state is left whole (the driver gets a copy)."""
    V, F, ids, T = bent
    d = Deformer(V, F, ids)
    kept, seen = [], []

    def keeping(step, initial):
        kept.append(STARTS["laplacian"](step, None))
        return kept[-1]

    def watching(step, state, monitor):
        seen.append(state)
        seen.append(DRIVERS[{"anderson": "anderson", "none": "plain"}[accel]](step, state, monitor))
        return seen[-1]

    register_start("test-keeping", keeping)
    try:
        watched = d.solve(T, start="test-keeping", driver=watching, max_iter=6, tol=0)
        plain = d.solve(T, start="laplacian", accel=accel, max_iter=6, tol=0)
    finally:
        STARTS.pop("test-keeping")
    (start, last), (own,) = seen, kept
    assert start is not own and start.handed_over and not own.handed_over
    assert start.positions.size == start.rotors.size == start.covariances.size == 0
    assert own.positions.shape == V.shape and own.covariances.shape == (len(V), 3, 3)
    assert np.array_equal(watched.positions, plain.positions)
    assert [r["total"] for r in watched.log] == [r["total"] for r in plain.log]
    # the accelerated driver keeps its iterates settled: no covariances past their local step
    assert (last.covariances.size == 0) == (accel == "anderson")
    assert np.array_equal(last.positions, watched.positions)


def test_a_settled_state_keeps_positions_rotors_and_energy_and_leaves_the_state_whole(bent):
    V, F, ids, T = bent
    step = Deformer(V, F, ids).step_for(T, tol=1e-6)
    state = step(STARTS["laplacian"](step, None))
    settled = state.settled()
    assert settled.covariances.shape == (0, 3, 3) and settled.stretch is None
    assert settled.positions is state.positions and settled.rotors is state.rotors
    assert (settled.total, settled.iteration) == (state.total, state.iteration)
    assert state.covariances.shape == (len(V), 3, 3)


def test_one_step_is_a_function_of_the_state(bent):
    """Two steps from the same state give the same state; the energy of any pair is the
    state's energy."""
    V, F, ids, T = bent
    d = Deformer(V, F, ids)
    step = d.step_for(T, tol=1e-6)
    s0 = STARTS["laplacian"](step, None)
    a, b = step(s0), step(s0)
    assert a.iteration == 1 and np.array_equal(a.positions, b.positions)
    assert np.array_equal(a.rotors, b.rotors)
    e = d.energy(a.positions, a.rotors)
    assert e["total"] == pytest.approx(a.total, rel=1e-9)
    assert np.array_equal(a.positions[ids], T)


def test_plain_driver_matches_the_loop_written_out(bent):
    V, F, ids, T = bent
    d = Deformer(V, F, ids)
    r = d.solve(T, accel="none", start="laplacian", max_iter=7, tol=0)
    step = d.step_for(T, tol=0)
    state = STARTS["laplacian"](step, None)
    for _ in range(7):
        state = step(state)
    assert np.array_equal(r.positions, state.positions) and r.iterations == 7


def test_every_setting_is_an_option_of_deform_and_a_handle_file_key(tmp_path):
    help_text = CliRunner().invoke(main, ["deform", "--help"]).output
    V = np.zeros((4, 3))
    for s in SETTINGS:
        assert s.flag in help_text
        value = s.choices[-1] if s.choices else ("needles" if s.kind == "codes" else
                                                 "off" if s.kind == "size" else
                                                 s.minimum + 1 if s.minimum is not None else 1)
        if s.kind == "float":
            value = float(value)
        path = tmp_path / "h.yaml"
        path.write_text(json.dumps({"solver": {s.name: value},
                                    "groups": {"a": {"indices": [0], "fixed": True}}}))
        assert s.name in load_handles(str(path), V).solver


def test_bad_setting_values_name_the_setting():
    def error(message):
        return InputError(message)
    with pytest.raises(InputError, match="time_limit must be > 0"):
        parse_mapping({"time_limit": 0}, "solver", error)
    with pytest.raises(InputError, match="tol must be a number"):
        parse_mapping({"tol": "abc"}, "solver", error)
    with pytest.raises(InputError, match="unknown key 'speed' in settings"):
        parse_mapping({"speed": 1}, "settings", error)


def test_library_entry_points_take_every_solver_keyword(bent):
    V, F, ids, T = bent
    r = deform(V, F, ids, T, alpha=0.2, feedback=0.1, weights="cotan-clamped",
               method="sr-relax", sweeps=1, max_iter=3, tol=1e-6, time_limit=60,
               multires="off")
    assert r.iterations == 3
    with pytest.raises(TypeError, match="unexpected keyword 'speed'"):
        deform(V, F, ids, T, speed=2)


def test_time_limit_stops_a_solve_not_converged(bent):
    V, F, ids, T = bent
    # tol 0: no stopping test, only the iteration count and the clock
    r = Deformer(V, F, ids).solve(T, max_iter=100000, tol=0, time_limit=0.3)
    assert not r.converged and 0 < r.iterations < 100000
    assert r.stop_reason is StopReason.TIME_LIMIT and not r.complete
    assert r.log[-1]["seconds"] >= 0.3


def test_one_settings_object_carries_a_solve_from_the_command_line_to_the_solver(monkeypatch,
                                                                                tmp_path):
    """Issue 62: Settings was rebuilt five times per solve. The command line resolves it once;
    every layer below passes that object on."""
    from srarap_cli.solver import settings as settings_module

    built = []
    real = settings_module.Settings.__post_init__

    def counting(self):
        built.append(self)
        real(self)

    monkeypatch.setattr(settings_module.Settings, "__post_init__", counting)
    r = CliRunner().invoke(main, ["deform", os.path.join(ROOT, "sample_meshes", "bar.obj"),
                                  os.path.join(ROOT, "configs", "bar-bend.yaml"), "-o",
                                  str(tmp_path / "o.obj"), "-q"])
    assert r.exit_code == 0, r.output
    assert len(built) == 1
