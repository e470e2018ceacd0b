"""Write several output files all-or-nothing: all to temporary names, then all renamed.

Only regular files (new ones, or existing ones reached directly or through a symbolic link)
are staged and renamed. A target that is not a regular file (a character device such as
``/dev/null``, a named pipe, a terminal) or that names an open descriptor (``/dev/stdout``,
``/proc/self/fd/N``) is written through, in place: renaming over it would replace the device
or the pipe, which a reader (or the system) is using, with a regular file.
"""
import glob
import os
import re
import secrets
import shutil
import signal
import stat
import tempfile

from .errors import OutputError
from .paths import leads_out

#: Paths this process has committed, in order: a signal that arrives after a commit is
#: reported with what was written, not as "no output written".
COMMITTED: list[str] = []
_SIGNALS = {signal.SIGINT, signal.SIGTERM}


def commit_files(files: list[tuple[str, bytes]], inside: str | None = None) -> None:
    """Write ``[(path, bytes), ...]`` as one unit: on any failure every target is left exactly
    as it was (not created, or its old content).

    ``inside``: a folder every target must stay in, symbolic links followed, checked before
    anything is written and again just before the renames (a batch's ``-o``: a link in it,
    made before the run or while it goes on, must not carry a file anywhere else).

    Every payload goes to a temporary file in its target's folder first; only when all are
    written are they renamed over the targets (a rename within a folder is atomic). A target
    that existed is kept under a temporary name (a hard link) until every rename succeeded, so
    a rename that fails late (the target became a folder, the disk went read-only) puts back
    what the earlier ones replaced. A symbolic link is followed: its target is replaced, the
    link kept. Targets that are not regular files are written through after every regular
    one was staged and before any is renamed, so a failed write through (``/dev/full``)
    leaves every regular target as it was.
    """
    staged: list = []
    made: list[str] = []  # folders this commit made, to remove again should it fail
    done = False
    _stay_inside(files, inside)
    try:
        _make_folders([path for path, _ in files], made)
        through = []
        for path, data in files:
            if _writes_through(path):
                through.append((path, data))
            else:
                target = _link_target(path) if os.path.islink(path) else path
                staged.append((_named(path, _stage, target, data), target))
        for path, data in through:
            _named(path, _write_through, path, data)
        # the renames and their record are one critical section: a SIGINT/SIGTERM waits
        # until both are done, so the report always matches the files on disk
        blocked = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
        try:
            _stay_inside(files, inside)
            _replace_all(staged)
            done = True
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
    finally:
        for tmp, _ in staged:
            _remove(tmp)
        if not done:
            _remove_folders(made)


def _stay_inside(files, inside):
    """OutputError for the first target that leads out of ``inside`` (None: no folder)."""
    if inside is None:
        return
    for path, _ in files:
        target = leads_out(path, inside)
        if target is not None:
            raise OutputError(f"{path}: leads out of the output folder {inside} (through a "
                              f"symbolic link, to {target}); nothing written")


def _make_folders(paths, made):
    """Make the missing folders of ``paths`` (every command's rule: an output's folder is
    made when it is written), each added to ``made`` as it is made."""
    for path in paths:
        folder = os.path.dirname(os.path.abspath(path))
        missing = []
        while not os.path.exists(folder):
            missing.append(folder)
            folder = os.path.dirname(folder)
        for folder in reversed(missing):
            _named(folder, os.mkdir, folder)
            made.append(folder)


def _remove_folders(made):
    for folder in reversed(made):  # deepest first
        try:
            os.rmdir(folder)
        except OSError:  # not empty after all: something else wrote there
            pass


def _replace_all(staged):
    done = []  # (path, kept copy of its old content or None), each already replaced
    try:
        for tmp, path in staged:
            kept = _named(path, _keep, path)
            try:
                _named(path, os.replace, tmp, path)
            except BaseException:
                _remove(kept)
                raise
            done.append((path, kept))
    except BaseException:
        for path, kept in reversed(done):
            _restore(path, kept)
        raise
    COMMITTED.extend(path for _, path in staged)
    for _, kept in done:
        _remove(kept)


def _link_target(path):
    """Where the symbolic link ``path`` leads (the file to replace); a link that leads
    nowhere it can end (a loop) is an output error, as the shell's ELOOP: replacing the
    link with a file would write where the user did not ask."""
    try:
        return os.path.realpath(path, strict=True)
    except FileNotFoundError:  # a dangling link: its target is made
        return os.path.realpath(path)
    except OSError as exc:
        raise OutputError(f"{path}: cannot write: {exc.strerror or exc} (a symbolic link "
                          "that leads back to itself)") from None


def _writes_through(path):
    """Whether ``path`` is written in place: it exists and is not a regular file or a folder
    (device, pipe, socket), or it names a descriptor (under /dev or /proc)."""
    try:
        mode = os.stat(path).st_mode
    except OSError:  # nothing there yet (or unreachable: the staging reports why)
        return False
    if stat.S_ISDIR(mode):
        return False
    return not stat.S_ISREG(mode) or os.path.abspath(path).startswith(("/dev/", "/proc/"))


def _write_through(path, data):
    with open(path, "wb") as fh:
        fh.write(data)
    COMMITTED.append(path)


def _restore(path, kept):
    try:
        if kept is None:
            os.unlink(path)
        else:
            os.replace(kept, path)
    except OSError:  # nothing more can be done; the failure being reported stays the cause
        pass


def _named(path, func, *args):
    """``func(*args)``, with an OSError reported against the user's ``path`` (not a
    temporary name)."""
    try:
        return func(*args)
    except BrokenPipeError:  # a reader went away (``-o /dev/stdout | head``): not an error
        raise
    except OSError as exc:
        reason = "is a folder" if isinstance(exc, IsADirectoryError) or os.path.isdir(path) \
            else f"cannot write: {exc.strerror or exc}"
        raise OutputError(f"{path}: {reason}") from None


def _keep(path):
    """A temporary hard link to the existing regular file ``path`` (None if there is none)."""
    if os.path.isdir(path):
        raise IsADirectoryError(path)
    if not os.path.isfile(path):
        return None
    kept = os.path.join(os.path.dirname(os.path.abspath(path)),
                        f".srarap-{os.getpid()}-{secrets.token_hex(6)}.tmp")
    try:
        os.link(path, kept)
    except OSError:  # a file system without hard links: a copy does the same job
        shutil.copy2(path, kept)
    return kept


def _remove(tmp):
    if tmp is not None and os.path.lexists(tmp):
        try:
            os.unlink(tmp)
        except OSError:  # swept already, or the folder went away: nothing left to clean
            pass


def atomic_write(path: str | os.PathLike, data: bytes) -> None:
    """Write bytes to ``path`` via a temporary file in the same folder and a rename."""
    commit_files([(os.fspath(path), data)])


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


#: what :func:`_stage` names a file: its process id, then mkstemp's random characters
_OURS = re.compile(r"\.srarap-([1-9][0-9]{0,9})-[a-z0-9_]{1,32}\.tmp")


def _writer(name):
    """The process id in a name :func:`_stage` makes, or None for any other name (a
    stranger's file, an id no process can have): such a file is never ours to delete."""
    found = _OURS.fullmatch(name)
    if found is None:
        return None
    pid = int(found[1])
    return pid if pid <= _pid_max() else None


def _pid_max():
    try:
        with open("/proc/sys/kernel/pid_max") as fh:
            return int(fh.read())
    except (OSError, ValueError):
        return 2 ** 22  # Linux's largest


def _sweep(folder):
    """Delete temporary files of srarap runs that no longer exist (a SIGKILL during staging
    leaves one behind); the writer's process id is in the name."""
    for tmp in glob.glob(os.path.join(glob.escape(folder), ".srarap-*-*.tmp")):
        pid = _writer(os.path.basename(tmp))
        if pid is None:  # not a name this module makes: not ours to delete
            continue
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            try:
                os.unlink(tmp)
            except OSError:  # another run swept it first: the goal is met either way
                pass
        except OSError:  # alive but not ours to signal: leave it
            continue
