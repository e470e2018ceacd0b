"""Reading and writing meshes: order, polygons, UVs, normals, determinism."""
import glob
import os
import re

import meshio
import numpy as np
import pytest
from helpers import ROOT, SHARED, needs_shared, tube_mesh

from srarap_cli.io.mesh import FORMATS, Mesh, format_mesh, read_mesh, write_mesh
from srarap_cli.io.mesh.normals import recompute_normals
from srarap_cli.runtime.errors import InputError
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix


def same_structure(a, b):
    assert np.array_equal(a.face_sizes, b.face_sizes)
    assert np.array_equal(a.face_vertices, b.face_vertices)


@pytest.mark.parametrize("suffix", [".obj", ".off", ".ply"])
def test_round_trip_keeps_vertices_and_polygons_exactly(tmp_path, suffix):
    mesh = tube_mesh(rings=3, segments=5)
    mesh.vertices = mesh.vertices + np.random.default_rng(0).normal(size=mesh.vertices.shape)
    path = str(tmp_path / f"m{suffix}")
    write_mesh(path, mesh)
    back = read_mesh(path)
    assert np.array_equal(back.vertices, mesh.vertices)  # 17 significant digits / binary
    same_structure(back, mesh)


def _triangles_in_space(mesh):
    """The mesh's triangles as sorted corner coordinates: what every format keeps, whatever
    it does to vertex order (STL welds corners) or polygons (split into triangles)."""
    corners = mesh.vertices[mesh.triangles()[0]]
    return sorted(tuple(sorted(map(tuple, t))) for t in corners.tolist())


@pytest.mark.parametrize("name", sorted(FORMATS))
def test_every_registered_format_keeps_the_surface(name, tmp_path):
    """Every format of the table, the meshio ones included: the triangles come back at the
    same coordinates (single-precision values, which STL stores exactly)."""
    tube = tube_mesh(rings=3, segments=5)
    V = (tube.vertices + np.random.default_rng(1).normal(size=tube.vertices.shape))
    mesh = Mesh.from_arrays(V.astype(np.float32).astype(float), tube.triangles()[0])
    path = tmp_path / f"m{FORMATS[name].extension}"
    write_mesh(path, mesh)
    assert _triangles_in_space(read_mesh(path)) == _triangles_in_space(mesh)


def test_obj_keeps_uv_seams_normals_and_other_statements(tmp_path):
    src = tmp_path / "in.obj"
    src.write_text("mtllib a.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                   "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\nvn 0 0 1\n"
                   "usemtl red\nf 1/1/1 2/2/1 3/3/1\nusemtl blue\nf -4/5/1 -2/4/1 -1/4/1\n"
                   "f 1 3 4\n")
    mesh = read_mesh(str(src))
    assert mesh.uv.shape == (5, 2) and mesh.normals.shape == (1, 3)
    assert mesh.face_vertices.tolist() == [0, 1, 2, 0, 2, 3, 0, 2, 3]
    assert mesh.face_uv.tolist() == [0, 1, 2, 4, 3, 3, -1, -1, -1]
    text = format_mesh(mesh, ".obj")[0].decode()
    assert text.index("usemtl red") < text.index("f 1/1/1") < text.index("usemtl blue")
    assert "f 1/5/1 3/4/1 4/4/1" in text and "f 1 3 4" in text and "mtllib a.mtl" in text
    out = tmp_path / "out.obj"
    write_mesh(str(out), mesh)
    again = read_mesh(str(out))
    assert np.array_equal(again.face_uv, mesh.face_uv) and np.array_equal(again.uv, mesh.uv)


def test_off_reader_takes_headers_meshio_rejects(tmp_path):
    path = tmp_path / "a.off"
    path.write_text("OFF\n# comment\n4  2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3 255 0 0\n")
    mesh = read_mesh(str(path))
    assert mesh.vertices.shape == (4, 3) and mesh.face_vertices.tolist() == [0, 1, 2, 0, 2, 3]


def test_ply_output_is_valid_for_meshio_and_carries_per_vertex_uv(tmp_path):
    mesh = tube_mesh(rings=2, segments=4)
    mesh.face_uv = mesh.face_vertices.copy()
    mesh.uv = mesh.vertices[:, :2] * 0.5
    path = str(tmp_path / "m.ply")
    assert write_mesh(path, mesh) == []
    m = meshio.read(path)
    assert np.array_equal(m.points, mesh.vertices)
    assert np.array_equal(np.concatenate([c.data.ravel() for c in m.cells]), mesh.face_vertices)
    assert np.array_equal(m.point_data["s"], mesh.uv[:, 0])


def test_formats_without_per_corner_uvs_say_what_they_drop(tmp_path):
    mesh = tube_mesh(rings=2, segments=4)  # UV seam: several uvs per vertex
    assert "texture coordinates not written" in write_mesh(str(tmp_path / "m.off"), mesh)[0]


def test_normals_follow_the_deformation():
    mesh = read_mesh(os.path.join(ROOT, "sample_meshes", "spot.obj"))
    R = to_matrix(from_axis_angle([1, 2, 3], 77))
    moved = mesh.with_vertices(mesh.vertices @ R.T)
    assert np.abs(moved.normals - recompute_normals(mesh) @ R.T).max() < 1e-12
    assert np.allclose(np.linalg.norm(moved.normals, axis=1), 1)


@pytest.mark.slow
def test_output_bytes_are_deterministic(tmp_path):
    mesh = read_mesh(os.path.join(ROOT, "sample_meshes", "spot.obj"))
    for fmt in FORMATS.values():
        assert format_mesh(mesh, fmt.extension)[0] == format_mesh(read_mesh(
            os.path.join(ROOT, "sample_meshes", "spot.obj")), fmt.extension)[0], fmt.name


@needs_shared
def test_every_shared_mesh_reads_with_its_vertex_count():
    assert os.path.isdir(SHARED), "the tests expect ../shared/meshes beside the repository"
    counts = {"cylinder.off": 4802, "decimated-max.obj": 5272, "spot.obj": 11533,
              "torus.obj": 2304, "hand_lowres.obj": 810, "armadillo1.obj": 502}
    found = {os.path.basename(p): p for p in glob.glob(os.path.join(SHARED, "*.o[bf][jf]"))}
    assert set(counts) <= set(found)
    for name, n in counts.items():
        assert len(read_mesh(found[name]).vertices) == n


@pytest.mark.parametrize("text, message", [
    ("", "no vertices"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "references vertex 3"),
    ("v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n", "vertex 1 has a NaN"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "index 0"),
    ("v 0 0\nf 1 2 3\n", "malformed 'v'"),
])
def test_bad_obj_files_are_invalid_input(tmp_path, text, message):
    path = tmp_path / "bad.obj"
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        read_mesh(str(path))


@pytest.mark.parametrize("name, data", [
    ("garbage.ply", b"garbage"),
    ("short.ply", b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\n"),
    ("cut.stl", b"solid x\nfacet normal 0 0 1\n"),
])
def test_broken_ply_and_stl_are_invalid_input(tmp_path, capfd, name, data):
    path = tmp_path / name
    path.write_bytes(data)
    with pytest.raises(InputError, match=name):
        read_mesh(str(path))
    assert capfd.readouterr() == ("", "")  # meshio's own printing is swallowed


def test_truncated_off_and_unknown_format_are_invalid_input(tmp_path):
    path = tmp_path / "t.off"
    path.write_text("OFF\n4 2 0\n0 0 0\n1 0 0\n")
    with pytest.raises(InputError, match="ends early"):
        read_mesh(str(path))
    # an extension no format claims: the content decides, and text of no format is refused
    (tmp_path / "x.xyz").write_text("# points\n0 0 0\n1 0 0 x\n")
    with pytest.raises(InputError, match="x.xyz: not a mesh: it is text"):
        read_mesh(str(tmp_path / "x.xyz"))
    with pytest.raises(InputError, match="y.xyz: cannot read: No such file"):
        read_mesh(str(tmp_path / "y.xyz"))


@pytest.mark.parametrize("binary", [True, False])
def test_stl_corners_are_welded_into_shared_vertices(tmp_path, binary):
    mesh = tube_mesh(rings=3, segments=5)
    F = mesh.triangles()[0]
    path = str(tmp_path / "t.stl")
    meshio.write(path, meshio.Mesh(mesh.vertices, [("triangle", F)]), binary=binary)
    back = read_mesh(path)
    assert len(back.vertices) == len(mesh.vertices) and back.face_sizes.size == len(F)
    tri = back.vertices[back.face_vertices.reshape(-1, 3)]
    assert np.allclose(np.sort(tri.reshape(-1, 9), axis=0),
                       np.sort(mesh.vertices[F].reshape(-1, 9).astype(np.float32), axis=0))


@pytest.mark.parametrize("binary", [True, False])
def test_stl_reads_the_same_vertices_in_the_same_order_as_meshio(tmp_path, binary):
    """meshio (a test dependency only) is the independent reader: same welding, same order."""
    from srarap_cli.io.mesh.stl import read_stl
    spot = read_mesh(os.path.join(ROOT, "sample_meshes", "spot.obj"))
    path = str(tmp_path / "spot.stl")
    meshio.write(path, meshio.Mesh(spot.vertices, [("triangle", spot.triangles()[0])]),
                 binary=binary)
    ours, theirs = read_stl(path), meshio.read(path)
    assert np.array_equal(ours.vertices, theirs.points)
    assert np.array_equal(ours.face_vertices.reshape(-1, 3), theirs.cells[0].data)


@pytest.mark.parametrize("text, message", [
    ("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
     "endloop\nendfacet\n", "does not end with 'endsolid'"),
    ("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
     "endloop\nendfacet\nendsolid t\n", "facet 0 is incomplete"),
    ("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
     "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
     "vertx 0 1 1\nendloop\nendfacet\nendsolid t\n", "facet 1: expected 'vertex'"),
    ("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 zero 0\nvertex 0 1 0\n"
     "endloop\nendfacet\nendsolid t\n", "not a number"),
    ("\x00" * 100, "does not match its triangle count"),
])
def test_broken_stl_is_refused_with_what_is_wrong(tmp_path, text, message):
    path = tmp_path / "broken.stl"
    path.write_text(text)
    with pytest.raises(InputError, match=re.escape(message)):
        read_mesh(str(path))


def test_ascii_stl_welds_shared_corners_and_keeps_its_name_tokens(tmp_path):
    path = tmp_path / "two.stl"
    facet = "facet normal 0 0 1\n outer loop\n  vertex {}\n  vertex {}\n  vertex {}\n endloop\nendfacet\n"
    path.write_text("solid my part\n" + facet.format("0 0 0", "1 0 0", "0 1 0")
                    + facet.format("1 0 0", "1 1 0", "0 1 0") + "endsolid my part\n")
    mesh = read_mesh(str(path))
    assert mesh.vertices.tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]
    assert mesh.face_vertices.tolist() == [0, 1, 2, 1, 3, 2]


@pytest.mark.parametrize("sizes", [[3, 3, 3], [4, 4], [3, 4, 5]])
def test_ply_face_records_are_a_count_byte_then_int32_ids(sizes):
    import struct

    from srarap_cli.io.mesh.mesh import Mesh
    from srarap_cli.io.mesh.ply import _face_bytes
    ids = np.arange(sum(sizes)) * 7919 % 100_003
    mesh = Mesh(vertices=np.zeros((100_003, 3)), face_sizes=np.array(sizes),
                face_vertices=ids)
    expected, at = b"", 0
    for k in sizes:
        expected += struct.pack(f"<B{k}i", k, *ids[at:at + k].tolist())
        at += k
    assert _face_bytes(mesh) == expected
