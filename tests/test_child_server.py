"""The child server (runtime.child_server): where this process may not fork, one fresh
interpreter, kept, forks each bounded call; a call past its bound is killed and reaped, a
server that died is started again, and the server and its children end with the process."""
import os
import signal
import subprocess
import sys
import time

import pytest
from helpers import children

from srarap_cli.runtime import child_server, forking
from srarap_cli.runtime.bounded import OutOfTime, run_bounded

pytestmark = pytest.mark.skipif(not child_server.available() or not os.path.isdir("/proc"),
                                reason="no pidfds or /proc here")


@pytest.fixture
def beside_threads(monkeypatch):
    """This process taken for one that runs other threads: bounded calls go to the server."""
    monkeypatch.setattr(forking, "threads", lambda: 2)


def _alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _until(condition, seconds=10.0):
    end = time.monotonic() + seconds
    while not condition() and time.monotonic() < end:
        time.sleep(0.02)
    return condition()


def test_calls_share_one_server_and_each_runs_in_a_child_of_its_own(beside_threads):
    first = run_bounded(os.getpid, seconds=30, memory=None)
    server = child_server._server[0].pid
    second = run_bounded(os.getpid, seconds=30, memory=None)
    assert child_server._server[0].pid == server
    assert len({first, second, server, os.getpid()}) == 4


def test_a_call_past_its_bound_is_killed_and_reaped(beside_threads):
    run_bounded(os.getpid, seconds=30, memory=None)
    server = child_server._server[0].pid
    with pytest.raises(OutOfTime):
        run_bounded(time.sleep, 60, seconds=0.3, memory=None)
    assert _until(lambda: not children(server))  # killed, and the server reaped it


def test_a_server_that_died_is_started_again(beside_threads):
    run_bounded(os.getpid, seconds=30, memory=None)
    process = child_server._server[0]
    process.kill()
    process.wait()
    assert run_bounded(abs, -3, seconds=30, memory=None) == 3
    assert child_server._server[0].pid != process.pid


def test_a_forked_child_does_not_use_its_parents_server(beside_threads):
    run_bounded(os.getpid, seconds=30, memory=None)
    pid = os.fork()
    if pid == 0:
        os._exit(0 if child_server._server is None else 1)
    assert os.waitpid(pid, 0)[1] == 0
    assert child_server._server is not None


OWNER = """
import threading, time, sys
from srarap_cli.runtime import child_server
from srarap_cli.runtime.bounded import start_bounded
threading.Thread(target=time.sleep, args=(60,), daemon=True).start()
call = start_bounded(time.sleep, 60, seconds=100, memory=None)
print(child_server._server[0].pid, flush=True)
time.sleep(60)
"""


@pytest.mark.parametrize("signum", [signal.SIGKILL, signal.SIGTERM])
def test_the_server_and_its_children_end_with_their_process(signum):
    owner = subprocess.Popen([sys.executable, "-c", OWNER], stdout=subprocess.PIPE, text=True)
    try:
        server = int(owner.stdout.readline())
        assert _until(lambda: len(children(server)) == 1)
        (child,) = children(server)
        owner.send_signal(signum)
        owner.wait(timeout=30)
        assert _until(lambda: not _alive(server) and not _alive(child))
    finally:
        owner.kill()
        owner.wait()


def test_a_server_that_cannot_start_is_not_tried_again_and_calls_run_fresh(beside_threads,
                                                                           monkeypatch):
    monkeypatch.setattr(child_server, "_SERVER", "raise SystemExit(1)")
    monkeypatch.setattr(child_server, "_server", None)
    monkeypatch.setattr(child_server, "_failed", False)
    asks = []
    real = child_server._ask
    monkeypatch.setattr(child_server, "_ask", lambda *a: (asks.append(a), real(*a))[1])
    assert run_bounded(abs, -2, seconds=30, memory=None) == 2
    assert len(asks) == 2 and child_server._failed
    assert run_bounded(abs, -3, seconds=30, memory=None) == 3
    assert len(asks) == 2
