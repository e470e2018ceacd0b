"""The edges of the command line, by class, on generated variants: outputs that are not
regular files, closed standard descriptors, standard input of any content and size, PLY
property tables, extreme quaternions, signals to a batch. ``SRARAP_EDGE_EXAMPLES`` sets the
budget of the cheap generators (default 40; a run of 20,000 is reported in the issue's
closing note)."""
import json
import os
import signal
import stat
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from helpers import ROOT, tube_mesh
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from srarap_cli.cli import main
from srarap_cli.io.mesh import format_mesh
from srarap_cli.solver.quaternion import to_matrix

BUDGET = int(os.environ.get("SRARAP_EDGE_EXAMPLES", "40"))
DOCUMENTED = {0, 2, 3, 4, 5, 6, 7, 8, 130, 141, 143}
MESH = tube_mesh(rings=3, segments=4)
TWIST = {"groups": {"base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]},
                             "fixed": True},
                    "top": {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]},
                            "rotate": {"axis": [0, 0, 1], "angle_deg": 30}}}}
cheap = settings(max_examples=BUDGET, deadline=None,
                 suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("edges")
    (folder / "m.obj").write_bytes(format_mesh(MESH, ".obj")[0])
    (folder / "h.yaml").write_text(yaml.safe_dump(TWIST))
    ref = CliRunner().invoke(main, ["deform", str(folder / "m.obj"), str(folder / "h.yaml"),
                                    "-o", str(folder / "ref.obj"), "--log",
                                    str(folder / "ref.csv"), "-q"])
    assert ref.exit_code == 0, ref.output
    return folder


def _srarap(*args, cwd, stdin=None, shell_prefix=""):
    """The console command in a subprocess (``shell_prefix``: redirections such as '2>&-')."""
    line = " ".join(f"'{a}'" for a in args)
    return subprocess.run(f"exec {sys.executable} -m srarap_cli {line} {shell_prefix}",
                          shell=True, cwd=cwd, input=stdin, capture_output=True, timeout=300)


# --- outputs that are not regular files are written through, never replaced --------------

def _special(folder, kind, name):
    path = folder / name
    if path.exists() or path.is_symlink():
        path.unlink()
    if kind == "device":
        try:
            os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, 3))  # /dev/null's numbers
        except PermissionError:
            pytest.skip("making a character device needs root (CI runs as root)")
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "symlink":
        (folder / f"real-{name}").write_text("old")
        path.symlink_to(folder / f"real-{name}")
    return path


@pytest.mark.parametrize("kind", ["device", "fifo", "symlink"])
@pytest.mark.parametrize("which", ["-o", "--log"])
def test_an_output_that_is_not_a_regular_file_is_written_through(case, kind, which):
    name = "out.obj" if which == "-o" else "out.csv"
    target = _special(case, kind, name)
    got = []
    if kind == "fifo":  # a reader, as a pipeline's next command would be
        reader = threading.Thread(target=lambda: got.append(open(target, "rb").read()))
        reader.start()
    other = ["--log", str(case / "x.csv")] if which == "-o" else ["-o", str(case / "x.obj")]
    r = CliRunner().invoke(main, ["deform", str(case / "m.obj"), str(case / "h.yaml"),
                                  which, str(target), *other, "-q"])
    assert r.exit_code == 0, r.output
    mode = os.lstat(target).st_mode
    assert {"device": stat.S_ISCHR, "fifo": stat.S_ISFIFO, "symlink": stat.S_ISLNK}[kind](mode)
    if kind == "fifo":
        reader.join(60)
        written = got[0]
    elif kind == "symlink":
        written = (case / f"real-{name}").read_bytes()
    else:
        return  # the null device keeps nothing; it is still the device
    if which == "-o":
        assert written == (case / "ref.obj").read_bytes()
    else:  # the log's seconds differ from run to run: its rows and columns do not
        ref = (case / "ref.csv").read_text().splitlines()
        rows = written.decode().splitlines()
        assert rows[0] == ref[0] and len(rows) == len(ref)


def test_dev_stdout_is_written_through_with_a_format(case):
    p = _srarap("deform", "m.obj", "h.yaml", "-o", "/dev/stdout", "--format", "obj", "-q",
                cwd=case)
    assert p.returncode == 0 and p.stdout == (case / "ref.obj").read_bytes()


# --- closed standard descriptors ---------------------------------------------------------

@pytest.mark.slow
@settings(max_examples=max(BUDGET // 40, 8), deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(closed=st.sets(st.sampled_from([0, 1, 2]), min_size=1),
       command=st.sampled_from(["deform-file", "deform-stdout", "deform-stdin", "info"]))
def test_closed_standard_descriptors(case, closed, command):
    """A closed stream is no error of the run: a solve to a file succeeds and writes its mesh
    whole; '-' on a closed stream is refused by name (4 reading, 6 writing), nothing written."""
    redirect = " ".join(f"{fd}>&-" if fd else "<&-" for fd in sorted(closed))
    out = case / f"closed-{command}.obj"
    if out.exists():
        out.unlink()
    args = {"deform-file": ["deform", "m.obj", "h.yaml", "-o", out.name],
            "deform-stdout": ["deform", "m.obj", "h.yaml", "-o", "-"],
            "deform-stdin": ["deform", "-", "h.yaml", "-o", out.name],
            "info": ["info", "m.obj", "h.yaml"]}[command]
    p = _srarap(*args, cwd=case, shell_prefix=redirect)
    assert b"Traceback" not in p.stderr and p.returncode in DOCUMENTED
    if command == "deform-file" or command == "info":
        assert p.returncode == 0, p.stderr
    if command == "deform-file":
        assert out.read_bytes() == (case / "ref.obj").read_bytes()
    if command == "deform-stdout" and 1 in closed:
        assert p.returncode == 6
    if command == "deform-stdin" and 0 in closed:
        assert p.returncode == 4 and not out.exists()


def test_standard_output_that_fills_up_changes_no_other_output(case):
    (case / "keep.csv").write_text("old")
    p = _srarap("deform", "m.obj", "h.yaml", "-o", "-", "--log", "keep.csv", cwd=case,
                shell_prefix="> /dev/full")
    assert p.returncode == 6 and (case / "keep.csv").read_text() == "old"


# --- standard input: any bytes, any size --------------------------------------------------

FORMATS = {name: format_mesh(MESH, ext)[0] for name, ext in
           (("obj", ".obj"), ("off", ".off"), ("ply", ".ply"), ("stl", ".stl"))}


@st.composite
def stdin_bytes(draw):
    kind = draw(st.sampled_from(["mesh", "cut", "noise", "prefix"]))
    data = FORMATS[draw(st.sampled_from(sorted(FORMATS)))]
    if kind == "cut":
        return data[:draw(st.integers(0, len(data)))]
    if kind == "noise":
        return draw(st.binary(max_size=300))
    if kind == "prefix":
        return draw(st.binary(max_size=20)) + data
    return data


@cheap
@given(data=stdin_bytes())
def test_standard_input_of_any_content_is_a_mesh_or_one_line(case, data):
    r = CliRunner().invoke(main, ["deform", "-", str(case / "h.yaml"), "-o", "-", "-q"],
                           input=data)
    assert r.exit_code in DOCUMENTED and "Traceback" not in r.output, r.output
    if r.exit_code not in (0, 3):
        assert r.stdout_bytes == b"" and len(r.stderr.strip().splitlines()) == 1


def test_unbounded_standard_input_is_stopped_by_the_memory_guard(case):
    """A stream that never ends: the guard stops the read once parsing what came would not
    fit (200 MB at OBJ's 20 bytes a byte: 10 MB), counted in the bytes it took."""
    env = {**os.environ, "SRARAP_MEMORY_LIMIT": "200000000"}
    p = subprocess.Popen([sys.executable, "-m", "srarap_cli", "info", "-", "--input-format",
                          "obj"], stdin=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                         cwd=case)
    sent, chunk = 0, bytes(1 << 20)
    try:
        while sent < 1 << 30:
            p.stdin.write(chunk)
            sent += len(chunk)
    except (BrokenPipeError, OSError):
        pass
    _, err = p.communicate(timeout=120)
    assert p.returncode == 4 and b"<stdin>: reading it needs about" in err
    assert sent <= 12 << 20  # 10 MB, a chunk in flight and the pipe's buffer


# --- PLY property tables -----------------------------------------------------------------

PLY_TYPES = ["float", "double", "int", "uchar", "short", "float32", "int32"]


@st.composite
def ply_tables(draw):
    """A PLY of the tube with a generated vertex property table: x, y, z in any order among
    extra properties, sometimes one declared twice; ASCII or binary."""
    names = ["x", "y", "z"] + draw(st.lists(st.sampled_from(["nx", "s", "t", "w", "x", "q"]),
                                            max_size=3))
    names = draw(st.permutations(names))
    types = [draw(st.sampled_from(PLY_TYPES)) for _ in names]
    ascii_ = draw(st.booleans())
    V, F = MESH.vertices, MESH.triangles()[0]
    head = ["ply", f"format {'ascii' if ascii_ else 'binary_little_endian'} 1.0",
            f"element vertex {len(V)}"]
    head += [f"property {t} {n}" for t, n in zip(types, names)]
    head += [f"element face {len(F)}", "property list uchar int vertex_indices", "end_header"]
    column = {"x": V[:, 0], "y": V[:, 1], "z": V[:, 2]}
    values = [column.get(n, np.full(len(V), 1.0)) for n in names]
    codes = {"float": "<f4", "float32": "<f4", "double": "<f8", "int": "<i4", "int32": "<i4",
             "uchar": "u1", "short": "<i2"}
    if ascii_:
        rows = [" ".join(repr(float(c[k])) if codes[t][1] == "f" else str(int(c[k]))
                         for c, t in zip(values, types)) for k in range(len(V))]
        faces = [f"3 {a} {b} {c}" for a, b, c in F]
        body = ("\n".join(rows + faces) + "\n").encode()
    else:
        table = np.empty(len(V), dtype=[(f"c{i}", codes[t]) for i, t in enumerate(types)])
        for i, c in enumerate(values):
            table[f"c{i}"] = c
        face = np.empty(len(F), dtype=[("n", "u1"), ("v", "<i4", 3)])
        face["n"], face["v"] = 3, F
        body = table.tobytes() + face.tobytes()
    return ("\n".join(head) + "\n").encode() + body, names


@cheap
@given(table=ply_tables())
def test_ply_property_tables_are_read_or_refused_by_name(case, table, tmp_path_factory):
    data, names = table
    path = tmp_path_factory.mktemp("ply") / "m.ply"
    path.write_bytes(data)
    r = CliRunner().invoke(main, ["info", str(path)])
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        assert r.exit_code == 4 and f"property {twice[0]!r}" in r.output or \
            any(f"property {n!r}" in r.output for n in twice), r.output
    else:
        assert r.exit_code == 0, r.output


# --- extreme quaternions -----------------------------------------------------------------

def _angle_about(q):
    """Degrees of the rotation of quaternion q (any scale), computed apart from srarap:
    from the rotation matrix of q scaled into range with Python's own arithmetic."""
    top = max(abs(c) for c in q)
    w, x, y, z = (c / top for c in q)
    n = (w * w + x * x + y * y + z * z) ** 0.5
    R = to_matrix(np.array([w, x, y, z]) / n)
    return float(np.degrees(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))))


@cheap
@given(direction=st.lists(st.floats(-1, 1, allow_nan=False), min_size=4, max_size=4),
       exponent=st.integers(-300, 300))
def test_a_quaternion_of_any_scale_is_the_rotation_it_points_at(case, direction, exponent,
                                                               tmp_path_factory):
    q = [c * 10.0 ** exponent for c in direction]
    doc = {"groups": {"base": TWIST["groups"]["base"],
                      "top": {"box": TWIST["groups"]["top"]["box"],
                              "rotate": {"quaternion_wxyz": q}}}}
    path = tmp_path_factory.mktemp("q") / "h.json"
    path.write_text(json.dumps(doc))
    r = CliRunner().invoke(main, ["info", str(case / "m.obj"), str(path), "--json"])
    if not any(q):
        assert r.exit_code == 4 and "must not be zero" in r.output
        return
    assert r.exit_code == 0, r.output
    action = json.loads(r.stdout)["groups"][1]["action"]
    angle = _angle_about(q)
    if action == "fixed":
        assert angle < 1e-6, (q, angle)
    else:
        said = float(action.split()[1])
        assert action.startswith("rotate ") and abs(said - angle) < 1e-4 * max(angle, 1.0), \
            (action, angle)


# --- signals to a batch ------------------------------------------------------------------

@pytest.fixture(scope="module")
def slow_batch(tmp_path_factory):
    folder = tmp_path_factory.mktemp("batchsig")
    jobs = [{"name": f"j{i}", "mesh": f"{ROOT}/sample_meshes/spot.obj",
             "handles": f"{ROOT}/configs/spot-nod.yaml", "output": f"o{i}.obj",
             "settings": {"tol": 0, "max_iter": 300 + i}} for i in range(6)]
    (folder / "jobs.yaml").write_text(yaml.safe_dump({"jobs": jobs}))
    return folder


@pytest.mark.slow
@settings(max_examples=3, deadline=None, phases=[Phase.generate],  # timed: no replaying
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(signum=st.sampled_from([signal.SIGINT, signal.SIGTERM]),
       delay=st.floats(0.3, 4.0), extra=st.sampled_from([[], ["--scheduler", "local"]]))
def test_a_signal_stops_a_batch_within_seconds_with_a_true_summary(slow_batch, signum, delay,
                                                                  extra):
    out = slow_batch / f"out-{time.monotonic_ns()}"  # a fresh folder: nothing up to date
    p = subprocess.Popen([sys.executable, "-m", "srarap_cli", "batch", "jobs.yaml", "-o",
                          str(out), "--workers", "2", *extra], cwd=slow_batch,
                         stderr=subprocess.PIPE, start_new_session=True)
    time.sleep(delay)
    os.killpg(p.pid, signum)  # the whole group, as a terminal's Ctrl-C
    _, err = p.communicate(timeout=60)  # a batch that does not stop is the failure
    code = {signal.SIGINT: 130, signal.SIGTERM: 143}[signum]
    assert p.returncode == code and b"Traceback" not in err, err.decode()[-800:]
    if (out / "summary.json").exists():  # a signal before the jobs were read writes none
        rows = json.loads((out / "summary.json").read_text())
        assert {r["status"] for r in rows} <= {"ok", "interrupted"}
        assert all(r["exit_code"] == code for r in rows if r["status"] == "interrupted")
        assert all((out / f"o{r['job'][1:]}.obj").exists() for r in rows if r["status"] == "ok")
    for _ in range(50):  # workers a starting cluster forked after the signal end too
        left = subprocess.run(["pgrep", "-g", str(p.pid)], capture_output=True).stdout
        if not left:
            break
        time.sleep(0.1)
    assert left == b"", "processes left behind"



@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
@pytest.mark.parametrize("extra", [[], ["--scheduler", "local"]])
def test_a_job_committed_just_before_the_signal_is_ok_in_the_summary(slow_batch, signum,
                                                                      extra):
    """Issue 61: under Dask a job committed 0.1-0.6 s before the signal was "interrupted" (or
    "up-to-date": the restarted worker ran it again and found its outputs)."""
    out = slow_batch / f"out-{time.monotonic_ns()}"
    p = subprocess.Popen([sys.executable, "-m", "srarap_cli", "batch", "jobs.yaml", "-o",
                          str(out), "--workers", "2", *extra], cwd=slow_batch,
                         stderr=subprocess.PIPE, start_new_session=True)
    first = []
    while not first:  # the first job committed (either worker's); a hang is the run's timeout
        assert p.poll() is None
        first = [f.name for f in out.iterdir() if f.name.endswith(".srarap.json")] \
            if out.is_dir() else []
        time.sleep(0.01)
    time.sleep(0.2)
    os.killpg(p.pid, signum)
    _, err = p.communicate(timeout=60)
    assert p.returncode == {signal.SIGINT: 130, signal.SIGTERM: 143}[signum], err.decode()
    rows = json.loads((out / "summary.json").read_text())
    for r in rows:
        on_disk = (out / f"o{r['job'][1:]}.obj.srarap.json").exists()
        assert (r["status"] == "ok") == on_disk, (r, err.decode()[-400:])
        assert r["status"] in ("ok", "interrupted"), r
    committed = {f"o{r['job'][1:]}.obj.srarap.json": r["status"] for r in rows}
    assert all(committed[name] == "ok" for name in first)  # on disk before the signal: ok


# a batch worker, just forked and still in multiprocessing's start-up, sends the signal to
# the whole group itself: the window between the fork and the worker's own handlers
SIGNAL_IN_A_WORKERS_START = """
import os, signal, sys
import multiprocessing.queues as q
real = q.Queue._after_fork
def after_fork(self):
    try:  # the first worker only
        os.close(os.open(os.environ["SIGNAL_SENT"], os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except FileExistsError:
        pass
    else:
        os.killpg(0, signal.{name})
    real(self)
q.Queue._after_fork = after_fork
sys.argv = ["srarap", "batch", "jobs.yaml", "-o", "out", "--workers", "2"]
from srarap_cli.entry import main
main()
"""


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_as_a_worker_starts_is_one_line_and_its_code(slow_batch, tmp_path, signum):
    """Workers start with SIGINT/SIGTERM held back until they have their own handlers: a
    Ctrl-C reaching a worker just forked raised in its start-up (a traceback, a broken pool
    reported as an internal error)."""
    code = SIGNAL_IN_A_WORKERS_START.replace("{name}", signum.name)
    p = subprocess.run([sys.executable, "-c", code], cwd=slow_batch, capture_output=True,
                       start_new_session=True, timeout=120,
                       env={**os.environ, "SIGNAL_SENT": str(tmp_path / "sent")})
    err = p.stderr.decode()
    expected = {signal.SIGINT: 130, signal.SIGTERM: 143}[signum]
    assert p.returncode == expected and "Traceback" not in err, err[-1500:]
    assert "internal error" not in err and err.count("srarap: error:") <= 1, err[-1500:]


# a second SIGTERM comes while a batch stopped by the first writes its summary (a CI
# runner's timeout sends more than one): every interpreter imports this sitecustomize, and
# the batch's own sends the signal as its summary is committed
SECOND_SIGNAL_AT_THE_SUMMARY = """
import os, signal
from srarap_cli.cli import batch
real = batch.commit_files
def commit_files(files, **kwargs):
    os.kill(os.getpid(), signal.SIGTERM)
    return real(files, **kwargs)
batch.commit_files = commit_files
"""


@pytest.mark.slow
def test_a_second_signal_while_a_stopped_batch_writes_its_summary_keeps_the_summary(
        slow_batch, tmp_path):
    (tmp_path / "sitecustomize.py").write_text(SECOND_SIGNAL_AT_THE_SUMMARY)
    out = tmp_path / "out"
    p = subprocess.Popen([sys.executable, "-m", "srarap_cli", "batch", "jobs.yaml", "-o",
                          str(out), "--workers", "2"], cwd=slow_batch, stderr=subprocess.PIPE,
                         env={**os.environ, "PYTHONPATH": str(tmp_path)})
    for _ in range(600):  # until the workers run (the manifest is read by then)
        if subprocess.run(["pgrep", "-P", str(p.pid)], capture_output=True).stdout:
            break
        time.sleep(0.1)
    time.sleep(0.5)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 143 and "Traceback" not in err.decode(), err.decode()[-800:]
    rows = json.loads((out / "summary.json").read_text())
    assert len(rows) == 6 and "interrupted" in {r["status"] for r in rows}
    assert "terminated: the jobs not finished are marked interrupted" in err.decode()


# the batch sends the signal to its group as soon as its fork server has been started: the
# window while the server (a fresh interpreter) imports the workers' code
SIGNAL_AS_THE_FORK_SERVER_STARTS = """
import os, signal, sys, time
from multiprocessing import forkserver
real = forkserver.ensure_running
def ensure_running():
    real()
    time.sleep(0.15)  # the server is importing by now
    os.killpg(0, signal.{name})
forkserver.ensure_running = ensure_running
sys.argv = ["srarap", "batch", "jobs.yaml", "-o", "out", "--workers", "2",
            "--scheduler", "local"]
from srarap_cli.entry import main
main()
"""


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_as_the_fork_server_starts_is_one_line_and_its_code(slow_batch, signum):
    """The fork server that starts a local Dask cluster's workers starts with SIGINT/SIGTERM
    held back until it has set them: a Ctrl-C during its imports printed their traceback."""
    pytest.importorskip("distributed")
    code = SIGNAL_AS_THE_FORK_SERVER_STARTS.replace("{name}", signum.name)
    p = subprocess.run([sys.executable, "-c", code], cwd=slow_batch, capture_output=True,
                       start_new_session=True, timeout=120)
    err = p.stderr.decode()
    expected = {signal.SIGINT: 130, signal.SIGTERM: 143}[signum]
    assert p.returncode == expected and "Traceback" not in err, err[-1500:]
    assert "internal error" not in err and err.count("srarap: error:") <= 1, err[-1500:]

# --- a signal at any moment of a run's start and end -------------------------------------

@pytest.mark.slow
@settings(max_examples=max(BUDGET // 4, 10), deadline=None, phases=[Phase.generate],
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(signum=st.sampled_from([signal.SIGINT, signal.SIGTERM]), delay=st.floats(0.0, 1.5))
def test_a_signal_at_any_moment_is_one_line_and_its_code(case, signum, delay):
    """While modules load (numpy's class set-up took a SIGINT as a RuntimeError), during the
    solve, or after the summary line on the way out: exit 130/143 with one line, or 0 when
    the run had ended; never a traceback, never exit 1. A signal during the interpreter's
    own start, before srarap's entry module runs its first line (which holds the signals back
    until srarap's handlers are in), is Python's: its traceback then shows no srarap module
    but the package's ``__init__`` or the line of ``__main__`` that imports the entry, and
    nothing is written."""
    out = case / f"sig-{time.monotonic_ns()}.obj"
    p = subprocess.Popen([sys.executable, "-m", "srarap_cli", "deform", "m.obj", "h.yaml",
                          "-o", str(out)], cwd=case, stderr=subprocess.PIPE)
    time.sleep(delay)
    p.send_signal(signum)
    _, err = p.communicate(timeout=120)
    code = {signal.SIGINT: 130, signal.SIGTERM: 143}[signum]
    if p.returncode in (1, -signum):  # the interpreter's start
        frames = [line for line in err.decode().splitlines() if "/srarap_cli/" in line
                  and line.strip().startswith("File")]
        assert all("srarap_cli/__init__.py" in f or "srarap_cli/__main__.py" in f
                   for f in frames) and not out.exists(), \
            err.decode()[-800:]
        return
    assert p.returncode in (0, code) and b"Traceback" not in err, err.decode()[-600:]
    if p.returncode == code:
        assert err.count(b"srarap: error:") == 1
