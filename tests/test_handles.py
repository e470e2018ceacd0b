"""Handle files: every selector, every action, and errors that name group and field."""
import json

import numpy as np
import pytest
import yaml
from helpers import rounded_turn, tube

from srarap_cli.io.handles import load_handles
from srarap_cli.runtime.errors import InputError
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix

V, F = tube()
BOTTOM = np.flatnonzero(V[:, 2] < 1e-9)
TOP = np.flatnonzero(V[:, 2] > 6 - 1e-9)


def load(tmp_path, doc, name="handles.yaml"):
    path = tmp_path / name
    path.write_text(json.dumps(doc) if name.endswith(".json") else yaml.safe_dump(doc))
    return load_handles(str(path), V)


def target_of(c, ids):
    return c.targets[np.searchsorted(c.ids, ids)]


BOX_TOP = {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]}


def test_selectors_pick_the_expected_vertices(tmp_path):
    (tmp_path / "g.dmat").write_text(f"1 {len(V)}\n" + "\n".join(
        "1" if i in TOP else "-1" for i in range(len(V))) + "\n")
    (tmp_path / "s.sel").write_text("# sel\n# v\n" + "\n".join(
        "0" if i in BOTTOM else "1" for i in range(len(V))) + "\n")
    c = load(tmp_path, {"groups": {
        "a": {"indices": [3, 5], "fixed": True},
        "b": {"sphere": {"center": [0, 0, 3], "radius": 1.01}, "fixed": True},
        "c": {"box": BOX_TOP, "fixed": True},
        "d": {"dmat": {"file": "g.dmat", "group": 1}, "fixed": True},
        "e": {"sel": {"file": "s.sel", "status": "fixed"}, "fixed": True}}})
    ring3 = np.flatnonzero(np.isclose(V[:, 2], 3.0))
    assert c.groups["a"].tolist() == [3, 5]
    assert np.array_equal(c.groups["b"], ring3)
    assert np.array_equal(c.groups["c"], TOP) and np.array_equal(c.groups["d"], TOP)
    assert np.array_equal(c.groups["e"], BOTTOM)
    assert np.array_equal(c.ids, np.unique(np.concatenate([[3, 5], ring3, TOP, BOTTOM])))
    assert np.array_equal(c.targets, V[c.ids])


def test_actions_move_groups_as_stated(tmp_path):
    (tmp_path / "m.def").write_text("# def\n0 -1 0 1\n1 0 0 2\n0 0 1 3\n0 0 0 1\n")
    R = to_matrix(from_axis_angle([0, 0, 1], 90))
    pivot = np.array([1.0, 0, 0])
    groups = {
        "translate": {"indices": [0], "translate": [1, 2, 3]},
        "rotate_centroid": {"box": BOX_TOP, "rotate": {"axis": [0, 0, 1], "angle": 90}},
        "rotate_pivot": {"indices": [20], "rotate": {"axis": [0, 0, 2], "angle": 90},
                         "pivot": pivot.tolist(), "translate": [0, 0, 1]},
        "quaternion": {"indices": [30], "rotate": {"quaternion": [2, 0, 0, 2]},
                       "pivot": [0, 0, 0]},
        "matrix": {"indices": [40], "matrix": [[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 3],
                                               [0, 0, 0, 1]]},
        "def_file": {"indices": [50], "matrix": "m.def"},
        "fixed": {"indices": [60], "fixed": True},
    }
    c = load(tmp_path, {"groups": groups})
    centroid = V[TOP].mean(axis=0)
    assert np.allclose(target_of(c, [0]), V[0] + [1, 2, 3])
    assert np.allclose(target_of(c, TOP), (V[TOP] - centroid) @ R.T + centroid)
    assert np.allclose(target_of(c, [20]), (V[20] - pivot) @ R.T + pivot + [0, 0, 1])
    assert np.allclose(target_of(c, [30]), V[30] @ R.T)
    for i in (40, 50):
        assert np.allclose(target_of(c, [i]), V[i] @ R.T + [1, 2, 3])
    assert np.array_equal(target_of(c, [60]), V[[60]])


def test_yaml_and_json_give_the_same_constraints(tmp_path):
    doc = {"solver": {"alpha": 0.5, "max_iter": 7}, "region": {"box": BOX_TOP},
           "groups": {"tip": {"box": BOX_TOP, "translate": [0, 1, 0]},
                      "base": {"indices": BOTTOM.tolist(), "fixed": True}}}
    a, b = load(tmp_path, doc), load(tmp_path, doc, "handles.json")
    assert np.array_equal(a.ids, b.ids) and np.array_equal(a.targets, b.targets)
    assert a.solver == b.solver == {"alpha": 0.5, "max_iter": 7}
    assert np.array_equal(a.region, TOP)


def test_sel_file_alone_uses_the_def_beside_it(tmp_path):
    (tmp_path / "c.sel").write_text("# a\n# b\n" + "\n".join(
        "0" if i in BOTTOM else "2" if i in TOP else "1" for i in range(len(V))))
    (tmp_path / "c.def").write_text("# 4x4\n1 0 0 5\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    c = load_handles(str(tmp_path / "c.sel"), V)
    assert np.array_equal(c.ids, np.union1d(BOTTOM, TOP))
    assert np.allclose(target_of(c, TOP), V[TOP] + [5, 0, 0])
    assert np.array_equal(target_of(c, BOTTOM), V[BOTTOM])


@pytest.mark.parametrize("groups, message", [
    ({"tip": {"sphere": {"center": [0, 0, 0], "radius": 0}, "fixed": True}},
     "handles.yaml: group 'tip': radius must be > 0"),
    ({"tip": {"indices": [0], "fixd": True}}, "group 'tip': unknown key 'fixd'"),
    ({"tip": {"indices": [100000], "fixed": True}}, "group 'tip': indices: vertex 100000 out of range"),
    ({"tip": {"box": {"min": [9, 9, 9], "max": [10, 10, 10]}, "fixed": True}},
     "group 'tip': selects no vertex (box [9, 9, 9]..[10, 10, 10]); the mesh spans x "),
    ({"tip": {"indices": [0]}}, "group 'tip': no action"),
    ({"tip": {"fixed": True}}, "group 'tip': no selector"),
    ({"tip": {"indices": [0], "fixed": True, "translate": [1, 0, 0]}}, "cannot be combined"),
    ({"tip": {"indices": [0], "rotate": {"axis": [0, 0, 0], "angle": 3}}}, "axis must not be zero"),
    ({"tip": {"indices": [0], "translate": [1, 0]}}, "translate must be a list of 3 numbers"),
    ({"tip": {"indices": [0], "translate": "up"}}, "translate must be numeric"),
    ({"tip": {"indices": [0], "pivot": [0, 0, 0], "translate": [1, 0, 0]}}, "pivot only applies"),
    ({"a": {"indices": [0, 1], "fixed": True}, "b": {"indices": [1], "translate": [1, 0, 0]}},
     "vertex 1 is in groups 'a' and 'b' with different targets"),
    ({"tip": {"dmat": {"file": "short.dmat", "group": 0}, "fixed": True}},
     "short.dmat has 3 entries but the mesh has"),
    ({"tip": {"dmat": {"file": "missing.dmat", "group": 0}, "fixed": True}}, "no such file"),
    ({}, "'groups' must map at least one group"),
    ({"tip": {"sphere": {"center": [0, 0, 0]}, "fixed": True}},
     "group 'tip': sphere needs 'center' and 'radius'"),
    ({"tip": {"box": {"min": [0, 0, 0]}, "fixed": True}}, "box needs 'min' and 'max'"),
    ({"tip": {"dmat": {"file": "short.dmat"}, "fixed": True}}, "dmat needs 'file' and 'group'"),
    ({"tip": {"sel": {"status": "handle"}, "fixed": True}}, "sel needs 'file' and 'status'"),
    ({"tip": {"box": [0, 1], "fixed": True}}, "box must be a mapping"),
])
def test_invalid_handle_files_name_group_and_field(tmp_path, groups, message):
    (tmp_path / "short.dmat").write_text("1 3\n0\n0\n0\n")
    with pytest.raises(InputError) as info:
        load(tmp_path, {"groups": groups})
    assert message in str(info.value) and "\n" not in str(info.value)


def test_two_groups_giving_a_vertex_one_motion_in_rounded_decimals_agree(tmp_path):
    turn = {"box": BOX_TOP, "rotate": {"axis": [0, 0, 1], "angle_deg": 30}, "pivot": [0, 0, 0]}
    c = load(tmp_path, {"groups": {"a": turn, "b": {"box": BOX_TOP,
                                                    "matrix": rounded_turn([0, 0, 1], 30, 6).tolist()}}})
    exact = V[TOP] @ to_matrix(from_axis_angle([0, 0, 1], 30)).T
    assert np.allclose(target_of(c, TOP), exact, atol=1e-14)  # the first group's target
    with pytest.raises(InputError, match="with different targets"):
        load(tmp_path, {"groups": {"a": turn, "b": {"box": BOX_TOP,
                                                    "matrix": rounded_turn([0, 0, 1], 30.1, 6).tolist()}}})


@pytest.mark.parametrize("solver, message", [
    ({"alpha": -1}, "solver: alpha must be > 0"),
    ({"max_iter": 2.5}, "solver: max_iter must be an integer"),
    ({"weights": "mean"}, "solver: weights must be one of"),
    ({"tolerance": 1}, "unknown key 'tolerance' in solver"),
])
def test_invalid_solver_settings(tmp_path, solver, message):
    with pytest.raises(InputError, match=message):
        load(tmp_path, {"solver": solver, "groups": {"a": {"indices": [0], "fixed": True}}})


def test_malformed_yaml_reports_the_line(tmp_path):
    path = tmp_path / "h.yaml"
    path.write_text("groups:\n  a: {indices: [0\n")
    with pytest.raises(InputError, match=r"h.yaml: not valid YAML \(line \d+, column \d+\)"):
        load_handles(str(path), V)


@pytest.mark.parametrize("doc, message", [
    ({"groups": {"a": {"indices": [0], "fixd": True}}},
     "unknown key 'fixd' in the group; did you mean 'fixed'?"),
    ({"solver": {"multires_mod": "transfer"}, "groups": {"a": {"indices": [0], "fixed": True}}},
     "unknown key 'multires_mod' in solver; did you mean 'multires_mode'?"),
])
def test_an_unknown_key_suggests_the_nearest_one(tmp_path, doc, message):
    with pytest.raises(InputError, match=message.replace("?", r"\?")):
        load(tmp_path, doc)


def test_an_index_out_of_range_gives_the_valid_range(tmp_path):
    n = len(V)
    with pytest.raises(InputError, match=rf"vertex {n + 5} \(and 1 more\) out of range: the "
                                         rf"mesh has {n} vertices, ids 0..{n - 1} \(0-based\)"):
        load(tmp_path, {"groups": {"a": {"indices": [0, n + 5, -1], "fixed": True}}})


def test_two_angles_are_named_as_the_mistake(tmp_path):
    doc = {"groups": {"a": {"indices": [0], "rotate": {"axis": [0, 0, 1], "angle_deg": 30,
                                                         "angle_rad": 0.5}}}}
    with pytest.raises(InputError, match="rotate takes one angle, got angle_deg and angle_rad"):
        load(tmp_path, doc)


def test_a_yaml_syntax_error_gives_line_and_column(tmp_path):
    (tmp_path / "h.yaml").write_text("groups:\n  a: {indices: [0, fixed: true}\n")
    with pytest.raises(InputError, match=r"not valid YAML \(line 2, column \d+\)"):
        load_handles(str(tmp_path / "h.yaml"), V)


def test_a_rotate_without_pivot_turns_about_the_groups_centroid():
    """The documented default, on a group whose centroid is far from the origin and from
    every axis (a tube turned about its own axis would pass with either pivot)."""
    from scipy.spatial.transform import Rotation

    from srarap_cli.io.handles import parse_handles

    V = np.random.default_rng(3).normal(size=(40, 3)) + [5.0, -3.0, 7.0]
    ids = np.arange(10, 20)
    c = parse_handles({"groups": {"g": {"indices": ids.tolist(), "rotate": {
        "axis": [1, 2, 2], "angle_deg": 70}}}}, V)
    R = Rotation.from_rotvec(np.radians(70) * np.array([1, 2, 2]) / 3).as_matrix()
    centroid = V[ids].mean(axis=0)
    assert np.allclose(c.targets, (V[ids] - centroid) @ R.T + centroid, atol=1e-12)
    # the centroid itself stays where it is; about the origin it would move by |c| x angle
    assert np.allclose(c.targets.mean(axis=0), centroid, atol=1e-12)


def test_a_box_and_a_sphere_select_the_vertices_on_their_boundary():
    """Closed sets, as the docs say: a box's faces and a sphere's surface belong to them (a
    handle box drawn at a mesh's extent must select its end vertices)."""
    from srarap_cli.io.handles import parse_handles

    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 1], [0.5, 0.5, 0.5], [1.0000001, 0, 0],
                  [2, 0, 0], [0, 0, 2]])
    box = parse_handles({"groups": {"g": {"box": {"min": [0, 0, 0], "max": [1, 1, 1]},
                                          "fixed": True}}}, V)
    assert box.ids.tolist() == [0, 1, 2, 3]
    ball = parse_handles({"groups": {"g": {"sphere": {"center": [0, 0, 0], "radius": 2},
                                           "fixed": True}}}, V)
    assert ball.ids.tolist() == [0, 1, 2, 3, 4, 5, 6]
    small = parse_handles({"groups": {"g": {"sphere": {"center": [0, 0, 0], "radius": 1},
                                            "fixed": True}}}, V)
    assert small.ids.tolist() == [0, 1, 3]
