"""What a second thread can buy on this machine: the same work twice, side by side on two
threads against one after the other, for three kinds of work a solve is made of.

- compute: dense products of 200 x 200 matrices (in cache; BLAS at one thread per call);
- stream: ``b = a + 1`` over arrays of 32 MB each, out of any cache (what the solver's
  vertex-wise stages do at 500k-1.2M vertices);
- gather: rows of a (1.2M, 4) array taken in a random order (the per-edge gathers).

Each thread has its own arrays, touched before the clock starts. The ratio is the side-by-side
time over the one-after-the-other time: 0.5 means the second core doubled the rate, 1.0 that
it bought nothing (the work waits on memory both cores share). A solve's 2-thread ratio cannot
go below its stages' ratios here, weighted by their time (see the performance page).

Run: python benchmarks/machine_threads.py [--repeat 7]
"""
import argparse
import os
import statistics
import threading
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one BLAS thread, as srarap's solves

import numpy as np  # noqa: E402 -- OpenBLAS reads its thread count when numpy loads it


def compute():
    a = np.random.default_rng(0).random((200, 200))

    def work():
        for _ in range(300):
            a @ a
    return work


def stream():
    a, b = np.ones(4_000_000), np.zeros(4_000_000)

    def work():
        for _ in range(30):
            np.add(a, 1.0, out=b)
    return work


def gather():
    rng = np.random.default_rng(1)
    rows, order = rng.random((1_228_802, 4)), rng.permutation(1_228_802)
    out = np.empty_like(rows)

    def work():
        for _ in range(6):
            np.take(rows, order, axis=0, out=out)
    return work


KINDS = {"compute": compute, "stream": stream, "gather": gather}


def ratio(make):
    """Side-by-side seconds over one-after-the-other seconds, and the latter."""
    one, two = make(), make()
    one(), two()  # first touch and warm caches outside the clock
    mark = time.perf_counter()
    one()
    two()
    serial = time.perf_counter() - mark
    threads = [threading.Thread(target=w) for w in (one, two)]
    mark = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return (time.perf_counter() - mark) / serial, serial


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    print(f"{os.cpu_count()} CPUs; medians of {args.repeat} (min-max)")
    print("| work | one after the other | side by side / one after the other |")
    print("|---|---:|---:|")
    for name, make in KINDS.items():
        runs = [ratio(make) for _ in range(args.repeat)]
        r = [x for x, _ in runs]
        print(f"| {name} | {statistics.median(s for _, s in runs):.3f} s | "
              f"{statistics.median(r):.2f} ({min(r):.2f}-{max(r):.2f}) |")


if __name__ == "__main__":
    main()
