"""``srarap info``: counts and extent that can be checked by hand, actions described as the
motions they are, and a dry run that refuses exactly what deform refuses."""
import glob
import json
import os

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import SHARED, needs_shared, tube_mesh

from srarap_cli.cli import main
from srarap_cli.io.handles import parse_handles
from srarap_cli.io.mesh import write_mesh
from srarap_cli.io.mesh.mesh import Mesh
from srarap_cli.tasks.info import describe_motion, mesh_info


def test_counts_extent_parts_and_loops_of_known_meshes():
    bar = tube_mesh(length=6.0, rings=5, segments=8)
    d = mesh_info(bar)
    assert d["vertices"] == len(bar.vertices) and d["faces"] == bar.face_sizes.size
    assert d["components"] == 1 and d["boundary_loops"] == 0
    np.testing.assert_allclose(d["extent"], [2, 2, 6], atol=1e-12)  # 8 segments: at 0, 90 deg
    # an open tube (caps dropped) twice, apart: two parts, four boundary loops
    quads = bar.face_vertices[:bar.face_sizes.tolist().index(3) * 4].reshape(-1, 4)
    V = np.vstack([bar.vertices, bar.vertices + [10, 0, 0]])
    open_pair = Mesh.from_arrays(V, np.vstack([quads, quads + len(bar.vertices)]))
    d = mesh_info(open_pair)
    assert d["components"] == 2 and d["boundary_loops"] == 4


@pytest.mark.parametrize("action, words", [
    ({"fixed": True}, "fixed"),
    ({"translate": [3, 0, -1.5]}, "translate (3, 0, -1.5)"),
    ({"rotate": {"axis": [0, 1, 0], "angle_deg": 60}, "pivot": [0, 0, 10]},
     "rotate 60 degrees about +y through"),
])
def test_actions_are_described_as_the_motions_they_are(action, words):
    bar = tube_mesh(length=10.0, rings=5, segments=8)
    doc = {"groups": {"g": {"box": {"min": [-2, -2, 9.9], "max": [2, 2, 10.1]}, **action}}}
    c = parse_handles(doc, bar.vertices)
    text = describe_motion(bar.vertices[c.ids], c.targets)
    assert text.startswith(words) and "not rigid" not in text


def test_a_rigid_description_reproduces_the_targets():
    rng = np.random.default_rng(3)
    rest = rng.normal(size=(20, 3))
    c = parse_handles({"groups": {"g": {"indices": list(range(20)),
                                        "rotate": {"axis": [1, 2, 3], "angle_deg": 37},
                                        "translate": [0.5, -2, 1]}}}, rest)
    text = describe_motion(rest, c.targets)
    assert "rotate 37 degrees" in text and "then translate" in text and "not rigid" not in text
    bent = c.targets + rng.normal(scale=0.1, size=c.targets.shape)
    assert "not rigid" in describe_motion(rest, bent)


BAD = [
    "groups: {}\n",
    "groups: {g: {indices: [999999], fixed: true}}\n",
    "groups: {g: {box: {min: [1, 1, 1], max: [0, 0, 0]}, fixed: true}}\n",
    "groups: {g: {indices: [0], rotate: {axis: [0, 0, 1]}}}\n",
    "groups:\n  a: {indices: [0], fixed: true}\n  b: {indices: [0], translate: [1, 0, 0]}\n",
    "solver: {tol: -1}\ngroups: {g: {indices: [0], fixed: true}}\n",
    "region: {indices: [0]}\ngroups: {g: {indices: [0], fixed: true}}\n",
    "groups: {g: {dmat: {file: missing.dmat, group: 0}, fixed: true}}\n",
]


@pytest.mark.parametrize("text", BAD)
def test_the_dry_run_refuses_what_deform_refuses_with_the_same_line(tmp_path, text):
    write_mesh(str(tmp_path / "m.obj"), tube_mesh(rings=4, segments=6))
    (tmp_path / "h.yaml").write_text(text)
    runner = CliRunner()
    info = runner.invoke(main, ["info", str(tmp_path / "m.obj"), str(tmp_path / "h.yaml")])
    deform = runner.invoke(main, ["deform", str(tmp_path / "m.obj"), str(tmp_path / "h.yaml"),
                                  "-o", str(tmp_path / "o.obj")])
    assert info.exit_code == deform.exit_code == 4, (info.output, deform.output)
    assert info.stderr == deform.stderr


@needs_shared
@pytest.mark.parametrize("mesh", sorted(glob.glob(os.path.join(SHARED, "*.o*"))))
def test_every_shared_mesh_is_described(mesh):
    r = CliRunner().invoke(main, ["info", mesh, "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["vertices"] > 0 and d["diagonal"] > 0 and d["up_guess"] in ("+y", "+z")


@needs_shared
def test_the_shared_handle_files_are_described():
    runner = CliRunner()
    sel = runner.invoke(main, ["info", os.path.join(SHARED, "cylinder.off"),
                               os.path.join(SHARED, "cylinder.sel"), "--json"])
    assert sel.exit_code == 0, sel.output
    d = json.loads(sel.stdout)
    assert {g["name"] for g in d["groups"]} == {"fixed", "handle"}
    assert d["constrained"] + d["free"] == d["vertices"]
    # the .def's turn is written with six decimals (-0.866025): a rotation all the same
    handle = next(g for g in d["groups"] if g["name"] == "handle")
    assert handle["action"].startswith("rotate 120 degrees about -y"), handle
    assert "not rigid" not in handle["action"], handle


@pytest.mark.parametrize("name", ["bar-twist", "bar-bend", "bar-twist-animated"])
def test_the_shipped_configs_are_described(name):
    from helpers import ROOT

    from srarap_cli.io.handles import load_handles
    from srarap_cli.io.mesh import read_mesh
    mesh = os.path.join(ROOT, "sample_meshes", "bar.obj")
    handles = os.path.join(ROOT, "configs", f"{name}.yaml")
    c = load_handles(handles, read_mesh(mesh).vertices)
    r = CliRunner().invoke(main, ["info", mesh, handles, "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert [(g["name"], g["vertices"]) for g in d["groups"]] == \
        [(g, len(ids)) for g, ids in c.groups.items()]
    assert d["constrained"] == len(c.ids) and d["constrained"] + d["free"] == d["vertices"]


def test_a_surface_cut_open_at_coincident_vertices_is_named():
    """Give the faces on one side of the tube's x = max line their own copies of its
    vertices: exactly those copies sit on other vertices; the welded tube has none."""
    from helpers import tube

    from srarap_cli.solver.mesh_checks import mesh_warnings
    V, F = tube()
    assert not any("sit exactly" in w for w in mesh_warnings(V, F))
    seam = np.flatnonzero(np.isclose(np.arctan2(V[:, 1], V[:, 0]), 0) & (np.hypot(V[:, 0], V[:, 1]) > 0.5))
    side = (V[F].mean(axis=1)[:, 1] > 0)  # faces on the +y side of the seam
    copy = np.arange(len(V))
    copy[seam] = len(V) + np.arange(seam.size)
    F2 = np.where(side[:, None], copy[F], F)
    V2 = np.vstack([V, V[seam]])
    [line] = [w for w in mesh_warnings(V2, F2) if "sit exactly" in w]
    assert line.startswith(f"{seam.size} vertices sit exactly on another vertex ({seam.size} positions)")


def test_info_gives_euler_characteristic_genus_and_unreferenced_vertices():
    from helpers import torus

    from srarap_cli.io.mesh import Mesh
    from srarap_cli.tasks.info import mesh_info
    V, F = torus()
    closed = mesh_info(Mesh.from_arrays(V, F))
    assert (closed["euler"], closed["genus"], closed["boundary_loops"]) == (0, 1, 0)
    lonely = mesh_info(Mesh.from_arrays(np.vstack([V, [[9.0, 9, 9]]]), F))
    assert lonely["genus"] == 1 and "1 unreferenced vertices" in lonely["problems"][-1]


def test_the_up_guess_falls_back_to_y_when_the_extents_do_not_tell():
    """A figure as wide as it is tall (the ogre: x 31.2, y 32.0, z 9.7) stands on y, as most
    OBJ files do, and says it was assumed; two stray vertices do not turn a bar over."""
    from helpers import ROOT

    from srarap_cli.io.mesh import Mesh, read_mesh
    from srarap_cli.tasks.info import up_axis, up_decided

    rng = np.random.default_rng(0)
    V = rng.uniform(0, 1, size=(400, 3)) * [31.2, 32.0, 9.7]
    F = np.array([[i, i + 1, i + 2] for i in range(0, 396, 3)])
    ogre = Mesh.from_arrays(V, F)
    assert up_axis(ogre) == "y" and not up_decided(ogre)
    bar = read_mesh(f"{ROOT}/sample_meshes/bar.obj")
    assert up_axis(bar) == "z" and up_decided(bar)
    strays = np.vstack([bar.vertices, [[40.0, 0, 5], [-40.0, 0, 5]]])
    F = np.vstack([bar.triangles()[0], [[658, 0, 659]]])
    assert up_axis(Mesh.from_arrays(strays, F)) == "z"


@pytest.mark.parametrize("turn", ["angle_deg: 10", "angle_rad: 30"])
def test_the_dry_run_warns_what_deform_warns_on_a_mesh_of_several_parts(tmp_path, turn):
    """Issue 60: ``info MESH HANDLES`` listed no warning where ``deform`` then warned of a
    part carried off rigidly and a part nothing holds. Three tubes: one bent by its handles,
    one moved whole by a group, one held by nothing; ``info --json`` (its warnings and the
    mesh's problems) says exactly what ``deform`` says."""
    from helpers import run_cli, tube, tube_handles

    V, F = tube(length=6.0, rings=8, segments=6)
    W = np.vstack([V, V + [5.0, 0, 0], V + [10.0, 0, 0]])
    G = np.vstack([F, F + len(V), F + 2 * len(V), F[:1]])  # and one face twice
    write_mesh(str(tmp_path / "m.obj"), Mesh.from_arrays(W, G))
    (tmp_path / "h.yaml").write_text(tube_handles(
        f"rotate: {{axis: [0, 0, 1], {turn}}}",
        more="  whole: {box: {min: [3, -2, -1], max: [7, 2, 7]}, translate: [0, 0, 1]}\n"))
    dry = run_cli(["info", "m.obj", "h.yaml", "--json"], cwd=tmp_path)
    assert dry.returncode == 0, dry.stderr
    doc = json.loads(dry.stdout)
    wet = run_cli(["deform", "m.obj", "h.yaml", "-o", "o.obj"], cwd=tmp_path)
    assert wet.returncode == 0, wet.stderr
    said = {line[len("srarap: warning: "):] for line in wet.stderr.splitlines()
            if line.startswith("srarap: warning: ")}
    assert said == set(doc["warnings"]) | set(doc["problems"])
    assert any("move each rigidly" in w for w in said)
    assert any("without a constrained vertex" in w for w in said)


def test_info_passes_over_the_edges_once(monkeypatch):
    """Issue 70: info took three passes over the edges (parts, loops, Euler) besides the
    mesh checks' own. A blow-up guard that counts work: one pass for a clean mesh, and
    the facts it gives are those of the separate passes."""
    from srarap_cli.solver import mesh_checks
    from srarap_cli.tasks import info
    m = tube_mesh(rings=8, segments=10)
    before = mesh_info(m)
    calls = []
    real = mesh_checks.edge_counts

    def counted(F):
        calls.append(len(F))
        return real(F)
    monkeypatch.setattr(mesh_checks, "edge_counts", counted)
    monkeypatch.setattr(info, "edge_counts", counted)
    assert mesh_info(m) == before and len(calls) == 1
    assert (before["components"], before["boundary_loops"], before["genus"]) == (1, 0, 0)


def test_describe_gives_the_mesh_and_the_handles_alike_at_one_and_two_threads():
    from srarap_cli.runtime.parallel import using_threads
    from srarap_cli.tasks.info import describe, handles_info
    m = tube_mesh(rings=8, segments=10)
    c = parse_handles({"groups": {"base": {"indices": [0, 1, 2], "fixed": True},
                                  "top": {"indices": [80, 81], "translate": [0, 0, 1]}}},
                      m.vertices)
    for threads in (1, 2):
        with using_threads(threads):
            assert describe(m, c, "m") == (mesh_info(m), handles_info(m, c, "m"))
            assert describe(m) == (mesh_info(m), None)
