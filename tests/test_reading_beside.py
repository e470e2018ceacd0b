"""A second mesh read in a child process while this one reads the first (render's rest shape):
the same mesh and the same errors as a read here, and no child left behind."""
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from helpers import ROOT, children, tube

from srarap_cli.io.mesh import Mesh, read_mesh, reading_beside, write_mesh
from srarap_cli.runtime import child_server, forking
from srarap_cli.runtime.bounded import start_bounded
from srarap_cli.runtime.errors import InputError

SPOT = os.path.join(ROOT, "sample_meshes", "spot.obj")


def test_the_mesh_read_beside_is_the_mesh_read_here(tmp_path):
    V, F = tube(length=2.0, rings=8, segments=10)
    other = str(tmp_path / "tube.ply")
    write_mesh(other, Mesh.from_arrays(V, F))
    before = children()
    with reading_beside(SPOT) as rest:
        here = read_mesh(other)
        beside = rest()
    spot = read_mesh(SPOT)
    assert np.array_equal(beside.vertices, spot.vertices)
    assert np.array_equal(beside.face_vertices, spot.face_vertices)
    assert np.array_equal(beside.normals, spot.normals) and beside.statements == spot.statements
    assert np.array_equal(here.vertices, V)
    assert children() <= before  # nothing left running, no zombie


def test_an_error_beside_is_the_error_here(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0\nv 1 0 0 0\nv 0 1 0\nf 1 2 3\n")
    for path in (str(bad), str(tmp_path / "missing.obj")):
        with pytest.raises(InputError) as here:
            read_mesh(path)
        with reading_beside(path) as rest, pytest.raises(InputError) as beside:
            rest()
        assert str(beside.value) == str(here.value)
    with reading_beside(None) as rest:
        assert rest() is None


@pytest.mark.parametrize("threads", [1, 2])
def test_leaving_early_stops_the_child(monkeypatch, threads):
    """Forked here (one thread) or by the child server (other threads run)."""
    monkeypatch.setattr(forking, "threads", lambda: threads)
    before = children()  # the child server among them, where an earlier test started it
    with pytest.raises(RuntimeError, match="the shown mesh failed"):
        with start_bounded(time.sleep, 30, seconds=60, memory=None) as call:
            parent = os.getpid() if threads == 1 else child_server._server[0].pid
            running = children(parent) - before
            assert len(running) == 1 and (call.pid in running or threads > 1)
            raise RuntimeError("the shown mesh failed")
    # killed and reaped (by its parent: the server reaps within half a second)
    end = time.monotonic() + 10
    while children(parent) & running and time.monotonic() < end:
        time.sleep(0.02)
    assert not children(parent) & running


def test_with_other_threads_the_read_runs_here(monkeypatch):
    """A fork copies only the thread that makes it: a lock another thread holds stays held in
    the child. So beside other threads nothing forks."""
    def fork():
        raise AssertionError("forked beside another thread")

    monkeypatch.setattr(os, "fork", fork)
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        with reading_beside(SPOT) as rest:
            mesh = rest()
    finally:
        stop.set()
        other.join()
    assert np.array_equal(mesh.vertices, read_mesh(SPOT).vertices)


@pytest.mark.parametrize("rest", ["spot", "missing"])
def test_render_writes_and_says_the_same_whether_the_rest_is_read_beside_or_here(tmp_path, rest):
    """The command line runs one thread: there the rest shape is read in a child."""
    rest_path = SPOT if rest == "spot" else str(tmp_path / "missing.obj")
    runs = []
    for bounded in ("1", "0"):
        out = tmp_path / f"r{bounded}.png"
        done = subprocess.run([sys.executable, "-m", "srarap_cli", "render", SPOT, "--rest",
                               rest_path, "-o", str(out), "--up", "y"],
                              capture_output=True, text=True, timeout=120,
                              env={**os.environ, "SRARAP_BOUNDED": bounded})
        runs.append((done.returncode, done.stderr.replace(str(out), "OUT"),
                     out.read_bytes() if out.exists() else None))
    assert runs[0] == runs[1]
    assert (runs[0][0] == 0 and runs[0][2]) if rest == "spot" else runs[0][0] == 4
