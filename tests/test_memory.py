"""Peak resident memory per stage (runtime.memory): nested stages, each stage's own peak."""
import subprocess
import sys

import pytest

from srarap_cli.runtime import memory

pytestmark = pytest.mark.skipif(memory._high_water() is None,
                                reason="no /proc high-water mark here")

MB = 1 << 20


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
print(big, small, memory.stop(outer))
"""


def test_a_stage_sees_the_memory_it_touched_and_a_later_stage_does_not():
    out = subprocess.run([sys.executable, "-c", STAGES], capture_output=True, text=True,
                         check=True).stdout
    big, small, whole = map(int, out.split())
    assert big - small > 150 * MB  # the reset: the second stage did not inherit the first's
    assert whole >= big  # the enclosing stage keeps the peak of everything inside it


def test_closing_an_unmeasured_stage_gives_none_and_formatting_skips_it():
    assert memory.stop(None) is None
    assert memory.gigabytes({"read": None, "solve": 2_500_000_000}) == "solve 2.50 GB"
