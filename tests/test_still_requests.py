"""Requests that deform nothing are said (``tasks/still_requests.py``, ``tasks/rigid_parts.py``):
a one-part mesh moved by handles that move it rigidly (the forgotten fixed group), only
fixed groups (the rest shape), every vertex held; as request warnings with codes, so that
``--strict`` fails them, in ``deform``, ``info`` and a batch; an animation's rest pose at its
first frame says nothing."""
import json

import numpy as np
import pytest
from helpers import ROOT, run_cli

BAR = f"{ROOT}/sample_meshes/bar.obj"
BASE = {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True}
TOP = {"box": {"min": [-2, -2, 9.99], "max": [2, 2, 10.01]}}
EVERYTHING = {"box": {"min": [-5, -5, -1], "max": [5, 5, 11]}}
CASES = {
    "forgotten fixed group": ({"top": {**TOP, "translate": [3, 0, -1.5]}}, "rigid-part",
                              "the whole mesh (1 connected part, 658 vertices) is held only by"),
    "a rigid turn of the top alone": ({"top": {**TOP, "rotate": {"axis": [0, 1, 0],
                                                                  "angle_deg": 30}}},
                                      "rigid-part", "nothing bends (a fixed group forgotten?"),
    "only fixed groups": ({"base": BASE}, "no-motion",
                          "every handle keeps its rest position (group(s) 'base')"),
    "a motion of zero": ({"base": BASE, "top": {**TOP, "translate": [0, 0, 0]}}, "no-motion",
                         "the result is the rest shape"),
    "every vertex held": ({"all": {**EVERYTHING, "translate": [0, 0, 1]}}, "all-held",
                          "every vertex is constrained (658 of 658)"),
}


def handles(tmp_path, groups):
    path = tmp_path / "h.yaml"
    path.write_text(json.dumps({"groups": groups}))
    return path


@pytest.mark.parametrize("case", CASES)
def test_deform_and_info_say_it_and_strict_fails_it(tmp_path, case):
    groups, code, words = CASES[case]
    h = handles(tmp_path, groups)
    r = run_cli(["deform", BAR, h, "-o", tmp_path / "o.obj"])
    assert r.returncode == 0 and f"[{code}]" in r.stderr and words in r.stderr
    assert sum(f"[{code}]" in line for line in r.stderr.splitlines()) == 1
    r = run_cli(["deform", BAR, h, "-o", tmp_path / "s.obj", "--strict"])
    assert r.returncode == 4 and f"[{code}]" in r.stderr and not (tmp_path / "s.obj").exists()
    assert run_cli(["deform", BAR, h, "-o", tmp_path / "a.obj", "--strict", "--allow",
                    code]).returncode == 0
    info = run_cli(["info", BAR, h, "--json"])
    assert any(f"[{code}]" in w for w in json.loads(info.stdout)["warnings"])


def test_a_bend_held_at_both_ends_says_nothing(tmp_path):
    h = handles(tmp_path, {"base": BASE, "top": {**TOP, "translate": [3, 0, -1.5]}})
    r = run_cli(["deform", BAR, h, "-o", tmp_path / "o.obj"])
    assert r.returncode == 0 and "warning" not in r.stderr


def test_an_animation_starting_at_rest_says_nothing_of_its_first_frame(tmp_path):
    h = handles(tmp_path, {"base": BASE, "top": {**TOP, "keyframes": [
        {"frame": 0, "translate": [0, 0, 0]}, {"frame": 2, "translate": [1, 0, 0]}]}})
    r = run_cli(["animate", BAR, h, "-o", str(tmp_path / "f_{}.obj"), "--frames", "3"])
    assert r.returncode == 0 and "no-motion" not in r.stderr and "warning" not in r.stderr


def test_a_batch_job_that_moves_rigidly_fails_under_strict(tmp_path):
    h = handles(tmp_path, CASES["forgotten fixed group"][0])
    manifest = tmp_path / "m.yaml"
    manifest.write_text(json.dumps({"jobs": [{"name": "slip", "mesh": BAR, "handles": str(h),
                                              "output": "slip.obj"}]}))
    r = run_cli(["batch", manifest, "-o", tmp_path / "out", "--strict"])
    row = json.loads((tmp_path / "out" / "summary.json").read_text())[0]
    assert r.returncode == 8 and row["status"] == "failed" and row["exit_code"] == 4
    assert "[rigid-part]" in row["message"]


def test_the_rigid_result_is_really_rigid(tmp_path):
    """What the warning says holds: the output is the rest shape moved by the handles'
    translation, to round-off."""
    from srarap_cli.io.mesh import read_mesh
    h = handles(tmp_path, CASES["forgotten fixed group"][0])
    assert run_cli(["deform", BAR, h, "-o", tmp_path / "o.obj"]).returncode == 0
    moved = read_mesh(str(tmp_path / "o.obj")).vertices - read_mesh(BAR).vertices
    assert np.allclose(moved, [3, 0, -1.5], atol=1e-6)
