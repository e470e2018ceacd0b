"""The stopping rules: windowed relative energy change, vertex moves, exact answers."""
from types import SimpleNamespace

import numpy as np

from srarap_cli.solver.drivers.monitor import EPS, EXACT, STILL, WINDOW, Monitor


def run(energies, *, tol=1e-6, moves=None, energy_scale=1.0):
    """Record one state per energy (the first is the start), each step moving a vertex by
    ``moves[k]`` (default 1e-4 of the mesh's size: still moving, within sqrt(tol)); the
    iteration it stopped at."""
    m = Monitor(max_iter=len(energies) + 5, tol=tol, energy_scale=energy_scale, scale=1.0)
    moves = moves or [1e-4] * len(energies)
    previous = None
    for k, (e, x) in enumerate(zip(energies, np.cumsum(moves))):
        state = SimpleNamespace(total=e, membrane=e, bending=0.0,
                                positions=np.array([[x, 0.0, 0.0]]))
        if m.record(state, previous):
            return k, m.converged
        previous = state
    return None, m.converged


def test_one_small_change_between_large_ones_does_not_stop_the_run():
    """The case that ended a refine run 0.08% above the minimum: steps still gaining 2e-5
    each, then one accepted step changing the energy by 3e-7."""
    gains = [1.0, 2e-5, 2e-5, 2e-5, 3e-7, 2e-5, 2e-5]
    energies = np.cumprod([10.0] + [1 - g for g in gains[1:]])
    stopped, _ = run(list(energies))
    assert stopped is None


def test_a_run_whose_changes_settle_stops_once_the_window_averages_below_tol():
    gains = [1e-3, 1e-4, 5e-7, 4e-7, 3e-7]
    energies = list(np.cumprod([10.0] + [1 - g for g in gains]))
    stopped, converged = run(energies)
    # the last WINDOW changes average 4e-7; a window holding the 1e-4 does not settle
    assert converged and stopped == len(energies) - 1 == 2 + WINDOW


def test_a_warm_start_at_the_answer_stops_after_a_full_window():
    """A first small step alone does not stop a run: across an animation such one-step stops
    added up (see the monitor's docstring)."""
    assert run([5.0, 5.0]) == (None, False)
    assert run([5.0] * (WINDOW + 1)) == (WINDOW, True)


def test_an_exact_answer_stops_even_though_its_relative_changes_are_noise():
    """Energies at rounding level (1e-14 of the rest scale) changing by 50% per step: the
    relative test never settles, the energy itself says nothing is left to gain."""
    tiny = [2e-14, 1e-14, 3e-14, 1.5e-14]
    assert run([1.0] + tiny, energy_scale=1.0)[1]
    assert 1e-14 < 1e-6 * EXACT  # below the default tol's exact-answer level
    # a tight tol asks for more than that: the same energies do not count as exact then
    assert run([1.0] + tiny, tol=1e-16, energy_scale=1.0) == (None, False)


def test_an_iterate_that_no_longer_moves_is_converged_whatever_its_energy_noise():
    """An exactly rigid answer keeps a bending energy of rounding (the rotors' errors),
    which may sit above a tight tol's exact level: a solve whose last WINDOW steps moved
    nothing beyond rounding stops, converged; fewer such steps do not; tol 0 is a budget."""
    tiny = [2e-14, 1e-14, 3e-14, 1.5e-14]
    unit = STILL * EPS  # one vertex here: the bound is STILL units of rounding of the size
    still = [0.0] + [unit / 2] * len(tiny)
    assert run([1.0] + tiny, tol=1e-16, moves=still) == (WINDOW, True)
    assert run([1.0] + tiny, tol=1e-16, moves=[0.0, 1e-4, unit / 2, unit / 2, 1e-4]) \
        == (None, False)
    assert run([1.0] + tiny, tol=1e-16, moves=[0.0] + [2 * unit] * len(tiny)) \
        == (None, False)
    assert run([1.0] + tiny, tol=0.0, moves=still) == (None, False)


def test_a_large_move_keeps_the_run_going_however_little_the_energy_changed():
    energies = [1.0, 1.0, 1.0, 1.0]
    stopped, _ = run(energies, moves=[0.0, 0.1, 0.1, 0.1])
    assert stopped is None


def test_the_rounding_a_still_step_may_show_grows_with_the_vertex_count():
    """A Poisson solve's rounding grows with the mesh (measured: 1 unit on 106 vertices, 60
    on 100k, 94 on 1.2M): 300 units of rounding a step is still on 10,000 vertices (the
    bound is n/25 = 400 units), not on one (64)."""
    def stops(n):
        m = Monitor(max_iter=20, tol=1e-16, energy_scale=1.0, scale=1.0)
        x = np.zeros((n, 3))
        previous = None
        for k in range(WINDOW + 2):
            x = x + [300 * EPS if k else 0.0, 0.0, 0.0]
            state = SimpleNamespace(total=1e-14 * (1 + k % 2), membrane=0.0, bending=0.0,
                                    positions=x)
            if m.record(state, previous):
                return m.converged
            previous = state
        return False
    assert stops(10_000) and not stops(1)
