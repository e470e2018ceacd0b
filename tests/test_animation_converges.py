"""Animations converge unless asked not to, and warm starts from earlier frames pay.

A tube of a few thousand vertices twisted by keyframes: every frame passes the stopping test
by default; a frame that cannot (``--max-iter`` too small) stops the sequence with exit 3
before it is written; ``--keep-unconverged`` writes it and goes on (exit 3);
``--iters-per-frame`` is a fixed budget (exit 0)."""
import csv
import subprocess
import sys

import numpy as np
import pytest
from helpers import ends, tube, tube_mesh

from srarap_cli import Deformer
from srarap_cli.io.mesh import write_mesh
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix
from srarap_cli.tasks.animate.sequence import _carried

TWIST = ("groups:\n  base: {box: {min: [-2, -2, -0.01], max: [2, 2, 0.01]}, fixed: true}\n"
         "  top:\n    box: {min: [-2, -2, 9.99], max: [2, 2, 10.01]}\n    keyframes:\n"
         "      - {frame: 0}\n      - {frame: 9, rotate: {axis: [0, 0, 1], angle_deg: 27}}\n")


@pytest.fixture
def case(tmp_path):
    write_mesh(str(tmp_path / "m.obj"), tube_mesh(length=10.0, rings=50, segments=40))
    (tmp_path / "k.yaml").write_text(TWIST)
    return tmp_path


def _animate(folder, *extra):
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "animate", "m.obj", "k.yaml", "-o",
                        "f_{:02d}.obj", "--log", "frames.csv", *extra], cwd=folder,
                       capture_output=True, text=True, timeout=300)
    rows = list(csv.DictReader(open(folder / "frames.csv"))) if (folder / "frames.csv").exists() \
        else []
    written = sorted(p.name for p in folder.glob("f_*.obj"))
    return p, rows, written


def test_every_frame_converges_by_default(case):
    p, rows, written = _animate(case)
    assert p.returncode == 0, p.stderr
    assert len(rows) == 10 and all(r["converged"] == "true" for r in rows)
    assert len(written) == 10 and "10 of 10 frames converged" in p.stderr


def test_a_frame_that_cannot_converge_stops_the_sequence_with_exit_3(case):
    p, rows, written = _animate(case, "--max-iter", "2")
    assert p.returncode == 3, p.stderr
    stopped = int(p.stderr.split("STOPPED at frame ")[1].split(":")[0])
    assert written == [f"f_{f:02d}.obj" for f in range(stopped)]  # only converged frames
    assert rows[-1]["converged"] == "false" and int(rows[-1]["frame"]) == stopped


def test_keep_unconverged_writes_every_frame_and_still_exits_3(case):
    p, rows, written = _animate(case, "--max-iter", "2", "--keep-unconverged")
    assert p.returncode == 3 and len(written) == 10
    assert any(r["converged"] == "false" for r in rows)


def test_a_fixed_budget_writes_every_frame_and_exits_0(case):
    p, rows, written = _animate(case, "--iters-per-frame", "2")
    assert p.returncode == 0 and len(written) == 10
    assert all(int(r["iterations"]) <= 2 for r in rows)


def test_warm_starts_a_few_degrees_on_reach_the_cold_shape_in_fewer_iterations():
    """One earlier pose (the API's ``initial``): no more iterations than cold; two earlier
    frames (an animation carries them on): far fewer. Same shape as a tight solve."""
    V, F = tube(length=10.0, rings=40, segments=24)
    ids = ends(V, 10.0)
    top = V[ids][:, 2] > 5
    d = Deformer(V, F, ids)

    def targets(deg):
        T = V[ids].copy()
        T[top] = T[top] @ to_matrix(from_axis_angle([0, 0, 1], deg)).T
        return T

    earlier, before = d.solve(targets(27.0)), d.solve(targets(30.0))
    warm = d.solve(targets(33.0), initial=(before.positions, before.rotors))
    carried = d.solve(targets(33.0), initial=_carried(before.positions, before.rotors,
                                                       (earlier.positions, earlier.rotors)))
    cold = d.solve(targets(33.0))
    tight = d.solve(targets(33.0), tol=1e-12, max_iter=3000)
    assert warm.converged and warm.iterations <= cold.iterations
    assert carried.converged and carried.iterations <= cold.iterations // 2
    for r in (warm, carried):
        assert np.abs(r.positions - tight.positions).max() < 1e-4 * d.diagonal
