"""Pipes and output formats: '-' is read by every command that reads a mesh, the output
format follows --format else the input's, binary STL and ASCII PLY are written and read back."""
import subprocess
import sys

import numpy as np
import pytest
from helpers import ROOT

from srarap_cli.io.mesh import format_mesh, read_mesh

BAR = f"{ROOT}/sample_meshes/bar.obj"
TWIST = f"{ROOT}/configs/bar-twist.yaml"


def _srarap(*args, stdin=None):
    return subprocess.run([sys.executable, "-m", "srarap_cli", *args], input=stdin,
                          capture_output=True, timeout=120)


@pytest.mark.slow
def test_standard_output_takes_the_inputs_format_without_format(tmp_path):
    p = _srarap("deform", BAR, TWIST, "-o", "-")
    assert p.returncode == 0 and p.stdout.startswith(b"# written by srarap\nv ")
    off = tmp_path / "bar.off"
    off.write_bytes(format_mesh(read_mesh(BAR), ".off")[0])
    p = _srarap("deform", "-", TWIST, "-o", "-", "--input-format", "off", stdin=off.read_bytes())
    assert p.returncode == 0 and p.stdout.startswith(b"OFF")
    p = _srarap("deform", BAR, TWIST, "-o", "-", "--format", "ply")
    assert p.returncode == 0 and p.stdout.startswith(b"ply\nformat binary_little_endian")


def test_binary_stl_and_ascii_ply_read_back_as_written(tmp_path):
    a = _srarap("deform", BAR, TWIST, "-o", str(tmp_path / "a.obj"), "-q")
    s = _srarap("deform", BAR, TWIST, "-o", str(tmp_path / "a.stl"), "-q")
    p = _srarap("deform", BAR, TWIST, "-o", str(tmp_path / "a.ply"), "--ascii", "-q")
    assert a.returncode == s.returncode == p.returncode == 0
    obj = read_mesh(str(tmp_path / "a.obj"))
    ply = read_mesh(str(tmp_path / "a.ply"))
    assert (tmp_path / "a.ply").read_bytes().startswith(b"ply\nformat ascii 1.0\n")
    np.testing.assert_array_equal(ply.vertices, obj.vertices)  # repr round-trips exactly
    assert np.array_equal(ply.face_vertices, obj.face_vertices)
    stl = read_mesh(str(tmp_path / "a.stl"))
    F = obj.triangles()[0]
    assert len(stl.face_sizes) == len(F)
    np.testing.assert_allclose(stl.vertices[stl.face_vertices].reshape(-1, 3),
                               obj.vertices[F].reshape(-1, 3), atol=1e-6)  # float32
    assert b"written as triangles (STL keeps triangles)" in s.stderr


def test_ascii_applies_to_ply_only(tmp_path):
    p = _srarap("deform", BAR, TWIST, "-o", str(tmp_path / "a.obj"), "--ascii")
    assert p.returncode == 2 and b"--ascii applies to PLY" in p.stderr


@pytest.mark.slow
@pytest.mark.parametrize("args", [
    ["info", "-", "--input-format", "obj"],
    ["compare", "-", BAR, "--input-format", "obj"],
    ["render", "-", "--input-format", "obj", "-o", "{tmp}/r.png", "--size", "64x48"],
])
def test_commands_that_read_a_mesh_read_standard_input(tmp_path, args):
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    p = _srarap(*args, stdin=open(BAR, "rb").read())
    assert p.returncode == 0, p.stderr
    if args[0] == "compare":
        assert b"within tol 0" in p.stderr
