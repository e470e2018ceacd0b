"""A meshio-format read beside other threads (a test runner's, a notebook's, a Dask
worker's): each read is bounded in a child, which the process may not fork. Forked by the
child server (``runtime/child_server.py``, one fresh interpreter kept for the process)
against a fresh interpreter per read (what ran before it, and what runs where there are no
pidfds), in the same run, alternating; with the read in this process, unbounded, as the
floor. Medians of ``--repeat`` reads of the sample bar written as VTU; the first served read
(it starts the server) is reported apart.

Run: python benchmarks/bounded_read.py [--repeat 15] [--ext vtu]
"""
import argparse
import os
import statistics
import tempfile
import threading
import time

from srarap_cli.io.mesh import read_mesh, write_mesh
from srarap_cli.runtime import child_server

HERE = os.path.dirname(os.path.abspath(__file__))
BAR = os.path.join(HERE, "..", "sample_meshes", "bar.obj")


def timed(path):
    start = time.perf_counter()
    read_mesh(path)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--ext", default="vtu", help="the file's extension (a meshio format)")
    args = parser.parse_args()
    done = threading.Event()
    beside = threading.Thread(target=done.wait)  # this process now runs other threads
    beside.start()
    served_available = child_server.available
    try:
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, f"bar.{args.ext}")
            write_mesh(path, read_mesh(BAR))
            first = timed(path)
            times = {"served": [], "fresh": [], "here": []}
            for _ in range(args.repeat):
                times["served"].append(timed(path))
                child_server.available = lambda: False
                times["fresh"].append(timed(path))
                child_server.available = served_available
                os.environ["SRARAP_BOUNDED"] = "0"
                times["here"].append(timed(path))
                del os.environ["SRARAP_BOUNDED"]
    finally:
        child_server.available = served_available
        done.set()
        beside.join()
    median = {way: statistics.median(t) for way, t in times.items()}
    print(f"{args.ext} read of the bar beside a thread, medians of {args.repeat}:")
    print(f"  in this process, unbounded:        {median['here'] * 1e3:8.1f} ms")
    print(f"  forked by the child server:        {median['served'] * 1e3:8.1f} ms"
          f"  (the first, starting it: {first * 1e3:.0f} ms)")
    print(f"  a fresh interpreter per read:      {median['fresh'] * 1e3:8.1f} ms"
          f"  ({median['fresh'] / median['served']:.1f}x the served read)")


if __name__ == "__main__":
    main()
