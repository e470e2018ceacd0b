"""When this process started its work, for the wall seconds a summary reports."""
import time

#: perf_counter() when srarap was first imported in this process (the console entry imports
#: this before anything else)
STARTED = time.perf_counter()


def elapsed() -> float:
    """Wall seconds since :data:`STARTED`."""
    return time.perf_counter() - STARTED
