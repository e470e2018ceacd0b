"""Write several output files all-or-nothing: all to temporary names, then all renamed."""
import glob
import os
import signal
import tempfile

from .errors import OutputError

#: Paths this process has committed, in order: a signal that arrives after a commit is
#: reported with what was written, not as "no output written".
COMMITTED = []
_SIGNALS = {signal.SIGINT, signal.SIGTERM}


def commit_files(files):
    """Write ``[(path, bytes), ...]``; on any failure no target is created or replaced.

    Every payload goes to a temporary file in its target's folder first; only when all are
    written are they renamed over the targets (a rename within a folder is atomic).
    """
    staged = []
    try:
        for path, data in files:
            staged.append((_stage(path, data), path))
        # the renames and their record are one critical section: a SIGINT/SIGTERM waits
        # until both are done, so the report always matches the files on disk
        blocked = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
        try:
            for tmp, path in staged:
                os.replace(tmp, path)
                COMMITTED.append(path)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
    except OSError as exc:
        raise OutputError(f"{exc.filename or files[0][0]}: cannot write: {exc.strerror}") from None
    finally:
        for tmp, _ in staged:
            if os.path.exists(tmp):
                os.unlink(tmp)


def atomic_write(path, data):
    """Write bytes to ``path`` via a temporary file in the same folder and a rename."""
    commit_files([(path, data)])


def _stage(path, data):
    folder = os.path.dirname(os.path.abspath(path))
    _sweep(folder)
    fd, tmp = tempfile.mkstemp(prefix=f".srarap-{os.getpid()}-", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
    except BaseException:
        os.unlink(tmp)
        raise
    return tmp


def _sweep(folder):
    """Delete temporary files of srarap runs that no longer exist (a SIGKILL during staging
    leaves one behind); the writer's process id is in the name."""
    for tmp in glob.glob(os.path.join(glob.escape(folder), ".srarap-*-*.tmp")):
        try:
            pid = int(os.path.basename(tmp).split("-")[1])
            os.kill(pid, 0)
        except ValueError:  # not a name this module makes: not ours to delete
            continue
        except ProcessLookupError:
            try:
                os.unlink(tmp)
            except OSError:  # another run swept it first: the goal is met either way
                pass
        except OSError:  # alive but not ours to signal: leave it
            continue
