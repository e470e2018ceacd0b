"""Bounded children for a process that may not fork: a fresh, single-threaded interpreter
that forks them.

Where other threads run, :mod:`.bounded` may not fork this process (:mod:`.forking`), and a
fresh interpreter per call paid its start and its imports (numpy and meshio: 0.3-1 s) for
every file read. This server is that interpreter, started once per process and kept: it
forks a child per call, and a child starts with what earlier calls imported (it unpickles
each call before it forks). The caller gets the child's result on a pipe of its own, as
from a forked child, and a pidfd to kill it and wait for it (Linux 5.3 and later): the
child is the server's, and a pid alone could name another process once it was reaped.

The server ends when this process does (its socket reaches end of file, a SIGKILL's too),
and kills the children still running first; a child dies with the server. A server that
died is started again at the next call. Where there is no pidfd, or the server cannot start,
:func:`start` returns None and the caller starts a fresh interpreter for the call.
"""
import functools
import os
import pickle
import signal
import socket
import struct
import subprocess
import sys
import threading
from collections.abc import Callable, Sequence
from typing import Any

from .child_call import imported, readable, run_child

#: the server's own program: no death signal tied to the thread that starts it (a pool
#: thread that ends would kill it under a read another thread started); end of file on its
#: socket ends it instead
_SERVER = """\
import sys
from srarap_cli.runtime.child_server import serve
serve(int(sys.argv[1]))
"""
_HEAD = struct.Struct("!Q")
_lock = threading.Lock()
_server: tuple[subprocess.Popen, socket.socket] | None = None
_failed = False


@functools.cache
def available() -> bool:
    """Whether this platform has what the server needs: pidfds (Linux 5.3; a container's
    seccomp filter may refuse them, so one is opened to see) and descriptor passing."""
    if not all(hasattr(module, name) for module, name in (
            (os, "pidfd_open"), (signal, "pidfd_send_signal"), (socket, "send_fds"))):
        return False
    try:
        os.close(os.pidfd_open(os.getpid()))
    except OSError:
        return False
    return True


def start(func: Callable[..., Any], args: tuple, memory: int | None,
          preload: Sequence[str] = ()) -> tuple[int, int] | None:
    """``func(*args)`` under :func:`.child_call.run_child` in a child the server forks, once
    the server has imported the modules ``preload`` names: the child's pidfd and the
    reading end of its result's pipe, or None where no server can run here."""
    global _failed
    if _failed or not available():
        return None
    payload = pickle.dumps((tuple(preload), func, args, memory),
                           protocol=pickle.HIGHEST_PROTOCOL)
    read, write = os.pipe()
    try:
        with _lock:
            for retry in (False, True):  # a server that died meanwhile is started again
                pidfd = _ask(_connection(retry), payload, write)
                if pidfd is not None:
                    return pidfd, read
            # twice in a row: it cannot run here (srarap not importable by a fresh
            # interpreter, say); not tried again, each call starting two for nothing
            _failed = True
    finally:
        os.close(write)
    os.close(read)
    return None


def reap(pidfd: int, kill: bool) -> None:
    """Wait until the child of ``pidfd`` has ended, killing it first where ``kill``; close
    ``pidfd``. The server reaps it."""
    try:
        if kill:
            signal.pidfd_send_signal(pidfd, signal.SIGKILL)
        readable(pidfd, None)
    except OSError:  # ended already
        pass
    finally:
        os.close(pidfd)


def _connection(restart: bool) -> socket.socket | None:
    global _server
    if _server is not None and restart:
        _close(_server)
        _server = None
    if _server is None:
        ours, theirs = socket.socketpair()
        try:
            process = subprocess.Popen([sys.executable, "-c", _SERVER, str(theirs.fileno())],
                                       pass_fds=[theirs.fileno()], stdin=subprocess.DEVNULL,
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        except (OSError, ValueError, subprocess.SubprocessError):
            ours.close()
            return None
        finally:
            theirs.close()
        _server = (process, ours)
    return _server[1]


def _ask(sock: socket.socket | None, payload: bytes, write: int) -> int | None:
    if sock is None:
        return None
    try:
        socket.send_fds(sock, [_HEAD.pack(len(payload))], [write])
        sock.sendall(payload)
        answer, fds, _, _ = socket.recv_fds(sock, _HEAD.size, 1)
    except OSError:  # the server died: the caller starts another and asks again
        return None
    if len(answer) == _HEAD.size and len(fds) == 1:
        return fds[0]
    for fd in fds:
        os.close(fd)
    return None


def _close(server: tuple[subprocess.Popen, socket.socket]) -> None:
    process, sock = server
    sock.close()
    process.kill()
    process.wait()


def _forget() -> None:
    global _server
    if _server is not None:  # a forked child's copy of the socket: the server is not its
        _server[1].close()
        _server = None


os.register_at_fork(after_in_child=_forget)


def serve(fd: int) -> None:
    """The server's loop on the socket ``fd``: a call in, a child forked, its pidfd out;
    until end of file, when the children still running are killed."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # a Ctrl-C is its parent's to answer
    sock = socket.socket(fileno=fd)
    children: set[int] = set()
    try:
        while True:
            while children and not readable(sock.fileno(), 0.5):
                children -= _reaped(children)  # no zombie kept while it waits
            if (call := _receive(sock)) is None:
                break
            payload, write = call
            pid = _fork_child(sock, payload, write)
            children.add(pid)
            pidfd = os.pidfd_open(pid)  # unreaped until after this: the pid is still its
            try:
                socket.send_fds(sock, [_HEAD.pack(pid)], [pidfd])
            finally:
                os.close(pidfd)
    finally:
        for pid in children - _reaped(children):
            os.kill(pid, signal.SIGKILL)


def _receive(sock: socket.socket) -> tuple[bytes, int] | None:
    head, fds = b"", []
    while len(head) < _HEAD.size:
        chunk, got, _, _ = socket.recv_fds(sock, _HEAD.size - len(head), 1)
        fds += got
        if not chunk:
            return None
        head += chunk
    (size,) = _HEAD.unpack(head)
    payload = bytearray()
    while len(payload) < size:
        chunk = sock.recv(min(size - len(payload), 1 << 20))
        if not chunk:
            return None
        payload += chunk
    return bytes(payload), fds[0]


def _fork_child(sock: socket.socket, payload: bytes, write: int) -> int:
    try:  # here, not in the child: what it imports, later children start with
        preload, func, args, memory = pickle.loads(payload)
        imported(preload)
    except Exception as exc:  # noqa: BLE001 -- the child raises it to the caller
        func, args, memory = _raise, (exc,), None
    pid = os.fork()
    if pid == 0:  # never returns
        sock.close()
        _die_with_parent()
        run_child(write, func, args, memory)
    os.close(write)
    return pid


def _raise(exc: BaseException) -> None:
    raise exc


def _die_with_parent() -> None:
    try:
        import ctypes

        ctypes.CDLL(None).prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # not Linux: the server kills it on its way out
        pass


def _reaped(children: set[int]) -> set[int]:
    done = set()
    for pid in children:
        try:
            if os.waitpid(pid, os.WNOHANG)[0]:
                done.add(pid)
        except ChildProcessError:
            done.add(pid)
    return done
