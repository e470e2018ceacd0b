"""One BLAS thread for srarap's numerical work.

The results must not depend on the machine's thread settings: OpenBLAS splits dot products
and matrix products by thread count, which changed the last digits of a solve (4,125 of
4,802 lines of a cylinder's output differed between 1 and 2 threads). The threads bought
nothing either: the work here is sparse (SuperLU, Eigen, scipy's sparse products are single
threaded) and the dense BLAS calls are small, so a second thread only added CPU time, and
under load (``batch --workers 2`` on 2 cores) it slowed everything down. Parallelism comes from
running jobs side by side (``batch --workers``).
"""
import functools
import os

_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def single_threaded(func):
    """Run ``func`` with every BLAS library limited to one thread (threadpoolctl)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            return func(*args, **kwargs)

    return wrapper


def pin_process():
    """Ask the BLAS libraries for one thread before they load (the command line calls this
    first; libraries already loaded keep their pools, which :func:`single_threaded` limits)."""
    for name in _VARIABLES:
        os.environ[name] = "1"
