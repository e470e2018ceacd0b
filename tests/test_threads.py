"""The background helper that overlaps the full-resolution setup with the simplification."""
import threading

import pytest

from srarap_cli.runtime.threads import background


def test_background_returns_the_result_computed_in_another_thread():
    seen = {}

    def work():
        seen["thread"] = threading.current_thread()
        return [1, 2, 3]

    wait = background(work)
    assert wait() == [1, 2, 3]
    assert seen["thread"] is not threading.main_thread() and seen["thread"].daemon


def test_background_raises_the_exception_of_its_function_when_waited_on():
    def fail():
        raise ValueError("bad mesh")

    wait = background(fail)
    with pytest.raises(ValueError, match="bad mesh"):
        wait()


def _blas_threads():
    import numpy  # noqa: F401  (loads the BLAS library)
    from threadpoolctl import threadpool_info
    return {i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"}


def test_background_work_keeps_one_blas_thread_after_the_call_that_started_it_returns():
    # a multiresolution setup returns while its full-resolution factorization still runs
    from threadpoolctl import threadpool_limits

    from srarap_cli.runtime.parallel import numerics
    with threadpool_limits(limits=2, user_api="blas"):
        assert _blas_threads() == {2}  # the host's setting, which the solver must not see
        returned, seen = threading.Event(), {}

        def factor():
            returned.wait(10)
            seen["during"] = _blas_threads()
            return "factored"

        wait = numerics(lambda: background(factor))()
        seen["between"] = _blas_threads()
        returned.set()
        assert wait() == "factored"
        assert seen == {"between": {1}, "during": {1}}
        assert _blas_threads() == {2}  # given back once the last user is done


ARENA_PROBE = """
import ctypes, os, sys, tempfile, threading
if sys.argv[1] == "pinned":
    from srarap_cli.runtime.threads import pin_process
    pin_process()

def work():
    for _ in range(20):
        kept = [bytearray(1000) for _ in range(100)]
        del kept

threads = [threading.Thread(target=work) for _ in range(4)]
for t in threads:
    t.start()
for t in threads:
    t.join()
libc = ctypes.CDLL(None)
libc.fopen.restype = ctypes.c_void_p
path = tempfile.mktemp()
fp = libc.fopen(path.encode(), b"w")
libc.malloc_info(0, ctypes.c_void_p(fp))
libc.fclose(ctypes.c_void_p(fp))
print(open(path).read().count("<heap nr="))
os.unlink(path)
"""


def test_the_command_line_keeps_every_threads_allocations_in_one_malloc_arena():
    import ctypes
    import subprocess
    import sys
    if not hasattr(ctypes.CDLL(None), "malloc_info"):
        pytest.skip("not glibc: no per-thread arenas")
    heaps = {how: int(subprocess.run([sys.executable, "-c", ARENA_PROBE, how], check=True,
                                     capture_output=True, text=True, timeout=120).stdout)
             for how in ("pinned", "free")}
    assert heaps["free"] > 1  # the threads did get arenas of their own by default
    assert heaps["pinned"] == 1
