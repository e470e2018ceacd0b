"""``srarap compare`` against distances known in advance."""
import json

import igl
import numpy as np
import pytest
from click.testing import CliRunner
from helpers import tube_mesh

from srarap_cli.cli import main
from srarap_cli.io.mesh import write_mesh
from srarap_cli.io.mesh.mesh import Mesh
from srarap_cli.tasks.comparison.compare import compare_meshes


def tri_mesh(V, F):
    return Mesh(vertices=V, face_sizes=np.full(len(F), 3), face_vertices=F.ravel())


def run(*args):
    return CliRunner().invoke(main, ["compare", *map(str, args)])


@pytest.fixture()
def pair(tmp_path):
    m = tube_mesh(rings=4, segments=6)
    a, b = tmp_path / "a.obj", tmp_path / "b.obj"
    write_mesh(str(a), m)
    moved = m.with_vertices(m.vertices + [0.0, 0.0, 0.25])
    write_mesh(str(b), moved)
    return m, a, b


def test_same_topology_is_compared_per_vertex(pair, tmp_path):
    m, a, b = pair
    assert run(a, a).exit_code == 0
    r = run(a, b, "--tol", "0.2", "--json", tmp_path / "r.json")
    assert r.exit_code == 7 and "BEYOND" in r.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["mode"] == "per-vertex"
    assert np.isclose(report["max"], 0.25) and np.isclose(report["mean"], 0.25)
    assert run(a, b, "--tol", "0.25").exit_code == 0
    diag = np.linalg.norm(np.ptp(m.vertices, axis=0))
    r = run(a, b, "--relative", "--tol", "0.1", "--json", tmp_path / "r.json")
    assert r.exit_code == 0
    assert np.isclose(json.loads((tmp_path / "r.json").read_text())["max"], 0.25 / diag)


def test_different_topology_uses_surface_distances():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2], [0, 2, 3]])
    fine_V, fine_F = igl.upsample(V, F, 2)
    same = compare_meshes(tri_mesh(V, F), tri_mesh(fine_V, fine_F))
    assert same.mode == "surface" and same.max < 1e-12
    lifted = compare_meshes(tri_mesh(V, F), tri_mesh(fine_V + [0, 0, 0.3], fine_F))
    assert np.isclose(lifted.max, 0.3) and np.isclose(lifted.mean, 0.3)
    # the one home of "relative to the diagonal": sqrt(2) here
    rel = lifted.scaled(True)
    assert np.isclose(rel.max, 0.3 / np.sqrt(2)) and rel.relative and rel.scale == np.sqrt(2)
    assert rel.scaled(False).max == lifted.max and not rel.scaled(False).relative
    assert rel.verdict(0.3 / np.sqrt(2) + 1e-9).within and not rel.verdict(0.2).within
    assert rel.verdict(0.2).beyond == 1.0 and rel.verdict(0.3).beyond == 0.0


def test_compare_runs_from_python_as_the_command_does(pair, tmp_path):
    from srarap_cli.tasks.comparison.job import CompareJob, run_compare
    _, a, b = pair
    done = run_compare(CompareJob(str(a), str(b), tol=1e-9, json=str(tmp_path / "r.json")))
    assert done.exit_code == 7 and not done.verdict.within
    assert json.loads((tmp_path / "r.json").read_text()) == done.figures()
    r = run(a, b, "--tol", "1e-9")
    assert done.summary() in r.stderr


def test_missing_file_is_invalid_input(pair, tmp_path):
    _, a, _ = pair
    r = run(a, tmp_path / "nope.obj")
    assert r.exit_code == 4 and "nope.obj" in r.stderr


def test_meshes_that_do_not_correspond_get_both_one_sided_distances(tmp_path):
    """A: the unit square; B: a 2 x 1 rectangle of another triangulation holding it. Every
    point of A lies on B (A to B: 0), B's far edge is 1 from A (B to A: 1, at 2 of its 4
    vertices: p95 and p99 interpolate between them)."""
    a = tri_mesh(np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]),
                 np.array([[0, 1, 2], [0, 2, 3]]))
    b = tri_mesh(np.array([[0.0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]]),
                 np.array([[0, 1, 3], [1, 2, 3]]))
    found = compare_meshes(a, b)
    sides = found.one_sided
    assert sides["a_to_b"]["max"] < 1e-12 and sides["a_to_b"]["samples"] == 4
    assert np.isclose(sides["b_to_a"]["max"], 1.0) and np.isclose(sides["b_to_a"]["mean"], 0.5)
    assert found.max == sides["b_to_a"]["max"] and "vertex" in sides["sampling"]
    write_mesh(str(tmp_path / "a.obj"), a)
    write_mesh(str(tmp_path / "b.obj"), b)
    r = run(tmp_path / "a.obj", tmp_path / "b.obj", "--tol", "0.5", "--relative",
            "--json", tmp_path / "r.json")
    figures = json.loads((tmp_path / "r.json").read_text())
    diag = np.sqrt(2)
    assert figures["a_to_b"]["max"] < 1e-12 and np.isclose(figures["b_to_a"]["max"], 1 / diag)
    assert "A to B: max 0, B to A: max 0.707" in r.stderr and r.exit_code == 7


def test_percentiles_and_fraction_beyond_tol_gate_from_the_command_line(pair, tmp_path):
    """B is A lifted by 0.25 everywhere: every vertex beyond tol 0.2 (100%), p95 0.25."""
    _, a, b = pair
    r = run(a, b, "--tol", "0.2", "--beyond-tol", "0.5", "--json", tmp_path / "r.json")
    assert r.exit_code == 7 and "100% of the vertices beyond tol 0.2 > beyond_tol 50%" in r.stderr
    figures = json.loads((tmp_path / "r.json").read_text())
    assert figures["beyond_tol"] == 1.0 and np.isclose(figures["p95"], 0.25)
    assert figures["failed"] and figures["status"] == "regressed"
    assert run(a, b, "--tol", "0.3", "--p95", "0.2").exit_code == 7
    assert run(a, b, "--tol", "0.3", "--p99", "0.3").exit_code == 0
    assert run(a, b, "--beyond-tol", "1.5").exit_code == 2


def test_a_golden_from_another_frame_is_aligned_rigidly_first(pair, tmp_path):
    """B is A turned 30 degrees about x and moved: ~0 after --align rigid, and the motion
    that brought it back is said (30 degrees about -x)."""
    m, a, _ = pair
    t = np.radians(30)
    R = np.array([[1, 0, 0], [0, np.cos(t), -np.sin(t)], [0, np.sin(t), np.cos(t)]])
    c = tmp_path / "c.obj"
    write_mesh(str(c), m.with_vertices(m.vertices @ R.T + [3.0, -1.0, 2.0]))
    assert run(a, c, "--tol", "1e-6").exit_code == 7
    r = run(a, c, "--tol", "1e-6", "--align", "rigid", "--json", tmp_path / "r.json")
    assert r.exit_code == 0, r.stderr
    motion = json.loads((tmp_path / "r.json").read_text())["motion"]
    assert np.isclose(motion["angle"], 30) and np.allclose(motion["axis"], [-1, 0, 0])
    assert "B aligned first: turned 30 degrees about (-1, " in r.stderr
    other = tmp_path / "o.obj"
    write_mesh(str(other), tube_mesh(rings=5, segments=6))
    r = run(a, other, "--align", "rigid")
    assert r.exit_code == 2 and "same vertices and faces" in r.stderr


def test_compare_update_writes_the_golden_only_when_missing_or_beyond(pair, tmp_path):
    _, a, b = pair
    golden = tmp_path / "g" / "golden.obj"
    r = run(a, golden, "--tol", "1e-9")
    assert r.exit_code == 4 and "--update writes A there" in r.stderr
    r = run(a, golden, "--tol", "1e-9", "--update", "--junit", tmp_path / "j.xml")
    assert r.exit_code == 8 and "B created from A" in r.stderr
    assert golden.read_bytes() == a.read_bytes()
    assert 'type="no-golden"' in (tmp_path / "j.xml").read_text()
    before = golden.stat().st_mtime_ns
    assert run(a, golden, "--tol", "1e-9", "--update").exit_code == 0
    assert golden.stat().st_mtime_ns == before  # within: kept as it was
    r = run(b, golden, "--tol", "1e-9", "--update", "--json", tmp_path / "r.json")
    assert r.exit_code == 7 and "B updated from A" in r.stderr
    assert json.loads((tmp_path / "r.json").read_text())["golden"] == "updated"
    assert golden.read_bytes() == b.read_bytes()
    r = run(a, golden, "--tol", "1e-9", "--accept")
    assert r.exit_code == 0 and golden.read_bytes() == a.read_bytes()
    r = run(a, a, "--update")
    assert r.exit_code == 4 and "is mesh A; refusing to overwrite an input" in r.stderr
    r = run(a, "-", "--update")
    assert r.exit_code == 2 and "B cannot be '-'" in r.stderr


def test_a_percentage_tolerance_is_of_the_diagonal(pair, tmp_path):
    """Issue 70: --tol 1% was refused though --multires takes percentages."""
    m, a, b = pair
    diag = np.linalg.norm(np.ptp(m.vertices, axis=0))
    at = 100 * 0.25 / diag  # the lift, as a percentage of the diagonal
    assert run(a, b, "--tol", f"{at * 1.01}%").exit_code == 0
    r = run(a, b, "--tol", f"{at * 0.99}%")
    assert r.exit_code == 7 and "of the diagonal" in r.stderr
    assert run(a, b, "--tol", "x%").exit_code == 2 and run(a, b, "--tol", "-1%").exit_code == 2
    from srarap_cli.tasks.comparison.gates import parse_expect
    e = parse_expect({"golden": "g", "tol": "0.5%"}, ValueError)
    assert e.tol == 0.005 and e.relative
