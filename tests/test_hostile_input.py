"""Hostile input: no crash, no hang, no blow-up, one InputError naming the file."""
import os
import re
import struct
import subprocess
import sys

import numpy as np
import pytest
from helpers import run_cli, tube_mesh

from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh, write_mesh
from srarap_cli.runtime.errors import InputError


def ply_header(fmt, n_vertices, n_faces, count="uchar", extra=""):
    return (f"ply\nformat {fmt} 1.0\nelement vertex {n_vertices}\nproperty float x\n"
            f"property float y\nproperty float z\n{extra}element face {n_faces}\n"
            f"property list {count} int vertex_indices\nend_header\n").encode()


def binary_faces(faces):
    return b"".join(struct.pack("<B", len(f)) + struct.pack(f"<{len(f)}i", *f) for f in faces)


VERTS = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)


@pytest.mark.parametrize("name, data, message", [
    ("zero.ply", ply_header("binary_little_endian", 3, 2) + VERTS
     + binary_faces([[0, 1, 2], []]), "face 1 has 0 corners"),
    ("zero-ascii.ply", ply_header("ascii", 3, 1) + b"0 0 0\n1 0 0\n0 1 0\n0\n",
     "face 0 has 0 corners"),
    ("two.ply", ply_header("binary_little_endian", 3, 1) + VERTS + binary_faces([[0, 1]]),
     "face 0 has 2 corners"),
    ("noend.ply", b"ply\nformat ascii 1.0\nelement vertex 3\n" + b"comment x\n" * 20000,
     "no 'end_header'"),
    ("huge-vertex.ply", ply_header("binary_little_endian", 2147483647, 1) + VERTS,
     "declares 2147483647 entries"),
    ("huge-face.ply", ply_header("binary_little_endian", 3, 100000000) + VERTS
     + binary_faces([[0, 1, 2]]), "declares 100000000 entries"),
    ("columns.ply", ply_header("ascii", 3, 1) + b"0 0 0 7\n1 0 0\n0 1 0\n3 0 1 2\n",
     "vertex 0 has 4 values, the header declares 3"),
    ("float-index.ply", ply_header("ascii", 3, 1) + b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n",
     "non-integer"),
    ("cut.ply", ply_header("binary_little_endian", 3, 2) + VERTS + binary_faces([[0, 1, 2]])
     + b"\x03\x00", "declares 2 entries|cut off"),
    ("nomagic.ply", b"PLX\nformat ascii 1.0\nend_header\n", "no 'ply' magic"),
    ("badline.ply", b"ply\nformat ascii 1.0\nelement vertex many\nend_header\n",
     "bad PLY header line"),
])
@pytest.mark.timeout(60)  # a hang is the failure
def test_broken_ply_files_are_one_input_error_quickly(tmp_path, name, data, message):
    path = tmp_path / name
    path.write_bytes(data)
    with pytest.raises(InputError, match=message) as err:
        read_mesh(str(path))
    assert str(path) in str(err.value) and "\n" not in str(err.value)


def test_ply_reader_keeps_polygons_of_mixed_size_in_both_byte_orders(tmp_path):
    mesh = tube_mesh(rings=3, segments=5)  # quads and triangle fans
    path = tmp_path / "m.ply"
    write_mesh(str(path), mesh)
    back = read_mesh(str(path))
    assert np.array_equal(back.face_sizes, mesh.face_sizes)
    assert np.array_equal(back.face_vertices, mesh.face_vertices)
    assert np.array_equal(back.vertices, mesh.vertices)
    data = path.read_bytes()
    head, _, body = data.partition(b"end_header\n")
    n = len(mesh.vertices)
    names = [line.split()[2] for line in head.decode().splitlines()
             if line.startswith("property double")]
    assert names[:3] == ["x", "y", "z"]
    table = np.frombuffer(body, dtype=[(k, "<f8") for k in names], count=n)
    big = table.astype([(k, ">f8") for k in names]).tobytes()
    faces = b"".join(struct.pack(">B", s) + struct.pack(f">{s}i", *f) for s, f in zip(
        mesh.face_sizes, np.split(mesh.face_vertices, np.cumsum(mesh.face_sizes)[:-1])))
    (tmp_path / "big.ply").write_bytes(
        head.replace(b"binary_little_endian", b"binary_big_endian") + b"end_header\n" + big
        + faces)
    other = read_mesh(str(tmp_path / "big.ply"))
    assert np.array_equal(other.vertices, mesh.vertices)
    assert np.array_equal(other.face_vertices, mesh.face_vertices)


def test_ascii_ply_with_extra_vertex_properties_reads(tmp_path):
    path = tmp_path / "a.ply"
    path.write_bytes(b"ply\nformat ascii 1.0\ncomment hi\nelement vertex 4\nproperty float x\n"
                     b"property float y\nproperty float z\nproperty uchar red\n"
                     b"element face 1\nproperty list uchar int vertex_index\nend_header\n"
                     b"0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n4 0 1 2 3\n")
    m = read_mesh(str(path))
    assert m.face_sizes.tolist() == [4] and m.vertex_data["red"].tolist() == [1, 2, 3, 4]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
@pytest.mark.parametrize("kind, says", [
    ("mesh.obj", "not a regular file"), ("mesh.ply", "not a regular file"),
    # a handle file is read from a pipe by its content (issue 60): one nobody writes to is
    # given up after the wait (0.5 s here), a .sel before it is opened
    ("handles.yaml", r"nothing came through it in 0\.[5-9] s"), ("handles.sel", "beside its .def")])
def test_a_fifo_or_device_nobody_writes_to_ends_in_one_line_without_blocking(tmp_path, kind,
                                                                             says):
    fifo = tmp_path / kind
    os.mkfifo(fifo)
    mesh_path = tmp_path / "ok.obj"
    write_mesh(str(mesh_path), tube_mesh(rings=3, segments=5))
    code = ("import sys\nfrom srarap_cli.runtime.errors import InputError\n"
            "from srarap_cli.io.mesh import read_mesh\nfrom srarap_cli.io.handles import load_handles\n"
            "import srarap_cli.io.documents as documents\ndocuments.STREAM_WAIT = 0.5\n"
            "try:\n"
            f"    if {kind!r}.startswith('mesh'): read_mesh({str(fifo)!r})\n"
            f"    else: load_handles({str(fifo)!r}, read_mesh({str(mesh_path)!r}).vertices)\n"
            "except InputError as e: print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=60).stdout
    assert re.search(says, out), out  # the wait as measured: a loaded machine adds a tenth
    with pytest.raises(InputError, match="not a regular file"):
        read_mesh(_link(tmp_path, "/dev/zero"))  # a device behind a symlink


def _link(tmp_path, target):
    link = tmp_path / "zero.obj"
    if not link.exists():
        link.symlink_to(target)
    return str(link)


def alias_bomb(levels=9, width=9):
    lines = ["a0: &a0 [1, 2, 3, 4, 5, 6, 7, 8, 9]"]
    for k in range(1, levels):
        lines.append(f"a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * width) + "]")
    return "\n".join(lines) + "\ngroups: {}\n"


@pytest.mark.parametrize("name, text, message", [
    ("bomb.yaml", alias_bomb(), "expands to more than"),
    ("deep.yaml", "groups: " + "[" * 1000 + "]" * 1000 + "\n", "nested too deeply"),
    ("deep.json", '{"groups": ' + "[" * 5000 + "]" * 5000 + "}", "nested too deeply"),
    ("self.yaml", "a: &a [*a]\ngroups: {f: {indices: [0], fixed: true}}\n", "refers to itself"),
    ("self-map.yaml", "a: &a {b: [1, {c: *a}]}\ngroups: {}\n", "refers to itself"),
])
@pytest.mark.timeout(60)  # a hang is the failure
def test_yaml_bombs_and_deep_nesting_are_refused_quickly(tmp_path, name, text, message,
                                                         monkeypatch):
    """Refused after a walk of the composed graph that visits each node once: the work is
    counted in nodes, not the 10^9 the aliases expand to (nor forever, for a cycle)."""
    from srarap_cli.io import documents

    visited = []
    real = documents._children
    monkeypatch.setattr(documents, "_children", lambda node: visited.append(1) or real(node))
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        load_handles(str(path), np.zeros((3, 3)))
    assert len(visited) < 50_000


def test_aliases_within_bounds_still_work(tmp_path):
    path = tmp_path / "h.yaml"
    path.write_text("groups:\n  a: {indices: [0], fixed: true}\n"
                    "  b: {indices: [1], translate: &up [0, 0, 1]}\n"
                    "  c: {indices: [2], translate: *up}\n")
    c = load_handles(str(path), np.eye(3))
    assert np.allclose(c.targets, np.eye(3) + [[0, 0, 0], [0, 0, 1], [0, 0, 1]])


def test_a_non_finite_energy_stops_a_solve_with_a_numerical_error():
    from types import SimpleNamespace

    from srarap_cli.runtime.errors import NumericalError
    from srarap_cli.solver.drivers import Monitor
    m = Monitor(max_iter=5, tol=1e-6)
    with pytest.raises(NumericalError, match="non-finite"):
        m.record(SimpleNamespace(total=float("nan"), membrane=0.0, bending=0.0,
                                 positions=np.zeros((2, 3))))


HANDLES = ("groups:\n  base: {box: {min: [-2, -2, -0.01], max: [2, 2, 0.01]}, fixed: true}\n"
           "  tip: {box: {min: [-2, -2, 5.99], max: [2, 2, 6.01]}, translate: [0, 0, 1]}\n")
TWO = "groups:\n  a: {indices: [0], fixed: true}\n  b: {indices: [3], translate: [0, 1, 0]}\n"
FLAT = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\n"
TINY = "".join(f"v {x * 1e-150} {y * 1e-150} 0\n" for x, y in [(0, 0), (1, 0), (0, 1), (1, 1)])


@pytest.mark.parametrize("args, files, code, message", [
    (["deform", "e.stl", "h.yaml", "-o", "o.obj"], {"e.stl": ""}, 4, "no vertices"),
    (["deform", "e.stl", "h.yaml", "-o", "o.obj"], {"e.stl": "solid x\nendsolid x\n"}, 4,
     "no vertices"),
    (["deform", "b.obj", "h.yaml", "-o", "o.obj"], {"b.obj": "f 1 2 99999999999999999999\n"},
     4, "out of range"),
    (["deform", "m.obj", "i.yaml", "-o", "o.obj"],
     {"i.yaml": "groups:\n  a: {indices: [9223372036854775808], fixed: true}\n"}, 4,
     "out of range"),
    (["deform", "m.obj", "h.yaml", "-o", "o.obj", "--alpha", "nan"], {}, 2, "finite"),
    (["deform", "m.obj", "h.yaml", "-o", "o.obj", "--feedback", "nan"], {}, 2, "finite"),
    (["deform", "m.obj", "h.yaml", "-o", "o.obj", "--tol", "nan"], {}, 2, "finite"),
    (["deform", "c.obj", "c.yaml", "-o", "o.obj"], {"c.obj": FLAT, "c.yaml": TWO}, 4,
     "zero area"),
    (["deform", "t.obj", "c.yaml", "-o", "o.obj"], {"t.obj": TINY + "f 1 2 3\nf 2 4 3\n",
                                                   "c.yaml": TWO}, 4, "rescale"),
    (["deform", "m.obj", "r.yaml", "-o", "o.obj"],
     {"r.yaml": HANDLES + "region: {indices: [0, 1]}\n"}, 4, "no vertex free to move"),
    (["batch", "j.yaml", "-o", "bo"], {"j.yaml": "jobs:\n  - {mesh: m.obj, handles: h.yaml, "
                                       "output: a.obj, expect: {tol: abc, golden: m.obj}}\n"},
     4, "tol must be a finite number"),
    (["animate", "m.obj", "h.yaml", "-o", "f_{:>1000000000}.obj", "--frames", "2"], {}, 2,
     "width at most 99"),
    (["animate", "m.obj", "h.yaml", "-o", "fr/{}/f.obj", "--frames", "2"], {}, 2,
     "not in a folder"),
    (["deform", "m.obj", "h.yaml", "-o", "folder.obj"], {}, 6, "is a folder"),
    (["deform", "m.obj"], {}, 2, "Missing argument"),
    (["nosuch"], {}, 2, "No such command"),
])
def test_bad_input_is_one_line_with_the_documented_code(tmp_path, args, files, code, message):
    write_mesh(str(tmp_path / "m.obj"), tube_mesh(rings=3, segments=4))
    (tmp_path / "h.yaml").write_text(HANDLES)
    (tmp_path / "folder.obj").mkdir()
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    p = run_cli(args, cwd=tmp_path)
    assert p.returncode == code, p.stderr
    assert p.stderr.startswith("srarap: error: ") and p.stderr.count("\n") == 1, p.stderr
    assert message in p.stderr and p.stdout == ""
    assert not (tmp_path / "o.obj").exists()


@pytest.mark.parametrize("output, message", [
    ("../../x.obj", "must stay inside the output folder"),
    ("/tmp/elsewhere.obj", "must stay inside the output folder"),
    ("../jobs.yaml", "must stay inside the output folder"),
    ("m.obj", "refusing to overwrite an input"),
    ("h.yaml.srarap.json.obj", None),
    ("o.txt", "needs one of the extensions"),
    ("o", "needs one of the extensions"),
])
def test_batch_outputs_stay_inside_their_folder_and_off_the_inputs(tmp_path, output, message):
    write_mesh(str(tmp_path / "m.obj"), tube_mesh(rings=3, segments=4))
    (tmp_path / "h.yaml").write_text(HANDLES)
    manifest = tmp_path / "jobs.yaml"
    manifest.write_text(f"jobs:\n  - {{mesh: m.obj, handles: h.yaml, output: '{output}'}}\n")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "batch", "jobs.yaml", "-o", "."],
                       cwd=tmp_path, capture_output=True, text=True, timeout=120)
    if message is None:
        assert p.returncode == 0, p.stderr
        return
    assert p.returncode == 4 and message in p.stderr and p.stderr.count("\n") == 1
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_two_jobs_with_one_output_are_refused(tmp_path):
    write_mesh(str(tmp_path / "m.obj"), tube_mesh(rings=3, segments=4))
    (tmp_path / "h.yaml").write_text(HANDLES)
    (tmp_path / "jobs.yaml").write_text(
        "jobs:\n  - {mesh: m.obj, handles: h.yaml, output: a.obj}\n"
        "  - {mesh: m.obj, handles: h.yaml, output: ./a.obj, name: b}\n")
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "batch", "jobs.yaml", "-o", "out"],
                       cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert p.returncode == 4 and "also another job's output" in p.stderr


def test_a_stale_temporary_file_of_a_dead_run_is_swept(tmp_path):
    from srarap_cli.runtime.commit import commit_files
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    stale = tmp_path / f".srarap-{dead}-abcd.tmp"
    stale.write_bytes(b"x" * 100)
    mine = tmp_path / f".srarap-{os.getpid()}-live.tmp"  # a live writer's: left alone
    mine.write_bytes(b"y")
    commit_files([(str(tmp_path / "out.obj"), b"data")])
    assert not stale.exists() and mine.exists()
    assert (tmp_path / "out.obj").read_bytes() == b"data"


@pytest.mark.slow
def test_output_bytes_do_not_depend_on_the_blas_thread_count(tmp_path):
    from helpers import ROOT
    outputs = []
    for threads in ("1", "2"):
        out = tmp_path / f"o{threads}.obj"
        env = dict(os.environ, OPENBLAS_NUM_THREADS=threads, OMP_NUM_THREADS=threads)
        subprocess.run([sys.executable, "-m", "srarap_cli", "deform",
                        os.path.join(ROOT, "sample_meshes", "spot.obj"),
                        os.path.join(ROOT, "configs", "spot-nod.yaml"), "-o", str(out), "-q"],
                       env=env, check=True, timeout=600)
        outputs.append(out.read_bytes())
    assert outputs[0] == outputs[1]


def test_the_library_solves_with_one_blas_thread():
    from threadpoolctl import threadpool_info

    from srarap_cli.runtime.parallel import available_cpus, current_threads, numerics
    seen = numerics(lambda: ([i["num_threads"] for i in threadpool_info()
                              if i["user_api"] == "blas"], current_threads()))(threads=2)
    assert seen[0] and set(seen[0]) == {1}
    assert seen[1] == min(2, available_cpus())


@pytest.mark.slow
def test_a_job_with_a_hostile_handle_file_fails_alone(tmp_path):
    write_mesh(str(tmp_path / "m.obj"), tube_mesh(rings=3, segments=4))
    (tmp_path / "h.yaml").write_text(HANDLES)
    (tmp_path / "deep.yaml").write_text("groups: " + "[" * 3000 + "]" * 3000 + "\n")
    (tmp_path / "bomb.yaml").write_text(alias_bomb() + HANDLES.replace("groups", "more"))
    (tmp_path / "jobs.yaml").write_text(
        "jobs:\n  - {mesh: m.obj, handles: deep.yaml, output: a.obj}\n"
        "  - {mesh: m.obj, handles: bomb.yaml, output: b.obj}\n"
        "  - {mesh: m.obj, handles: h.yaml, output: c.obj}\n")
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "batch", "jobs.yaml", "-o", "out"],
                       cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert p.returncode == 8, p.stderr
    import json
    rows = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert [r["status"] for r in rows] in (["failed", "failed", "ok"],
                                           ["failed", "failed", "not-converged"])
    assert "nested too deeply" in rows[0]["message"]
    assert "expands to more than" in rows[1]["message"]


@pytest.mark.parametrize("content", [b"", b"PK\x03\x04truncated"])
def test_an_empty_or_truncated_resume_state_is_invalid_input(tmp_path, content):
    write_mesh(str(tmp_path / "m.obj"), tube_mesh(rings=3, segments=4))
    (tmp_path / "h.yaml").write_text(HANDLES)
    (tmp_path / ".srarap-animate-state.npz").write_bytes(content)
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "animate", "m.obj", "h.yaml", "-o",
                        "f_{:03d}.obj", "--frames", "2", "--resume"], cwd=tmp_path,
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 4 and "unreadable resume state" in p.stderr
    assert p.stderr.count("\n") == 1 and not (tmp_path / "f_000.obj").exists()


def test_a_signal_after_the_commit_reports_what_was_written(tmp_path):
    import click
    from click.testing import CliRunner

    from srarap_cli.cli.common import guarded
    from srarap_cli.runtime.commit import COMMITTED, commit_files

    @click.command()
    @guarded
    def job():
        commit_files([(str(tmp_path / "a.obj"), b"a")])
        raise KeyboardInterrupt  # as if SIGINT arrived right after the renames

    del COMMITTED[:]
    r = CliRunner().invoke(job, [])
    del COMMITTED[:]
    assert r.exit_code == 130
    assert "stopped after writing" in r.output and "a.obj" in r.output
    assert (tmp_path / "a.obj").read_bytes() == b"a"


def test_sigterm_while_still_importing_is_one_line_and_143():
    code = ("import os, signal, sys\nsys.argv = ['srarap', '--help']\n"
            "import srarap_cli.entry as e\n"
            "import builtins\nreal = builtins.__import__\n"
            "def slow(name, *a, **k):\n"
            "    if name == 'click':\n"
            "        os.kill(os.getpid(), signal.SIGTERM)\n"
            "    return real(name, *a, **k)\n"
            "builtins.__import__ = slow\ne.main()\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert p.returncode == 143 and p.stderr == "srarap: error: terminated; no output written\n"


@pytest.mark.parametrize("make, message", [
    (lambda V, F: dict(targets=np.zeros((3, 2))), r"targets must be a \(2, 3\) array"),
    (lambda V, F: dict(targets=[[0, 0, np.nan], [0, 0, 0]]), "targets has NaN"),
    (lambda V, F: dict(V=V[:, :2]), r"V must be an \(n, 3\) array"),
    (lambda V, F: dict(F=F + len(V)), "F: vertex index"),
    (lambda V, F: dict(constrained=[0, 0]), "lists a vertex twice"),
    (lambda V, F: dict(constrained=[0.5, 1]), "integer vertex indices"),
])
def test_the_api_names_the_bad_argument_and_its_shape(make, message):
    from srarap_cli import deform
    from srarap_cli.solver.multires.simplify import _octahedron
    V, F = _octahedron()
    args = dict(V=V, F=F, constrained=[0, 1], targets=V[[0, 1]])
    args.update(make(V, F))
    with pytest.raises(ValueError, match=message):
        deform(args["V"], args["F"], args["constrained"], args["targets"], max_iter=2)
