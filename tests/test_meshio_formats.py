"""The formats meshio adds (``srarap-cli[meshio]``): every one registered writes and reads
back the sample bar's triangles and quads exactly and deterministically, deform works from
and to them like the native four, and without meshio their files are refused in one line
that names the extra."""
import os
import subprocess
import sys
import time

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
def test_a_format_writes_and_reads_back_exactly(name, faces, tmp_path, capsys):
    bar = read_mesh(BAR)
    mesh = (Mesh.from_arrays(bar.vertices, bar.triangles()[0]) if faces == "triangles" else
            Mesh(vertices=bar.vertices, face_sizes=bar.face_sizes,
                 face_vertices=bar.face_vertices))
    mesh.vertex_data["weight"] = np.linspace(0, 1, len(mesh.vertices))
    path = tmp_path / f"m{FORMATS[name].extension}"
    lost = write_mesh(path, mesh)
    keeps, split = FORMATS[name].keeps_vertex_data, faces != "triangles" and not TABLE[name].quads
    assert [w for w in lost if "per-vertex" in w] == ([] if keeps else [
        f"per-vertex data (weight) not written: {name.upper()} does not keep them (.ply "
        "does) [format-drops]"])
    assert all(w.code == "format-drops" for w in lost)
    assert ["quads written as triangles" in w for w in lost].count(True) == split
    back = read_mesh(path)
    assert np.array_equal(back.vertices, mesh.vertices)
    expected = Mesh.from_arrays(mesh.vertices, mesh.triangles()[0]) if split else mesh
    assert sorted(map(tuple, _faces(back))) == sorted(map(tuple, _faces(expected)))
    assert back.vertex_data.keys() == ({"weight"} if keeps else set())
    assert capsys.readouterr() == ("", "")  # meshio's own console notes are not printed
    if keeps:
        assert np.array_equal(back.vertex_data["weight"], mesh.vertex_data["weight"])


@pytest.mark.slow
def test_every_format_writes_the_same_bytes_a_second_later(tmp_path):
    """Determinism, where a writer stamps the time (Exodus, H5M) or gzip the mtime."""
    bar = read_mesh(BAR)
    first = {}
    for name in ADDED:
        write_mesh(tmp_path / f"m{FORMATS[name].extension}", bar)
        first[name] = (tmp_path / f"m{FORMATS[name].extension}").read_bytes()
    time.sleep(1.01)
    for name in ADDED:
        write_mesh(tmp_path / f"m{FORMATS[name].extension}", bar)
    assert [n for n in ADDED if (tmp_path / f"m{FORMATS[n].extension}").read_bytes() != first[n]] == []


@pytest.mark.parametrize("name", ADDED)
def test_a_file_that_is_not_of_its_format_is_one_line_and_exit_4(name, tmp_path):
    for i, junk in enumerate([b"", b"solid x\n" * 3, bytes(range(256)) * 8]):
        path = tmp_path / f"junk{i}{FORMATS[name].extension}"
        path.write_bytes(junk)
        r = run_cli(["info", path])
        assert r.returncode == 4 and r.stderr.count("\n") == 1, (name, junk[:10], r.stderr)
        assert str(path) in r.stderr


def test_a_quad_with_a_repeated_corner_is_a_triangle(tmp_path):
    """Tecplot writes a mixed mesh as quads, a triangle's last corner twice (other FE
    formats do the same): read back, it is the triangle again."""
    import meshio

    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0]])
    quads = [[0, 1, 2, 2], [1, 3, 2, 1], [1, 4, 3, 3], [0, 0, 1, 2]]
    meshio.write(tmp_path / "q.vtu", meshio.Mesh(points, [("quad", quads)]))
    back = read_mesh(tmp_path / "q.vtu")
    assert _faces(back) == [(0, 1, 2), (1, 3, 2), (1, 4, 3), (0, 1, 2)]


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


@pytest.mark.slow
def test_without_h5py_its_formats_are_refused_and_the_others_work(tmp_path):
    hide = ("import sys; sys.modules['h5py'] = None; sys.argv[0] = 'srarap'; "
            "from srarap_cli.cli import main; main()")
    for out, code in (("out.xdmf", 4), ("out.vol.gz", 0)):
        p = subprocess.run([sys.executable, "-c", hide, "deform", BAR, TWIST, "-o", out, "-q"],
                           cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert p.returncode == code, p.stderr
    assert ("XDMF files need meshio, h5py: pip install 'srarap-cli[meshio]'" in p.stderr
            or not (tmp_path / "out.xdmf").exists())
    assert not (tmp_path / "out.xdmf").exists() and (tmp_path / "out.vol.gz").exists()


def test_a_two_part_extension_names_its_format():
    from srarap_cli.io.mesh.formats import by_extension, suffix_of

    assert by_extension("out/Part.VOL.GZ").name == "netgen-gz"
    assert by_extension("part.vol").name == "netgen" and by_extension("notes.gz") is None
    assert suffix_of("a.b/c.post.gz") == ".post.gz" and suffix_of("a.b/c") == ""


@pytest.mark.parametrize("name", ["vtu", "vtk", "gmsh", "xdmf"])
def test_what_a_format_drops_is_said(name, tmp_path):
    """Issue 60: an OBJ's texture coordinates and normals went to .vtu, .vtk, .msh and .xdmf
    without a word (OFF, PLY and STL said it), so --strict could not catch it."""
    from helpers import tube_mesh

    mesh = tube_mesh(rings=4, segments=6)  # quads and triangle fans, with texture coordinates
    mesh.normals, mesh.face_normals = np.tile([0.0, 0.0, 1.0], (1, 1)), \
        np.zeros(len(mesh.face_vertices), dtype=np.int64)
    lost = write_mesh(tmp_path / f"m{FORMATS[name].extension}", mesh)
    assert any(w.startswith("texture coordinates") and "not written" in w for w in lost), lost
    assert any(w.startswith("normals not written") for w in lost), lost


@pytest.mark.parametrize("name", ["vtu", "gmsh"])
def test_one_pentagon_among_quads_splits_only_itself(name, tmp_path):
    """Issue 60: one pentagon turned every quad into two triangles, while the warning named
    only the large polygons."""
    side = 6
    grid = np.array([[x, y, 0.0] for y in range(side) for x in range(side)])
    quads = [[y * side + x, y * side + x + 1, (y + 1) * side + x + 1, (y + 1) * side + x]
             for y in range(side - 1) for x in range(side - 1)]
    quads[0] = [0, 1, 7, 6]
    extra = np.vstack([grid, [[0.5, -0.5, 0.0]]])  # a pentagon in place of the first quad
    faces = [[0, len(grid), 1, 7, 6]] + quads[1:]
    mesh = Mesh(vertices=extra, face_sizes=np.array([len(f) for f in faces]),
                face_vertices=np.concatenate(faces))
    lost = write_mesh(tmp_path / f"m{FORMATS[name].extension}", mesh)
    assert lost == [f"1 polygons of more than 4 corners written as triangles ({name.upper()} "
                    "keeps triangles and quads) [format-drops]"]
    back = read_mesh(tmp_path / f"m{FORMATS[name].extension}")
    assert (back.face_sizes == 4).sum() == len(quads) - 1 and (back.face_sizes == 3).sum() == 3


def test_a_full_temporary_folder_names_itself_and_tmpdir(tmp_path, monkeypatch):
    """meshio writes a file: a full TMPDIR said "No space left on device" naming nothing
    (issue 61)."""
    import errno
    import tempfile

    from srarap_cli.runtime.errors import OutputError

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(tempfile, "TemporaryDirectory", full)
    with pytest.raises(OutputError, match=r"cannot write the VTU file meshio makes there "
                       r"\(No space left on device\); set TMPDIR"):
        FORMATS["vtu"].encode(read_mesh(BAR))


def test_an_unconverged_run_that_writes_no_mesh_does_not_encode_it(tmp_path, monkeypatch):
    """... and such a run ended in exit 6 there, where it writes no mesh (exit 3)."""
    from srarap_cli.io.mesh.formats import MeshFormat

    def refuse(self, mesh, ascii=False):
        raise AssertionError("encoded a mesh that is not written")

    monkeypatch.setattr(MeshFormat, "encode", refuse)
    r = run_cli(["deform", BAR, TWIST, "-o", tmp_path / "o.vtu", "--max-iter", "2"])
    assert r.returncode == 3, r.stderr
    assert not (tmp_path / "o.vtu").exists()
