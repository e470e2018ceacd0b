"""The OBJ reader's and writer's bulk paths against the line-by-line ones and a reference
writer written out here, corner by corner."""
import os

import numpy as np
import pytest
from helpers import ROOT

from srarap_cli.io.mesh import obj, read_mesh
from srarap_cli.runtime.errors import InputError

FIELDS = ("vertices", "face_sizes", "face_vertices", "uv", "face_uv", "normals",
          "face_normals")
SQUARE = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nvn 0 0 -1\n"


def assert_same_mesh(a, b):
    for name in FIELDS:
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert x.dtype == y.dtype and np.array_equal(x, y), name
    assert a.statements == b.statements


def reference_obj(mesh):
    """OBJ text the slow way: one polygon, one corner at a time."""
    def number(x):
        return f"{x:.17g}"
    later = {}
    for k, s in mesh.statements:
        later.setdefault(k, []).append(s + "\n")
    out = ["# written by srarap\n", *later.get(0, [])]
    out += ["v " + " ".join(map(number, p)) + "\n" for p in mesh.vertices]
    if mesh.uv is not None:  # texture coordinates in their shortest exact text
        out += ["vt " + " ".join(repr(float(x)) for x in p) + "\n" for p in mesh.uv]
    if mesh.normals is not None:
        out += ["vn " + " ".join(map(number, p)) + "\n" for p in mesh.normals]
    corner = 0
    for f, size in enumerate(mesh.face_sizes, 1):
        tokens = []
        for c in range(corner, corner + size):
            t = -1 if mesh.face_uv is None else mesh.face_uv[c]
            n = -1 if mesh.face_normals is None else mesh.face_normals[c]
            tok = str(mesh.face_vertices[c] + 1)
            if t >= 0 or n >= 0:
                tok += "/" + (str(t + 1) if t >= 0 else "")
            if n >= 0:
                tok += "/" + str(n + 1)
            tokens.append(tok)
        corner += size
        out.append("f " + " ".join(tokens) + "\n")
        out += later.get(f, [])
    return "".join(out)


# (faces, whether the bulk reader takes them): every corner form, statements among faces,
# and what must go line by line: mixed forms (one corner "1/1/1" and one "2" hold two
# slashes for two corners, as two "v/t" corners would), negative ids, out-of-range ids,
# leading blanks, a bare head, a 4-number vertex
CASES = [
    ("f 1 2 3\nf 2 4 3\n", True),
    ("f 1/1 2/2 3/3\nf 2/2 4/1 3/3\n", True),
    ("f 1//1 2//1 3//2\n", True),
    ("f 1/1/1 2/2/1 3/3/2 4/1/1\n", True),
    ("o thing\nusemtl red\nf 1/1 2/2 3/3\ns off\nusemtl blue\nf 2/2 4/1 3/3\ng end\n", True),
    ("f 1 2 3 4\nf 1 2 3\n", True),
    ("# lead\n\nf 1 2 3\n   \n# tail\n", True),
    ("f 1/1/1 2 3/3\n", False),
    ("f 1/1/1 2 3/3/1 4/2\n", False),
    ("f 1//1 2/2/ 3/3/1\n", False),
    ("f 1/ 2/2 3/3\n", False),
    ("f -1 -2 -3\n", False),
    ("f 1/4 2/2 3/3\n", False),
    ("f 1//3 2//1 3//1\n", False),
    ("f 1 2 5\n", False),
    ("f 1.5 2 3\n", False),
    ("  f 1 2 3\n", False),
    ("o\nv\n", False),
    ("v 0 0 0 1\nf 1 2 3\n", False),
    ("f 1 2\n", False),
]


@pytest.mark.parametrize("newline", ["\n", "\r\n"])
@pytest.mark.parametrize("faces, bulk", CASES)
def test_bulk_reader_reads_what_the_line_by_line_reader_reads(faces, bulk, newline):
    text = (SQUARE + faces).replace("\n", newline)
    fast = obj._read_bulk(text)
    assert (fast is not None) == bulk
    if fast is not None:
        assert_same_mesh(fast, obj._read_general(text, "t.obj"))


@pytest.mark.parametrize("text, bulk", [
    ("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n", True),  # colours
    ("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\nf 1 3 2\n", True),  # vertices among faces
    ("v 0 0 0\nvt 0 0 1\nvt 1 0 0.5\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 3/1\n", True),
    ("v 0 0 0\nv 1 0 0\n# three\nv 0 1 0\nf 1 2 3\n", True),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0\nvt 1\nf 1/1 2/2 3/1\n", False),
])
def test_vertex_lines_in_blocks_or_scattered(text, bulk):
    fast = obj._read_bulk(text)
    assert (fast is not None) == bulk
    if fast is not None:
        assert_same_mesh(fast, obj._read_general(text, "t.obj"))


def test_a_short_vertex_line_is_not_made_up_from_the_next_one(tmp_path):
    """``v 0 0`` then ``v 1 0 0 0`` hold six numbers for two vertices: counting numbers over
    all lines (the bulk reader before) read them as (0, 0, 1) and (0, 0, 0)."""
    path = tmp_path / "short.obj"
    path.write_text("v 0 0\nv 1 0 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(InputError, match="malformed 'v' line"):
        read_mesh(str(path))


def test_a_line_continued_by_a_backslash_is_one_line(tmp_path):
    joined, continued = tmp_path / "joined.obj", tmp_path / "continued.obj"
    joined.write_text(SQUARE + "f 1 2 3\nf 2 4 3\n")
    continued.write_text(SQUARE.replace("v 1 0 0", "v 1 \\\n0 0") + "f 1 2 \\\n3\nf 2 4 3\n")
    assert_same_mesh(read_mesh(str(continued)), read_mesh(str(joined)))


def test_line_breaks_other_than_newline_go_line_by_line():
    for odd in ("\r", "\x0c", "\u2028"):
        assert obj._read_bulk(SQUARE + "f 1 2 3" + odd + "f 2 4 3\n") is None


@pytest.mark.parametrize("faces, bulk", [c for c in CASES if c[1]])
def test_writer_matches_the_corner_by_corner_reference(faces, bulk):
    mesh = obj._read_bulk(SQUARE + faces)
    assert obj.format_obj(mesh) == reference_obj(mesh)


def test_writer_handles_mixed_sizes_forms_and_alternation():
    spot = read_mesh(os.path.join(ROOT, "sample_meshes", "spot.obj"))
    assert obj.format_obj(spot) == reference_obj(spot)
    # some corners without normal ids, statements among the polygons; then polygon sizes
    # alternating every polygon, then in long runs
    spot.face_normals[::7] = -1
    spot.statements = [(0, "o cow"), (100, "usemtl a"), (100, "s 1"), (spot.face_sizes.size,
                                                                         "g end")]
    assert obj.format_obj(spot) == reference_obj(spot)
    for every in (1, 3, 10):  # statements every few polygons: line by line, then blocks
        spot.statements = [(k, f"s {k}") for k in range(0, spot.face_sizes.size, every)]
        assert obj.format_obj(spot) == reference_obj(spot)
    quads = obj._read_bulk(SQUARE + "f 1/1 2/2 4/1 3/3\nf 1/1 2/2 3/3\n" * 3
                           + "f 1/1 2/2 3/3\n" * 200 + "f 1/1 2/2 4/1 3/3\n" * 200)
    assert obj.format_obj(quads) == reference_obj(quads)


def test_statements_said_to_follow_missing_faces_are_written_last():
    mesh = obj._read_bulk(SQUARE + "f 1 2 3\ng end\n")
    mesh.statements.append((5, "g beyond"))
    assert obj.format_obj(mesh).endswith("f 1 2 3\ng end\ng beyond\n")


def test_sample_mesh_takes_the_bulk_path_and_round_trips():
    path = os.path.join(ROOT, "sample_meshes", "spot.obj")
    with open(path) as fh:
        text = fh.read()
    fast = obj._read_bulk(text)
    assert fast is not None and fast.normals is not None
    assert_same_mesh(fast, obj._read_general(text, path))
    assert_same_mesh(obj._read_bulk(obj.format_obj(fast)), fast)


@pytest.mark.parametrize("kind", ["normals and statements", "uvs", "plain"])
def test_animation_frames_are_the_files_format_obj_writes(kind):
    """``obj_frames`` formats faces, statements and uvs once: each frame must still be the
    corner-by-corner reference of the moved mesh (normals recomputed for each frame)."""
    spot = read_mesh(os.path.join(ROOT, "sample_meshes", "spot.obj"))
    if kind == "normals and statements":
        spot.statements = [(0, "o cow"), (100, "usemtl a"), (spot.face_sizes.size, "g end")]
    elif kind == "uvs":
        spot = obj._read_bulk(SQUARE + "f 1/1 2/2 4/1 3/3\nf 1/1 2/2 3/3\n")
    else:
        spot.normals = spot.face_normals = None
    frame = obj.obj_frames(spot)
    rng = np.random.default_rng(1)
    for _ in range(2):
        moved = spot.vertices + rng.normal(scale=0.1, size=spot.vertices.shape)
        expected = spot.with_vertices(moved)
        assert frame(moved) == reference_obj(expected).encode("utf-8")
        assert kind != "normals and statements" or not np.allclose(expected.normals,
                                                                    spot.normals)


@pytest.mark.parametrize("faces, what", [("f 1/1 2/2 3/3\n", "vt"), ("f 1//1 2//1 3//1\n", "vn"),
                                         ("f 1/1/1 2/2/1 3/3/1\n", "vt")])
def test_references_to_entries_a_file_has_none_of_are_refused(tmp_path, faces, what):
    """Issue 60: faces naming ``vt`` entries in a file without ``vt`` lines were accepted
    (and written back as an invalid OBJ), while one index past the last entry was refused."""
    path = tmp_path / "m.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n" + ("vn 0 0 1\n" if what == "vt" else "")
                    + faces)
    with pytest.raises(InputError, match=f"'{what}' entry that does not exist"):
        read_mesh(str(path))


def test_texture_coordinates_are_written_back_with_the_digits_read(tmp_path):
    """Issue 60: ``0.902657`` came back as ``0.90265700000000004``; each number is now the
    shortest text that reads back as the same float, so the digits read when they were."""
    path = tmp_path / "m.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.902657 0.5\nvt 0.1 1e-20\nvt 0.3 0.7\n"
                    "f 1/1 2/2 3/3\n")
    mesh = read_mesh(str(path))
    text = obj.format_obj(mesh)
    assert "vt 0.902657 0.5\nvt 0.1 1e-20\nvt 0.3 0.7\n" in text
    again = tmp_path / "again.obj"
    again.write_text(text)
    assert np.array_equal(read_mesh(str(again)).uv, mesh.uv)
