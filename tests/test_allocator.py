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
from srarap_cli.runtime.allocator import keep_freed_memory, own_process

class Info(ctypes.Structure):  # glibc's struct mallinfo2
    _fields_ = [(name, ctypes.c_size_t) for name in
                ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks",
                 "uordblks", "fordblks", "keepcost")]

info = ctypes.CDLL(None).mallinfo2
info.restype = Info
if sys.argv[1] == "keep":
    own_process()  # a command's process: the policy applies
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
from srarap_cli.runtime.allocator import own_process
if sys.argv[1] == "one":
    assert own_process()
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


def test_the_python_api_leaves_its_callers_allocator_alone_and_a_command_sets_it(tmp_path):
    """Issue 72: the one-arena and keep-freed-memory settings were applied from the
    pipeline that the public ``deform_mesh`` calls. In a fresh process: ``deform``,
    ``deform_mesh`` and ``Deformer`` call no mallopt; ``srarap deform`` does (each call is
    written to a file: the command ends its process without Python's exit handlers)."""
    calls = tmp_path / "calls.txt"
    code = f"""
import os, sys
from srarap_cli.runtime import allocator
def mallopt(param, value):
    with open({str(calls)!r}, "a") as fh:
        fh.write(f"{{param}}\\n")
    return 1
allocator._mallopt = lambda: mallopt
import numpy as np
import srarap_cli
bar = srarap_cli.read_mesh(os.path.join({ROOT!r}, "sample_meshes", "bar.obj"))
twist = os.path.join({ROOT!r}, "configs", "bar-twist.yaml")
srarap_cli.deform(bar, twist)
srarap_cli.deform_mesh(bar, srarap_cli.load_handles(twist, bar.vertices))
V, F = bar.vertices, bar.triangles()[0]
srarap_cli.Deformer(V, F, np.array([0, 1, 2])).solve(V[[0, 1, 2]])
with open({str(calls)!r}, "a") as fh:
    fh.write("api done\\n")
from srarap_cli.entry import main
sys.argv = ["srarap", "deform", os.path.join({ROOT!r}, "sample_meshes", "bar.obj"), twist,
            "-o", os.devnull, "-q"]
main()
"""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    lines = calls.read_text().splitlines()
    assert lines[0] == "api done" and len(lines) >= 5, lines  # one arena, then three more
