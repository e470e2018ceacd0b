"""Bad or awkward input: a clear error and a documented exit code, or a warned, finite solve."""
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from helpers import ROOT, tube_mesh

from srarap_cli.cli import main
from srarap_cli.io.mesh import read_mesh

BASE = {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True}
TIP = {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]}, "translate": [1.0, 0, 0]}


def run(*args, env=None):
    return CliRunner(env=env).invoke(main, ["deform", *map(str, args)])


def write_obj(path, V, F):
    path.write_text("".join("v {:.17g} {:.17g} {:.17g}\n".format(*v) for v in V)
                    + "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in F))


def handles(tmp_path, groups=None):
    path = tmp_path / "h.yaml"
    path.write_text(yaml.safe_dump({"groups": groups or {"base": BASE, "tip": TIP}}))
    return path


@pytest.fixture()
def tube(tmp_path):
    m = tube_mesh(rings=6, segments=6)
    return m.vertices, m.triangles()[0]


def test_awkward_triangles_are_solved_finitely_and_counted(tmp_path, tube):
    V, F = tube
    n = len(V)
    extra_v = np.array([[3.0, 0, 3], [4.0, 0, 3], [3.5, 1e-7, 3], [3.0, 1, 3], [4.0, 1, 3],
                        [3.5, 0, 3], [5.0, 0, 3], [5.0, 1, 3], [6.0, 0, 3], [6.0, 1, 3]])
    V2 = np.vstack([V, extra_v])
    needle = [n, n + 1, n + 2]
    fan = [[n, n + 1, n + 3], [n, n + 1, n + 4]]  # edge (n, n+1) now has three faces
    flat = [n, n + 5, n + 1]  # three distinct collinear points
    bowtie = [[n + 6, n + 7, n + 8], [n + 6, n + 8, n + 9], [n + 6, n + 1, n + 4]]
    F2 = np.vstack([F, F[:2], needle, fan, [[n, n, n + 1]], flat, bowtie])
    write_obj(tmp_path / "m.obj", V2, F2)
    groups = {"base": BASE, "tip": TIP, "extra": {"indices": [n], "fixed": True}}
    r = run(tmp_path / "m.obj", handles(tmp_path, groups), "-o", tmp_path / "o.obj")
    assert r.exit_code in (0, 3), r.output
    for text in ("2 duplicate faces", "1 needle faces", "1 non-manifold edges",
                 "1 faces repeat a vertex", "1 zero-area faces", "non-manifold vertices"):
        assert text in r.stderr
    out = read_mesh(str(tmp_path / "o.obj")).vertices
    assert np.isfinite(out).all() and len(out) == len(V2)


def test_unreferenced_vertices_and_unconstrained_parts_stay_at_rest(tmp_path, tube):
    V, F = tube
    V2 = np.vstack([V, V + [10, 0, 0], [[50.0, 50, 50]]])
    F2 = np.vstack([F, F + len(V)])
    write_obj(tmp_path / "m.obj", V2, F2)
    groups = {"base": BASE, "tip": {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]},
                                    "translate": [1.0, 0, 0]}}
    r = run(tmp_path / "m.obj", handles(tmp_path, groups), "-o", tmp_path / "o.obj")
    assert r.exit_code == 0, r.output
    out = read_mesh(str(tmp_path / "o.obj")).vertices
    assert np.array_equal(out[len(V):], V2[len(V):])
    assert "1 unreferenced vertices (in no triangle): 1 kept at rest, 0 constrained" in r.stderr
    assert "1 connected part(s) without a constrained vertex" in r.stderr


def test_the_unreferenced_warning_counts_those_in_handle_groups_too(tmp_path, tube):
    V, F = tube
    V2 = np.vstack([V, [[0.0, 0, 6.0], [50.0, 50, 50]]])  # one in the tip box, one far away
    write_obj(tmp_path / "m.obj", V2, F)
    groups = {"base": BASE, "tip": {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]},
                                    "translate": [1.0, 0, 0]}}
    r = run(tmp_path / "m.obj", handles(tmp_path, groups), "-o", tmp_path / "o.obj")
    assert r.exit_code == 0, r.output
    assert "2 unreferenced vertices (in no triangle): 1 kept at rest, 1 constrained ones " \
        "placed at their targets" in r.stderr
    out = read_mesh(str(tmp_path / "o.obj")).vertices
    assert np.allclose(out[len(V)], [1.0, 0, 6.0]) and np.array_equal(out[-1], V2[-1])


def test_coordinates_beyond_double_precision_are_refused_with_no_output(tmp_path, tube):
    V, F = tube
    write_obj(tmp_path / "m.obj", V * 1e160, F)
    groups = {"base": {"indices": [0, 1, 2], "fixed": True},
              "tip": {"indices": [len(V) - 1], "translate": [1e160, 0, 0]}}
    out = tmp_path / "o.obj"
    r = run(tmp_path / "m.obj", handles(tmp_path, groups), "-o", out)
    assert r.exit_code == 4, r.output
    assert "rescale the mesh" in r.stderr and not out.exists()


@pytest.mark.parametrize("text, message", [
    ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n", "references vertex -1"),
    ("OFF\n3 1 0\n0 0 0\n1 0 inf\n0 1 0\n3 0 1 2\n", "vertex 1 has a NaN or infinite"),
    ("OFF\n3 1 0\n0 0 0\n", "ends early"),
    ("PLY\n", "not an OFF file"),
    ("", "empty file"),
])
def test_broken_mesh_files_are_invalid_input(tmp_path, text, message):
    (tmp_path / "m.off").write_text(text)
    r = run(tmp_path / "m.off", handles(tmp_path), "-o", tmp_path / "o.obj")
    assert r.exit_code == 4 and message in r.stderr and "Traceback" not in r.output


def test_unreadable_mesh_is_invalid_input(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text("v 0 0 0\n")
    path.chmod(0)
    if os.access(path, os.R_OK):  # running as root: permissions do not stop reads
        path = tmp_path / "folder.obj"
        path.mkdir()
    r = run(path, handles(tmp_path), "-o", tmp_path / "o.obj")
    assert r.exit_code == 4 and "Traceback" not in r.output


def test_sel_of_the_wrong_length_is_invalid_input(tmp_path, tube):
    V, F = tube
    write_obj(tmp_path / "m.obj", V, F)
    (tmp_path / "h.sel").write_text("0\n2\n1\n")
    (tmp_path / "h.def").write_text("1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n")
    r = run(tmp_path / "m.obj", tmp_path / "h.sel", "-o", tmp_path / "o.obj")
    assert r.exit_code == 4 and "has 3 entries but the mesh has" in r.stderr


def test_a_mesh_that_would_not_fit_is_refused_early(tmp_path, tube):
    V, F = tube
    write_obj(tmp_path / "m.obj", V, F)
    r = run(tmp_path / "m.obj", handles(tmp_path), "-o", tmp_path / "o.obj",
            env={"SRARAP_MEMORY_LIMIT": "20000"})
    assert r.exit_code == 4
    # 20 kB allowed: the amounts in kB, not "0.0 GB" of "0.0 GB"
    assert "needs about" in r.stderr and "kB of memory, 20 kB available" in r.stderr
    assert not (tmp_path / "o.obj").exists()


@pytest.mark.slow
@pytest.mark.parametrize("sig, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_killed_run_leaves_the_old_output_whole(tmp_path, sig, code):
    """Kill a long deform mid-iteration: exit code says so, the old output is untouched and
    no temporary file is left."""
    out = tmp_path / "out.obj"
    out.write_text("old result\n")
    log = tmp_path / "log.csv"
    cmd = [sys.executable, "-m", "srarap_cli", "deform",
           os.path.join(ROOT, "sample_meshes", "spot.obj"),
           os.path.join(ROOT, "configs", "spot-nod.yaml"), "-o", str(out), "--log", str(log),
           "--tol", "0", "--max-iter", "100000"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(4.0)  # loading and precomputation take about a second; then it iterates
    assert proc.poll() is None
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == code, err
    assert "no output written" in err and "Traceback" not in err
    assert out.read_text() == "old result\n" and not log.exists()
    assert [p.name for p in tmp_path.iterdir()] == ["out.obj"]


def test_debug_shows_the_traceback_and_the_default_does_not(tmp_path):
    missing = tmp_path / "missing.obj"
    quiet = CliRunner().invoke(main, ["deform", str(missing), str(handles(tmp_path)), "-o",
                                      str(tmp_path / "o.obj")])
    loud = CliRunner().invoke(main, ["--debug", "deform", str(missing), str(handles(tmp_path)),
                                     "-o", str(tmp_path / "o.obj")])
    assert quiet.exit_code == loud.exit_code == 4
    assert "Traceback" not in quiet.stderr and "Traceback" in loud.stderr
