"""Subnormal flushing: inside the block and its thread only; single-precision factors use it."""
import threading

import numpy as np
import scipy.sparse as sp

from srarap_cli.runtime import fpu
from srarap_cli.solver import linalg

TINY = np.array([1e-39], dtype=np.float32)  # a float32 subnormal


def _flushes():
    """Whether this thread flushes float32 subnormals now."""
    return float((TINY * 1)[0]) == 0.0


def test_subnormals_flush_inside_the_block_only_where_supported():
    assert not _flushes()
    with fpu.subnormals_flushed():
        inside = _flushes()
    assert inside == (fpu._LIBM is not None)
    assert not _flushes()


def test_the_setting_stays_in_the_thread_that_made_it():
    seen = []
    entered, done = threading.Event(), threading.Event()

    def other():
        entered.wait()
        seen.append(_flushes())
        done.set()

    thread = threading.Thread(target=other)
    thread.start()
    with fpu.subnormals_flushed():
        entered.set()
        done.wait()
    thread.join()
    assert seen == [False]


def test_the_setting_is_restored_after_an_exception():
    try:
        with fpu.subnormals_flushed():
            raise KeyError("x")
    except KeyError:
        pass
    assert not _flushes()


def test_a_single_precision_factor_whose_fill_decays_to_subnormals_still_solves(monkeypatch):
    """A shifted grid Laplacian: its LU fill decays by about 1/40 a step, to below 1e-38 in
    single precision. The approximate solve stays within single precision of the exact one,
    and leaves the thread's arithmetic as it found it."""
    k = 60
    grid = sp.diags([-1.0, -1.0], [-1, 1], shape=(k, k))
    A = (sp.kronsum(grid, grid) + 40.0 * sp.eye(k * k)).tocsr()
    b = np.random.default_rng(5).standard_normal((k * k, 4))
    monkeypatch.setattr(linalg, "LARGE", 0)
    x = linalg.factor(A, symmetric=True, approximate=True)(b)
    assert not _flushes()
    exact = linalg.factor(A, symmetric=True)(b)
    assert np.abs(x - exact).max() / np.abs(exact).max() < 1e-5
    assert np.abs(A @ exact - b).max() < 1e-10
