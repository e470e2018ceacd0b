"""Peak resident memory per stage (runtime.memory): nested stages, each stage's own peak."""
import numpy as np
import pytest

from srarap_cli.runtime import memory

pytestmark = pytest.mark.skipif(memory.start() is None, reason="no /proc high-water mark here")

MB = 1 << 20


def _touch(megabytes):
    """Resident memory of that size for a moment (written, so the pages are real)."""
    block = np.ones(megabytes * MB // 8)
    del block


def test_a_stage_sees_the_memory_it_touched_and_a_later_stage_does_not():
    outer = memory.start()
    first = memory.start()
    _touch(200)
    big = memory.stop(first)
    second = memory.start()
    _touch(20)
    small = memory.stop(second)
    whole = memory.stop(outer)
    assert big - small > 150 * MB  # the reset: the second stage did not inherit the first's
    assert whole >= big  # the enclosing stage keeps the peak of everything inside it


def test_closing_an_unmeasured_stage_gives_none_and_formatting_skips_it():
    assert memory.stop(None) is None
    assert memory.gigabytes({"read": None, "solve": 2_500_000_000}) == "solve 2.50 GB"
