"""Every format against what it declares it keeps (issue 72): each kind of data a mesh may
hold beyond positions and triangles (``io/mesh/keeps.KINDS``) is written in every
registered format; a kind the format keeps comes back as it was written, and one it does not
keep is said in a ``format-drops`` warning. Generated from the declarations, so a new format
that drops data without saying so, or a warning removed, fails here."""
import numpy as np
import pytest

from srarap_cli.io.mesh import FORMATS, Mesh, read_mesh, write_mesh
from srarap_cli.io.mesh.keeps import KINDS, held

SQUARE = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0]])


def _holding(kind):
    """A small mesh that holds ``kind`` and nothing else beyond positions and faces."""
    if kind == "quads":
        return Mesh(vertices=SQUARE, face_sizes=np.array([4, 4]),
                    face_vertices=np.array([0, 1, 2, 3, 1, 4, 5, 2]))
    if kind == "polygons":
        pentagon = np.vstack([SQUARE[:4], [[0.5, -0.5, 0.0]]])
        return Mesh(vertices=pentagon, face_sizes=np.array([5]),
                    face_vertices=np.array([0, 4, 1, 2, 3]))
    mesh = Mesh.from_arrays(SQUARE, np.array([[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]]))
    corners = mesh.face_vertices
    if kind == "uv":
        mesh.uv, mesh.face_uv = SQUARE[:, :2] * 0.5, corners.copy()
    elif kind == "uv_seams":  # the second square's corners at another place in the texture
        mesh.uv = np.vstack([SQUARE[:, :2] * 0.5, SQUARE[:, :2] * 0.5 + 0.5])
        mesh.face_uv = np.where(np.arange(len(corners)) < 6, corners, corners + 6)
    elif kind == "normals":
        mesh.normals = np.tile([0.0, 0.0, 1.0], (len(SQUARE), 1))
        mesh.face_normals = corners.copy()
    elif kind == "vertex_data":
        mesh.vertex_data["weight"] = np.linspace(0.0, 1.0, len(SQUARE))
    elif kind == "statements":
        mesh.statements = [(0, "g part"), (0, "usemtl red")]
    return mesh


def test_each_sample_holds_its_kind_alone():
    for kind in KINDS:
        assert list(held(_holding(kind))) == [kind], kind


def _per_corner(values, refs):
    return np.asarray(values)[np.asarray(refs)]


def _came_back(kind, mesh, back):
    if kind == "quads":
        return (back.face_sizes == 4).sum() == 2
    if kind == "polygons":
        return (back.face_sizes == 5).sum() == 1
    if kind in ("uv", "uv_seams"):
        return back.uv is not None and np.allclose(_per_corner(back.uv, back.face_uv),
                                                   _per_corner(mesh.uv, mesh.face_uv))
    if kind == "normals":
        return back.normals is not None and np.allclose(
            _per_corner(back.normals, back.face_normals),
            _per_corner(mesh.normals, mesh.face_normals))
    if kind == "vertex_data":
        return np.allclose(back.vertex_data.get("weight", np.nan), mesh.vertex_data["weight"])
    return back.statements == mesh.statements


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", list(FORMATS))
def test_a_kind_comes_back_where_the_format_keeps_it_and_is_said_where_not(name, kind,
                                                                         tmp_path):
    fmt = FORMATS[name]
    mesh = _holding(kind)
    path = tmp_path / f"m{fmt.extension}"
    lost = write_mesh(str(path), mesh)
    words = held(mesh)[kind]
    said = [w for w in lost if w.startswith(words)]
    if kind in fmt.keeps:
        assert said == [], lost
        assert _came_back(kind, mesh, read_mesh(str(path))), f"{name} lost {kind}"
    else:
        assert len(said) == 1 and said[0].code == "format-drops", lost
        assert fmt.name.upper() in said[0]
