"""tasks/rigid_parts.py: a connected part carried off rigidly by its handles is named; one the
handles bend is not. Handle files give motions as rounded decimals, so "rigid" is up to that
rounding, not up to double precision."""
import numpy as np
import pytest
from helpers import rounded_turn

from srarap_cli.io.handles import Constraints
from srarap_cli.tasks.rigid_parts import rigid_part_warnings

# two triangles, ten apart: each a connected part of its own
V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [10, 0, 0], [11, 0, 0], [10, 1, 0]])
F = np.array([[0, 1, 2], [3, 4, 5]])


def _turn(decimals):
    return rounded_turn([0, 0, 1], 40, decimals)[:3, :3]


def _warnings(targets_of_second):
    ids = np.array([0, 3, 4, 5])
    targets = np.vstack([V[[0]], targets_of_second])
    return rigid_part_warnings(V, F, Constraints(ids=ids, targets=targets,
                                                 groups={"base": ids[:1], "arm": ids[1:]}))


@pytest.mark.parametrize("decimals", [4, 6, 15])
def test_a_part_turned_by_a_rounded_rotation_is_named(decimals):
    (warning,) = _warnings(V[3:] @ _turn(decimals).T + [0, 0, 2])
    assert "1 connected part(s) (3 vertices" in warning and "'arm'" in warning


@pytest.mark.parametrize("stretch", [1.01, 1.003])
def test_a_part_its_handles_stretch_is_not_named(stretch):
    X = V[3:] - V[3:].mean(axis=0)
    assert _warnings(V[3:].mean(axis=0) + stretch * X @ _turn(15).T) == []


def test_a_part_held_at_rest_is_not_named():
    assert _warnings(V[3:]) == []
