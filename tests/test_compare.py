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
