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
