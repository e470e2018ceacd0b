"""Third-party readers cannot take srarap with them (issue 61): every meshio read format, fed
truncated, zero-tailed and count-inflated files, ends within its time bound, inside the stated
memory bound, with exit 4 naming the file (or reads what is there); a signal during a read
that loops ends srarap with 143/130 and one line, and no reader process is left behind."""
import os
import re
import resource
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from helpers import ROOT, children

from srarap_cli.io.mesh import FORMATS, Mesh, read_mesh, write_mesh
from srarap_cli.io.mesh.meshio_formats import TABLE
from srarap_cli.runtime.bounded import OutOfMemory, OutOfTime, run_bounded, time_bound

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
#: the bounds the sweep states: a read of these small files gets 4 s, the process 1 GB
SECONDS, MEMORY = "4", "1e9"
ENV = {**os.environ, "SRARAP_READ_SECONDS": SECONDS, "SRARAP_MEMORY_LIMIT": MEMORY}
HUGE = b"4294967295"


def _variants(path, n_points):
    """name -> bytes: the file cut at a third, its second half zeros, and (text formats) the
    first number that counts its points made 4294967295, or 2**64."""
    data = open(path, "rb").read()
    half = len(data) // 2
    out = {"truncated": data[:len(data) // 3], "zero-tailed": data[:half] + bytes(len(data) - half)}
    found = re.search(rb"(?<![\d.eE+-])" + str(n_points).encode() + rb"(?![\d.eE])", data)
    if found:
        out["count-inflated"] = data[:found.start()] + HUGE + data[found.end():]
        out["past-64-bits"] = data[:found.start()] + str(2 ** 64).encode() + data[found.end():]
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", [n for n in FORMATS if n in TABLE])
def test_every_meshio_format_damaged_ends_in_bounds_with_one_line(name, tmp_path):
    mesh = read_mesh(BAR)
    good = tmp_path / f"good{FORMATS[name].extension}"
    write_mesh(good, Mesh.from_arrays(mesh.vertices, mesh.triangles()[0]))
    for kind, data in _variants(good, len(mesh.vertices)).items():
        path = tmp_path / f"{kind}{FORMATS[name].extension}"
        path.write_bytes(data)
        # a hang guard, not a timing: the read's bound plus a generous start-up
        done = subprocess.run([sys.executable, "-m", "srarap_cli", "info", str(path)],
                              capture_output=True, text=True, env=ENV,
                              timeout=float(SECONDS) + 60)
        lines = done.stderr.splitlines()
        assert "Traceback" not in done.stderr, (kind, done.stderr)
        if done.returncode == 0:  # the damage missed what the reader reads (padding)
            continue
        assert done.returncode == 4, (kind, done.stderr)
        assert len(lines) == 1 and lines[0].startswith(f"srarap: error: {path}"), (kind, lines)
    # every process of the sweep, readers included, stayed inside the stated memory bound
    assert resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024 < float(MEMORY) + 3e8


def _truncated_tecplot(tmp_path):
    mesh = read_mesh(BAR)
    good = tmp_path / "good.dat"
    write_mesh(good, Mesh.from_arrays(mesh.vertices, mesh.triangles()[0]))
    bad = tmp_path / "loops.dat"
    bad.write_bytes(good.read_bytes()[:274])  # meshio's Tecplot reader loops on it forever
    return bad


def test_a_reader_that_loops_is_stopped_at_its_time_bound(tmp_path):
    bad = _truncated_tecplot(tmp_path)
    done = subprocess.run([sys.executable, "-m", "srarap_cli", "info", str(bad)],
                          capture_output=True, text=True, timeout=120,
                          env={**os.environ, "SRARAP_READ_SECONDS": "2"})
    assert done.returncode == 4, done.stderr
    assert done.stderr == (f"srarap: error: {bad}: meshio's Tecplot reader did not finish in "
                           "2 s; stopped (a truncated or damaged file?)\n")


@pytest.mark.parametrize("signum, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_signal_during_a_read_that_loops_ends_srarap_and_the_reader(tmp_path, signum, code):
    bad = _truncated_tecplot(tmp_path)
    p = subprocess.Popen([sys.executable, "-m", "srarap_cli", "info", str(bad)],
                         stderr=subprocess.PIPE, text=True,
                         env={**os.environ, "SRARAP_READ_SECONDS": "300"})
    end = time.monotonic() + 120  # the read started: its child is there (a fixed wait was
    while not children(p.pid) and time.monotonic() < end:  # 3 s, short on a busy machine)
        time.sleep(0.02)
    assert children(p.pid), "the reader never started"
    p.send_signal(signum)
    err = p.communicate(timeout=60)[1]
    assert p.returncode == code and err.count("\n") == 1 and "srarap: error: " in err, err
    ps = subprocess.run(["ps", "-eo", "pid,ppid,args"], capture_output=True, text=True).stdout
    assert str(bad) not in ps  # the forked reader is gone too


def test_a_decompression_bomb_is_refused_before_the_disk_fills(tmp_path):
    import gzip
    bomb = tmp_path / "bomb.vol.gz"
    with gzip.open(bomb, "wb") as fh:
        for _ in range(300):
            fh.write(bytes(1 << 20))
    done = subprocess.run([sys.executable, "-m", "srarap_cli", "info", str(bomb)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 4
    assert done.stderr.startswith(f"srarap: error: {bomb}: decompresses to more than 64 MiB")


@pytest.mark.parametrize("way", ["fork", "served", "fresh"])
def test_run_bounded_returns_raises_and_bounds(monkeypatch, way):
    """Forked where this process runs one thread; where it does not, forked by the child
    server (runtime.child_server), or a fresh interpreter of its own where no server can run
    (issue 72: one fork policy, runtime.forking); all bound alike."""
    import operator

    from srarap_cli.runtime import bounded, child_server, forking
    monkeypatch.setattr(forking, "threads", lambda: 1 if way == "fork" else 2)
    if way == "fresh":
        monkeypatch.setattr(child_server, "available", lambda: False)
    started = []
    for module, name, said in ((bounded, "_fork", "fork"), (bounded, "_fresh", "fresh"),
                               (child_server, "_ask", "served")):
        real = getattr(module, name)
        monkeypatch.setattr(module, name, lambda *a, real=real, said=said: (started.append(said),
                                                                           real(*a))[1])
    assert run_bounded(np.arange, 5, seconds=10, memory=None).tolist() == [0, 1, 2, 3, 4]
    assert started == [way]
    with pytest.raises(ZeroDivisionError):
        run_bounded(operator.truediv, 1, 0, seconds=10, memory=None)
    with pytest.raises(OutOfTime):
        run_bounded(time.sleep, 30, seconds=0.5, memory=None)
    with pytest.raises(OutOfMemory):
        run_bounded(np.ones, 10 ** 10, seconds=30, memory=200 << 20)
    assert time_bound(10 ** 6) > time_bound(0) > 0
    assert set(started) == {way}


def test_the_fork_policy_is_one_table(monkeypatch):
    """Issue 72: every child srarap starts asks runtime.forking; a fork only where this
    process runs a single thread."""
    from srarap_cli.runtime import forking

    table = {}
    for threads in (1, 3):
        monkeypatch.setattr(forking, "threads", lambda threads=threads: threads)
        table[threads] = [forking.how(need) for need in forking.NEEDS]
    assert dict(zip(forking.NEEDS, zip(table[1], table[3]))) == {
        "bound": ("fork", "fresh"), "beside": ("fork", "here"), "gil": ("here", "fresh"),
        "workers": ("fork", "fresh")}
    with pytest.raises(ValueError):
        forking.how("sometimes")
