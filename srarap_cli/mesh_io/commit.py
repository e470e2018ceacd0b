"""Write several output files all-or-nothing: all to temporary names, then all renamed."""
import os
import tempfile

from ..errors import OutputError


def commit_files(files):
    """Write ``[(path, bytes), ...]``; on any failure no target is created or replaced.

    Every payload goes to a temporary file in its target's folder first; only when all are
    written are they renamed over the targets (a rename within a folder is atomic).
    """
    staged = []
    try:
        for path, data in files:
            staged.append((_stage(path, data), path))
        for tmp, path in staged:
            os.replace(tmp, path)
    except OSError as exc:
        raise OutputError(f"{exc.filename or files[0][0]}: cannot write: {exc.strerror}") from None
    finally:
        for tmp, _ in staged:
            if os.path.exists(tmp):
                os.unlink(tmp)


def _stage(path, data):
    fd, tmp = tempfile.mkstemp(prefix=".srarap-", suffix=".tmp",
                               dir=os.path.dirname(os.path.abspath(path)))
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
