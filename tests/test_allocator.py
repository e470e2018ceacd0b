"""After keep_freed_memory, a large temporary comes from the heap and stays there once freed,
for the next one to reuse (no fresh mapping, no trimming); after one_arena, another thread
allocates from the main arena; the results do not change."""
import os
import subprocess
import sys

import pytest
from helpers import ROOT

CHILD = """
import ctypes, sys
import numpy as np
from srarap_cli.runtime.allocator import keep_freed_memory

class Info(ctypes.Structure):  # glibc's struct mallinfo2
    _fields_ = [(name, ctypes.c_size_t) for name in
                ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks",
                 "uordblks", "fordblks", "keepcost")]

info = ctypes.CDLL(None).mallinfo2
info.restype = Info
if sys.argv[1] == "keep":
    assert keep_freed_memory()
a = np.ones(100 << 17)  # 100 MB
mapped = info().hblkhd
del a
print(mapped >> 20, info().arena >> 20)
"""


def _megabytes(mode):
    out = subprocess.run([sys.executable, "-c", CHILD, mode], capture_output=True, text=True,
                         check=True)
    return [int(x) for x in out.stdout.split()]  # (mapped while alive, heap after free)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_a_large_array_comes_from_the_heap_and_stays_for_reuse():
    mapped, heap = _megabytes("default")
    assert mapped >= 100 and heap < 100  # glibc's default: its own mapping, unmapped on free
    mapped, heap = _megabytes("keep")
    assert mapped < 100 and heap >= 100


ARENAS = """
import ctypes, sys, threading
import numpy as np
from srarap_cli.runtime.allocator import one_arena
if sys.argv[1] == "one":
    assert one_arena()
held = []
thread = threading.Thread(target=lambda: held.append(np.ones(1 << 17)))  # 1 MB from it
thread.start()
thread.join()
ctypes.CDLL(None).malloc_stats()  # one "Arena k:" block per arena, on stderr
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_after_one_arena_another_thread_allocates_from_the_main_arena():
    counts = [subprocess.run([sys.executable, "-c", ARENAS, mode], capture_output=True,
                             text=True, check=True).stderr.count("Arena ")
              for mode in ("default", "one")]
    assert counts == [2, 1]


def test_a_solve_gives_the_same_bytes_with_memory_kept():
    """The Python API leaves the allocator alone: solved once as it is, once after the
    setting, the positions are the same bytes."""
    outs = []
    for mode in ("default", "keep"):
        script = ("import sys, hashlib\n"
                  "from srarap_cli.runtime.allocator import keep_freed_memory\n"
                  + ("keep_freed_memory()\n" if mode == "keep" else "")
                  + "import srarap_cli\n"
                  "from srarap_cli.io.mesh import read_mesh\n"
                  "r = srarap_cli.deform(read_mesh(sys.argv[1]), sys.argv[2])\n"
                  "print(hashlib.sha256(r.positions.tobytes()).hexdigest())\n")
        out = subprocess.run([sys.executable, "-c", script,
                              os.path.join(ROOT, "sample_meshes", "bar.obj"),
                              os.path.join(ROOT, "configs", "bar-twist.yaml")],
                             capture_output=True, text=True, check=True)
        outs.append(out.stdout)
    assert outs[0] == outs[1] and len(outs[0]) > 60
