"""The formats meshio adds (``srarap-cli[meshio]``): every one registered writes and reads
back the sample bar's triangles and quads exactly and deterministically, deform works from
and to them like the native four, and without meshio their files are refused in one line
that names the extra."""
import os
import subprocess
import sys

import numpy as np
import pytest
from helpers import ROOT, run_cli

from srarap_cli.io.mesh import FORMATS, Mesh, read_mesh, write_mesh
from srarap_cli.io.mesh.meshio_formats import TABLE

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
TWIST = os.path.join(ROOT, "configs", "bar-twist.yaml")
ADDED = [name for name in FORMATS if name in TABLE]


def test_every_format_of_the_table_is_registered_when_meshio_is_here():
    assert ADDED == list(TABLE)  # their modules are all installed with the test extra


@pytest.mark.parametrize("name", ADDED)
@pytest.mark.parametrize("faces", ["triangles", "triangles and quads"])
def test_a_format_writes_and_reads_back_exactly_and_deterministically(name, faces, tmp_path):
    bar = read_mesh(BAR)
    mesh = (Mesh.from_arrays(bar.vertices, bar.triangles()[0]) if faces == "triangles" else
            Mesh(vertices=bar.vertices, face_sizes=bar.face_sizes,
                 face_vertices=bar.face_vertices))
    mesh.vertex_data["weight"] = np.linspace(0, 1, len(mesh.vertices))
    path = tmp_path / f"m{FORMATS[name].extension}"
    lost = write_mesh(path, mesh)
    keeps = FORMATS[name].keeps_vertex_data
    assert lost == [] if keeps else "per-vertex data (weight) not written" in lost[0]
    first = path.read_bytes()
    write_mesh(path, mesh)
    assert path.read_bytes() == first
    back = read_mesh(path)
    assert np.array_equal(back.vertices, mesh.vertices)
    assert sorted(map(tuple, _faces(back))) == sorted(map(tuple, _faces(mesh)))
    if keeps:
        assert np.array_equal(back.vertex_data["weight"], mesh.vertex_data["weight"])


def _faces(mesh):
    offsets = np.concatenate([[0], np.cumsum(mesh.face_sizes)])
    return [tuple(mesh.face_vertices[a:b]) for a, b in zip(offsets, offsets[1:])]


def test_deform_reads_and_writes_a_vtu_as_it_does_an_obj(tmp_path):
    part = tmp_path / "part.vtu"
    write_mesh(part, read_mesh(BAR))
    r = run_cli(["deform", part, TWIST, "-o", tmp_path / "out.vtu", "-q"])
    assert r.returncode == 0, r.stderr
    ref = run_cli(["deform", BAR, TWIST, "-o", tmp_path / "ref.obj", "-q"])
    assert ref.returncode == 0
    assert np.allclose(read_mesh(tmp_path / "out.vtu").vertices,
                       read_mesh(tmp_path / "ref.obj").vertices, atol=1e-12)


def test_a_volume_mesh_is_refused_in_one_line(tmp_path):
    import meshio

    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    meshio.write(tmp_path / "tet.vtu", meshio.Mesh(points, [("tetra", [[0, 1, 2, 3]])]))
    r = run_cli(["info", tmp_path / "tet.vtu"])
    assert r.returncode == 4 and "no triangle or quad cells (cells: tetra)" in r.stderr


@pytest.mark.slow
def test_without_meshio_its_formats_are_refused_naming_the_extra(tmp_path):
    write_mesh(tmp_path / "part.vtu", read_mesh(BAR))
    hide = ("import sys; sys.modules['meshio'] = None; sys.argv[0] = 'srarap'; "
            "from srarap_cli.cli import main; main()")
    for args in (["deform", "part.vtu", TWIST, "-o", "out.obj"],
                 ["deform", BAR, TWIST, "-o", "out.vtu"]):
        p = subprocess.run([sys.executable, "-c", hide, *args], cwd=tmp_path,
                           capture_output=True, text=True, timeout=300)
        assert p.returncode == 4 and p.stderr.count("\n") == 1, p.stderr
        assert "VTU files need meshio: pip install 'srarap-cli[meshio]'" in p.stderr
    assert not (tmp_path / "out.obj").exists() and not (tmp_path / "out.vtu").exists()
