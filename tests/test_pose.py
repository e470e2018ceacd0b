"""``deform`` and ``info`` on a keyframed handle file: the pose at frame 0 (``time:`` keys
need no frame rate for it), or at ``--frame`` (with ``--fps`` for ``time:`` keys)."""
import json
import os

import numpy as np
import yaml
from click.testing import CliRunner
from helpers import ROOT

from srarap_cli.cli import main
from srarap_cli.io.mesh import read_mesh
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
V = read_mesh(BAR).vertices
TOP = np.flatnonzero(V[:, 2] > 9.99)
HANDLES = {"groups": {
    "base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True},
    "top": {"box": {"min": [-2, -2, 9.99], "max": [2, 2, 10.01]}, "keyframes": [
        {"time": 0}, {"time": 2.0, "rotate": {"axis": [0, 0, 1], "angle_deg": 80}}]}}}


def deform(tmp_path, *extra):
    h = tmp_path / "h.yaml"
    h.write_text(yaml.safe_dump(HANDLES))
    out = tmp_path / "out.obj"
    if out.exists():
        out.unlink()
    r = CliRunner().invoke(main, ["deform", BAR, str(h), "-o", str(out), *extra])
    return r, out


def turned_top(degrees):
    """The top's rest positions turned about its centroid's vertical axis."""
    rest = V[TOP]
    c = rest.mean(axis=0)
    return (rest - c) @ to_matrix(from_axis_angle([0, 0, 1], degrees)).T + c


def test_time_keys_give_the_pose_at_frame_0_without_a_frame_rate(tmp_path):
    r, out = deform(tmp_path)
    assert r.exit_code == 0, r.stderr
    assert np.allclose(read_mesh(str(out)).vertices, V, atol=1e-9)  # time 0: the rest pose


def test_frame_and_fps_choose_the_pose_the_constrained_vertices_reach(tmp_path):
    r, out = deform(tmp_path, "--fps", "12", "--frame", "12")  # one second: half the turn
    assert r.exit_code == 0, r.stderr
    assert np.allclose(read_mesh(str(out)).vertices[TOP], turned_top(40), atol=1e-9)
    r, out = deform(tmp_path, "--fps", "12", "--frame", "24")
    assert np.allclose(read_mesh(str(out)).vertices[TOP], turned_top(80), atol=1e-9)


def test_a_later_frame_of_time_keys_without_a_frame_rate_says_to_give_one(tmp_path):
    r, out = deform(tmp_path, "--frame", "3")
    assert r.exit_code == 4 and not out.exists()
    assert "time needs a frame rate: give --fps" in r.stderr


def test_info_takes_the_same_file_and_options(tmp_path):
    h = tmp_path / "h.yaml"
    h.write_text(yaml.safe_dump(HANDLES))
    r = CliRunner().invoke(main, ["info", BAR, str(h), "--json"])
    assert r.exit_code == 0, r.stderr
    assert [g["name"] for g in json.loads(r.output)["groups"]] == ["base", "top"]
    r = CliRunner().invoke(main, ["info", BAR, str(h), "--fps", "24", "--frame", "10"])
    assert r.exit_code == 0, r.stderr
