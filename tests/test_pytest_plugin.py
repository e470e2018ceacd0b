"""The pytest plugin (``srarap_cli/pytest_plugin.py``, loaded through its ``pytest11`` entry
point): pytest run on a tiny test project that uses ``mesh_regression``, as a team's suite
would, in a process of its own (no import of the plugin by hand)."""
import re
import xml.etree.ElementTree as ET

import pytest

pytest_plugins = ["pytester"]

PROJECT = '''
import os

import numpy as np
import pytest

import srarap_cli

V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
F = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
SHIFT = float(os.environ.get("SHIFT", "0"))


def test_tet(mesh_regression):
    mesh_regression.check((V + [SHIFT, 0, 0], F), tol=1e-9)


@pytest.mark.parametrize("k", [1, 2])
def test_scaled_ply(mesh_regression, k):
    mesh_regression.check(srarap_cli.Mesh.from_arrays(V * k, F), tol=1e-9, extension=".ply")
'''


@pytest.fixture()
def project(pytester):
    pytester.makepyfile(test_meshes=PROJECT)
    return pytester


def outcome(result):
    return result.parseoutcomes()


@pytest.mark.slow  # eight pytest runs in processes of their own (about 10 s)
@pytest.mark.parametrize("workers", [[], ["-n", "2"]], ids=["plain", "xdist"])
def test_create_pass_fail_on_change_and_rebaseline(project, workers, monkeypatch):
    args = ["-p", "no:cacheprovider", *workers]
    golden = project.path / "test_meshes"
    first = project.runpytest_subprocess(*args)
    assert outcome(first) == {"failed": 3}
    first.stdout.fnmatch_lines(["*mesh_regression: no golden at *test_tet.obj: created*"])
    assert sorted(p.name for p in golden.iterdir()) == [
        "test_scaled_ply_1_.ply", "test_scaled_ply_2_.ply", "test_tet.obj"]
    assert outcome(project.runpytest_subprocess(*args)) == {"passed": 3}

    monkeypatch.setenv("SHIFT", "0.25")  # a deliberate change: one test fails with the verdict
    made = (golden / "test_tet.obj").read_bytes()
    changed = project.runpytest_subprocess(*args, "--junitxml", "j.xml")
    assert outcome(changed) == {"failed": 1, "passed": 2}
    line = next(s for s in changed.outlines if "mesh_regression: BEYOND" in s)
    assert re.search(r"BEYOND tol 1e-09 \(per-vertex\): max 0\.25, .*farthest: golden's vertex "
                     r"\d at .*; 100% of the vertices beyond tol; obtained mesh: .*"
                     r"test_tet\.obtained\.obj", line)
    assert (golden / "test_tet.obtained.obj").exists() and (golden / "test_tet.obj").read_bytes() == made
    case = next(c for c in ET.parse(project.path / "j.xml").getroot().iter("testcase")
                if c.get("name") == "test_tet")
    assert "max 0.25" in case.find("failure").get("message")
    props = {p.get("name"): p.get("value") for p in case.iter("property")}
    assert float(props["mesh_regression.max"]) == pytest.approx(0.25)
    assert props["mesh_regression.beyond_tol"] == "1.0"

    update = project.runpytest_subprocess(*args, "--update-goldens")
    assert outcome(update) == {"failed": 1, "passed": 2}
    update.stdout.fnmatch_lines(["*golden updated: look at it, then rerun*"])
    assert (golden / "test_tet.obj").read_bytes() != made
    assert outcome(project.runpytest_subprocess(*args)) == {"passed": 3}
    assert not (golden / "test_tet.obtained.obj").exists()  # a passing check clears it

    monkeypatch.setenv("SHIFT", "0.5")
    assert outcome(project.runpytest_subprocess(*args, "--accept-goldens")) == {"passed": 3}
    assert outcome(project.runpytest_subprocess(*args)) == {"passed": 3}


@pytest.mark.slow
def test_a_solve_is_gated_on_its_energy_and_iterations(pytester, monkeypatch):
    """A DeformResult brings its energy and iterations: the golden records them, and a
    tighter iteration budget or another energy fails that gate alone, by name."""
    pytester.makepyfile(test_solve=SOLVE)
    pytester.makepyfile(helpers_tube=TUBE)
    args = ["-p", "no:cacheprovider"]
    assert outcome(pytester.runpytest_subprocess(*args)) == {"failed": 1}
    record = (pytester.path / "test_solve" / "test_bend.obj.srarap.json").read_text()
    assert '"iterations"' in record and '"energy"' in record
    assert outcome(pytester.runpytest_subprocess(*args)) == {"passed": 1}
    monkeypatch.setenv("MAXIT", "1")
    tight = pytester.runpytest_subprocess(*args)
    tight.stdout.fnmatch_lines(["*within tol 0.001*; iterations * > max_iterations 1*"])
    monkeypatch.delenv("MAXIT")
    monkeypatch.setenv("DX", "1.1")
    monkeypatch.setenv("TOL", "10")
    other = pytester.runpytest_subprocess(*args)
    other.stdout.fnmatch_lines(["*within tol 10*; energy * is *% from the golden's * > "
                                "energy_rtol 0.1%*"])
    assert "max_iterations" not in next(s for s in other.outlines if "mesh_regression:" in s)


SOLVE = '''
import os

import srarap_cli
from helpers_tube import tube


def test_bend(mesh_regression):
    V, F = tube()
    ids = [i for i, v in enumerate(V) if v[2] < 0.1 or v[2] > 5.9]
    dx = float(os.environ.get("DX", "1"))
    targets = V[ids] + [[dx if V[i][2] > 5.9 else 0.0, 0, 0] for i in ids]
    result = srarap_cli.deform((V, F), (ids, targets), tol=1e-8)
    mesh_regression.check(result, tol=float(os.environ.get("TOL", "1e-3")), energy_rtol=1e-3,
                          max_iterations=int(os.environ.get("MAXIT", "1000")))
'''


TUBE = '''
import numpy as np

def tube(length=6.0, rings=12, segments=8):
    t = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    z = np.linspace(0, length, rings)
    V = np.array([[np.cos(a), np.sin(a), h] for h in z for a in t])
    F = []
    for r in range(rings - 1):
        for s in range(segments):
            a, b = r * segments + s, r * segments + (s + 1) % segments
            F += [[a, b, a + segments], [b, b + segments, a + segments]]
    return V, np.array(F)
'''
