"""Peak resident memory per stage (runtime.memory): nested stages, each stage's own peak."""
import subprocess
import sys

import pytest

from srarap_cli.runtime import memory

pytestmark = pytest.mark.skipif(memory._high_water() is None,
                                reason="no /proc high-water mark here")

MB = 1 << 20
# the kernel counts resident pages per CPU and folds them in batches, so VmRSS and VmHWM
# are each a few pages off (256 KB on 2 cores, more with more cores): far below the 200 MB
# that a reset mark or an inherited peak would show
SLACK = 16 * MB


# in a fresh process: one whose allocator keeps freed memory resident (the solver's setup
# asks glibc to) would reuse it, and a stage's peak would not rise
STAGES = """
import numpy as np
from srarap_cli.runtime import memory
assert memory.start() is None  # off until enabled
memory.enable()

def touch(megabytes):
    block = np.ones(megabytes * (1 << 20) // 8)
    del block

outer = memory.start()
first = memory.start()
touch(200)
big = memory.stop(first)
second = memory.start()
touch(20)
small = memory.stop(second)
whole = memory.stop(outer)
import resource
print(big, small, whole, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
      memory.status_bytes("VmHWM"))
"""


def test_a_stage_sees_the_memory_it_touched_and_a_later_stage_does_not():
    out = subprocess.run([sys.executable, "-c", STAGES], capture_output=True, text=True,
                         check=True).stdout
    big, small, whole, maxrss, hwm = map(int, out.split())
    assert big - small > 150 * MB  # the second stage did not inherit the first's peak
    assert whole >= big  # the enclosing stage keeps the peak of everything inside it
    # nothing reset what the kernel says of the process (/usr/bin/time, ru_maxrss): the
    # process's peak is the largest stage's, as -v says it
    assert maxrss >= big - SLACK and abs(hwm - whole) < SLACK


def test_closing_an_unmeasured_stage_gives_none_and_formatting_skips_it():
    assert memory.stop(None) is None
    assert memory.gigabytes({"read": None, "solve": 2_500_000_000}) == "solve 2.50 GB"
