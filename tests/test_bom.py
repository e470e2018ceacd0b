"""A UTF-8 byte order mark before any text input reads exactly like the file without it.

Property: for every text format srarap reads (OBJ, OFF, ASCII PLY, ASCII STL, YAML, JSON,
``.sel``, ``.def``, ``.dmat``, the CSV/JSONL logs ``plot`` reads), parse(BOM + file) ==
parse(file), on generated contents.
"""
import json

import numpy as np
import yaml
from helpers import tube_mesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from srarap_cli.io.documents import load_document
from srarap_cli.io.handles import load_handles
from srarap_cli.io.handles.formats import read_def, read_dmat, read_sel
from srarap_cli.io.mesh import format_mesh, read_mesh
from srarap_cli.io.solve_log import read_log

BOM = b"\xef\xbb\xbf"
MESH = tube_mesh(rings=3, segments=4)


def _ascii_stl(V, F):
    lines = ["solid s"]
    for tri in F:
        lines += ["facet normal 0 0 0", " outer loop"]
        lines += [f"  vertex {x!r} {y!r} {z!r}" for x, y, z in V[tri].tolist()]
        lines += [" endloop", "endfacet"]
    return ("\n".join(lines + ["endsolid s"]) + "\n").encode()


def _pair(tmp_path, name, data):
    plain, marked = tmp_path / name, tmp_path / ("bom_" + name)
    plain.write_bytes(data)
    marked.write_bytes(BOM + data)
    return str(plain), str(marked)


def _same_mesh(a, b):
    assert np.array_equal(a.vertices, b.vertices)
    assert np.array_equal(a.face_sizes, b.face_sizes)
    assert np.array_equal(a.face_vertices, b.face_vertices)


offsets = st.lists(st.floats(-100, 100, allow_nan=False), min_size=3, max_size=3)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(shift=offsets, fmt=st.sampled_from([".obj", ".off", ".ply-ascii", ".stl"]))
def test_mesh_formats(tmp_path, shift, fmt):
    mesh = MESH.with_vertices(MESH.vertices + np.array(shift))
    if fmt == ".stl":
        name, data = "m.stl", _ascii_stl(mesh.vertices, mesh.triangles()[0])
    elif fmt == ".ply-ascii":
        name = "m.ply"
        V, F = mesh.vertices, mesh.triangles()[0]
        data = (f"ply\nformat ascii 1.0\nelement vertex {len(V)}\nproperty double x\n"
                "property double y\nproperty double z\n"
                f"element face {len(F)}\nproperty list uchar int vertex_indices\n"
                "end_header\n"
                + "".join(f"{x!r} {y!r} {z!r}\n" for x, y, z in V.tolist())
                + "".join(f"3 {a} {b} {c}\n" for a, b, c in F.tolist())).encode()
    else:
        name, data = "m" + fmt, format_mesh(mesh, fmt)[0]
    plain, marked = _pair(tmp_path, name, data)
    _same_mesh(read_mesh(plain), read_mesh(marked))


def test_obj_bom_before_first_vertex_keeps_every_vertex(tmp_path):
    """The audit's case: a BOM directly before a ``v`` line used to turn that vertex into an
    opaque statement and shift every later one."""
    plain, marked = _pair(tmp_path, "m.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    m = read_mesh(marked)
    assert len(m.vertices) == 3 and np.array_equal(m.vertices, read_mesh(plain).vertices)
    assert b"\xef\xbb\xbf" not in format_mesh(m, ".obj")[0]


handle_docs = st.fixed_dictionaries({
    "solver": st.fixed_dictionaries({"max_iter": st.integers(1, 50)}),
    "groups": st.fixed_dictionaries({
        "base": st.just({"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True}),
        "tip": st.builds(lambda a: {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]},
                                    "rotate": {"axis": [0, 1, 0], "angle": a}},
                         st.floats(-180, 180, allow_nan=False))})})


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(doc=handle_docs, kind=st.sampled_from(["yaml", "json"]))
def test_handle_documents(tmp_path, doc, kind):
    mesh = tube_mesh(length=6.0, rings=3, segments=4)
    text = yaml.safe_dump(doc) if kind == "yaml" else json.dumps(doc)
    plain, marked = _pair(tmp_path, "h." + kind, text.encode())
    assert load_document(plain, kind) == load_document(marked, kind) == doc
    a, b = load_handles(plain, mesh.vertices), load_handles(marked, mesh.vertices)
    assert np.array_equal(a.ids, b.ids) and np.array_equal(a.targets, b.targets)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(status=st.lists(st.sampled_from([0, 1, 2]), min_size=1, max_size=30),
       matrix=st.lists(st.floats(-10, 10, allow_nan=False), min_size=12, max_size=12))
def test_sel_def_dmat(tmp_path, status, matrix):
    sel = ("# status\n" + "\n".join(map(str, status)) + "\n").encode()
    a, b = _pair(tmp_path, "h.sel", sel)
    assert np.array_equal(read_sel(a), read_sel(b))
    rows = np.array(matrix + [0, 0, 0, 1]).reshape(4, 4)
    a, b = _pair(tmp_path, "h.def", "\n".join(" ".join(map(repr, r)) for r in rows.tolist()).encode())
    assert np.array_equal(read_def(a), read_def(b))
    dmat = (f"1 {len(status)}\n" + "\n".join(map(str, status)) + "\n").encode()
    a, b = _pair(tmp_path, "g.dmat", dmat)
    assert np.array_equal(read_dmat(a), read_dmat(b))


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(energies=st.lists(st.floats(1e-6, 1e6), min_size=1, max_size=10),
       kind=st.sampled_from(["csv", "jsonl"]))
def test_logs_for_plot(tmp_path, energies, kind):
    rows = [{"iteration": k, "total": e, "seconds": 0.1 * k} for k, e in enumerate(energies)]
    if kind == "csv":
        text = "iteration,total,seconds\n" + "".join(
            f"{r['iteration']},{r['total']!r},{r['seconds']!r}\n" for r in rows)
    else:
        text = "".join(json.dumps(r) + "\n" for r in rows)
    a, b = _pair(tmp_path, "log." + kind, text.encode())
    assert read_log(a) == read_log(b)
