"""The gates of a golden, quantity by quantity (``tasks/comparison/gates.py``): each fails
alone, the verdict names every failing gate with its numbers and units, and a bad or
misspelt key is refused by name."""
import numpy as np
import pytest

from srarap_cli.io.mesh import Mesh
from srarap_cli.tasks.comparison import compare_meshes
from srarap_cli.tasks.comparison.gates import (
    EXPECT_KEYS,
    GATE_KEYS,
    Expect,
    Observed,
    judge,
    parse_expect,
    verdict_line,
)

#: a 10 x 10 grid of vertices in the plane z = 0
GRID = np.array([[x, y, 0.0] for y in range(10) for x in range(10)])
FACES = np.array([[a, a + 1, a + 10] for a in range(89) if a % 10 != 9])


def moved(ids, by):
    """The grid, and a copy with vertices ``ids`` lifted by ``by``: per-vertex distances
    are exactly ``by`` there and 0 elsewhere."""
    a = Mesh.from_arrays(GRID, FACES)
    V = GRID.copy()
    V[ids, 2] += by
    return compare_meshes(a, a.with_vertices(V))


def test_every_key_is_a_field_and_every_gate_a_key():
    assert EXPECT_KEYS[0] == "golden" and set(GATE_KEYS) == set(EXPECT_KEYS) - {"golden"}
    full = {"golden": "g.obj", "tol": 1, "relative": True, "beyond_tol": 0.5, "p95": 1,
            "p99": 2, "energy_rtol": 0.1, "max_iterations": 3, "iterations_within": 2,
            "max_seconds": 9, "align": "rigid"}
    assert set(full) == set(EXPECT_KEYS)
    e = parse_expect(full, ValueError)
    assert {k: getattr(e, k) for k in full} == {**full, "tol": 1.0, "p95": 1.0, "p99": 2.0,
                                               "max_seconds": 9.0}


@pytest.mark.parametrize("spec, words", [
    ({"golden": "g", "tolerance": 1}, "unknown key 'tolerance' in expect (allowed: align,"),
    ({"golden": "g", "energy_rtl": 1}, "did you mean 'energy_rtol'"),
    ({"tol": 1}, "expect needs a golden mesh"),
    ({"golden": "g", "tol": -1}, "tol must be a finite number >= 0"),
    ({"golden": "g", "tol": "nan"}, "tol must be a finite number"),
    ({"golden": "g", "tol": 10 ** 400}, "tol must be a finite number"),
    ({"golden": "g", "beyond_tol": 1.5}, "beyond_tol must be a finite number >= 0 and <= 1"),
    ({"golden": "g", "max_iterations": 2.5}, "max_iterations must be a whole number"),
    ({"golden": "g", "iterations_within": True}, "iterations_within must be a whole number"),
    ({"golden": "g", "relative": "yes"}, "relative must be true or false"),
    ({"golden": "g", "align": "affine"}, "align must be one of none, rigid"),
    ("g.obj", "expect must be a mapping"),
])
def test_a_bad_expect_is_refused_by_name(spec, words):
    with pytest.raises(ValueError, match=words.replace("(", r"\(").replace(")", r"\)")):
        parse_expect(spec, ValueError)


def test_numbers_spelt_as_yaml_text_are_numbers():
    e = parse_expect({"golden": "g", "tol": "1e-6", "max_iterations": "1e2"}, ValueError)
    assert e.tol == 1e-6 and e.max_iterations == 100


def test_within_every_gate_nothing_fails():
    found = moved([3], 0.5)
    expect = Expect("g", tol=0.5, p95=0.5, p99=0.5, energy_rtol=0.1, max_iterations=10,
                    iterations_within=1, max_seconds=5)
    assert judge(found, expect, Observed(10, 1.05, 4.0), {"energy": 1.0, "iterations": 9}) == []


def test_the_largest_distance_fails_with_where_and_how_many():
    failed = judge(moved([3], 0.5), Expect("g", tol=0.4), Observed(), None)
    assert failed == ["max distance 0.5 > tol 0.4 at vertex 3 of the golden mesh; 1% of the "
                      "vertices beyond tol"]


def test_a_fraction_beyond_tol_replaces_the_largest_distance():
    """One vertex of 100 beyond tol is 1%: within beyond_tol 2%, beyond 0.5%."""
    found = moved([3], 0.5)
    assert judge(found, Expect("g", tol=0.4, beyond_tol=0.02), Observed(), None) == []
    failed = judge(found, Expect("g", tol=0.4, beyond_tol=0.005), Observed(), None)
    assert failed == ["1% of the vertices beyond tol 0.4 > beyond_tol 0.5% at vertex 3 of the "
                      "golden mesh"]


def test_percentiles_gate_many_vertices_not_one():
    """Ten vertices of 100 moved by 1: p95 is 1 (the top 10% are all 1), p99 too; one
    vertex moved: p95 is 0, p99 is interpolated (0.01 of the way from 0 to 1)."""
    many, one = moved(list(range(10)), 1.0), moved([7], 1.0)
    assert many.p95 == 1.0 and many.p99 == 1.0 and one.p95 == 0.0
    assert one.p99 == pytest.approx(0.01)
    gate = Expect("g", tol=2.0, p95=0.5)
    assert judge(one, gate, Observed(), None) == []
    assert judge(many, gate, Observed(), None) == ["p95 distance 1 > p95 0.5"]
    assert judge(many, Expect("g", tol=2.0, p99=0.9), Observed(), None) == \
        ["p99 distance 1 > p99 0.9"]


@pytest.mark.parametrize("expect, run, record, words", [
    (Expect("g", energy_rtol=0.01), Observed(energy=1.02), {"energy": 1.0},
     "energy 1.02 is 2% from the golden's 1 > energy_rtol 1%"),
    (Expect("g", energy_rtol=0.01), Observed(energy=1.0), None,
     "energy: the golden has no recorded energy (--update-goldens records it)"),
    (Expect("g", energy_rtol=0.01), Observed(), {"energy": 1.0},
     "energy: this result has none to gate (no solve made it)"),
    (Expect("g", max_iterations=40), Observed(iterations=41), None,
     "iterations 41 > max_iterations 40"),
    (Expect("g", iterations_within=2), Observed(iterations=27), {"iterations": 30},
     "iterations 27, the golden's 30 (-3) > iterations_within 2"),
    (Expect("g", max_seconds=1.5), Observed(seconds=2.0), None,
     "seconds 2 > max_seconds 1.5 (wall time: noisy)"),
])
def test_each_run_gate_fails_alone_with_its_numbers(expect, run, record, words):
    assert judge(moved([], 0.0), expect, run, record) == [words]


def test_every_failing_gate_is_listed_in_the_verdict():
    found = moved(list(range(10)), 1.0)
    expect = Expect("g", tol=0.5, p95=0.5, energy_rtol=0.01, max_iterations=5)
    failed = judge(found, expect, Observed(9, 2.0, 1.0), {"energy": 1.0}, " of the diagonal")
    assert [f.split(" ")[0] for f in failed] == ["max", "p95", "energy", "iterations"]
    line = verdict_line(found, expect, failed, " of the diagonal")
    assert line.startswith("BEYOND tol 0.5 of the diagonal (per-vertex): max 1, ")
    assert "farthest: A's vertex 0 at (0, 0, 0); 10% of the vertices beyond tol" in line
    for phrase in failed[1:]:
        assert phrase in line
