"""Jobs for tests/test_worker_pool.py: importable by name in worker processes, whichever way
they start (forked, or from a fork server that imports this module from the tests folder)."""
import os
import signal
import time


def run(job):
    """``job``: (name, marker path or None). ``kill`` kills its worker every time;
    ``kill-once`` only when the marker file does not exist yet (it makes it first)."""
    name, marker = job
    if name == "kill" or (name == "kill-once" and _first(marker)):
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(0.05)
    return {"job": name, "pid": os.getpid()}


def lost(job, exitcode):
    return {"job": job[0], "lost": exitcode}


def _first(marker):
    try:
        os.close(os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except FileExistsError:
        return False
    return True
