"""Where a large deform's memory is: what the solver holds after its setup, by owner, and what
is allocated at the run's peak, by allocation site.

`srarap deform -v` gives the peak per stage; this says what makes it up, for the work on the
memory budget (issue 40). It runs the command's own path (``tasks.pipeline.deform_mesh``,
with its allocator settings) in this process and prints:

1. after the setup: resident memory, and the arrays, sparse matrices and factors reachable
   from the solver object, summed by owner (attribute path; closures and bound methods
   followed). An rslab factor is counted at its own ``heap_bytes`` (until 2026-11-28 rslab's
   factors, the largest holders at 1.2M vertices, were not counted at all); a SuperLU factor
   at 4 bytes of index per entry plus its value size, read from the factor (the precision of
   a solve's answer; until 2026-11-26 this guessed single precision from a size, which
   counted the double-precision Poisson factor at two thirds of its size);
2. at the highest resident memory seen during the solve (sampled every 0.3 s): the memory
   numpy and Python had allocated (tracemalloc), by allocation site, and what was not theirs
   (SuperLU, libigl, the allocator's free lists).

tracemalloc slows the run by a few percent; the figures are the run's own, not a benchmark
of its speed. Linux only (``/proc/self/status``).

Run: python benchmarks/memory_census.py out/cylinder-1m.obj benchmarks/cases/cylinder-subdivided.yaml
(the mesh is made by ``benchmarks/multires_large.py --cases cylinder1m``)
"""
import argparse
import collections
import threading
import time
import tracemalloc

import numpy as np
import scipy.sparse as sp

LEAVES = (str, bytes, int, float, bool, type(None), type)


def resident():
    """(VmRSS, VmHWM) in bytes."""
    fields = dict(line.split(":", 1) for line in open("/proc/self/status"))
    return tuple(int(fields[k].split()[0]) * 1024 for k in ("VmRSS", "VmHWM"))


def _bytes(obj):
    if isinstance(obj, np.ndarray):
        return obj.nbytes if obj.base is None else 0
    if sp.issparse(obj):
        return sum(getattr(obj, a).nbytes for a in ("data", "indices", "indptr", "row", "col")
                   if hasattr(obj, a))
    if type(obj).__module__.startswith("rslab"):  # a factor: its own count of its memory
        return int(getattr(obj, "heap_bytes", 0))
    if type(obj).__name__ == "SuperLU":
        # SuperLU answers in its factor's precision, whatever the right-hand side's
        value = obj.solve(np.zeros(obj.shape[0], dtype=np.float32)).itemsize
        return obj.nnz * (4 + value)
    return 0


def _children(obj):
    if hasattr(obj, "__self__") and not isinstance(obj, type):  # a bound method
        return [("", obj.__self__)]
    closure = getattr(obj, "__closure__", None)
    if callable(obj) and closure is not None:
        return [(f"<{obj.__name__}>", cell.cell_contents) for cell in closure]
    if isinstance(obj, dict):
        return [(f"[{k!r}]", v) for k, v in obj.items()]
    if isinstance(obj, (list, tuple, set, frozenset)):
        return [("[]", v) for v in obj]
    if hasattr(obj, "__dict__"):
        return [(f".{k}", v) for k, v in vars(obj).items()]
    return [(f".{s}", getattr(obj, s)) for s in getattr(obj, "__slots__", ()) if hasattr(obj, s)]


def owners(root, name, depth=4):
    """{owner path (its first ``depth`` steps): bytes} of everything reachable from ``root``,
    each object counted once."""
    seen, found = set(), collections.Counter()
    stack = [(root, name, 0)]
    while stack:
        obj, path, steps = stack.pop()
        if id(obj) in seen or isinstance(obj, LEAVES):
            continue
        seen.add(id(obj))
        size = _bytes(obj)
        if size:
            found[path + (" (SuperLU)" if type(obj).__name__ == "SuperLU" else "")] += size
            continue
        for key, child in _children(obj):
            stack.append((child, path + key if steps < depth else path, steps + 1))
    return found


def _print_owners(found, top):
    total = sum(found.values())
    print(f"  reachable from the solver: {total / 1e9:.2f} GB")
    for path, size in found.most_common(top):
        print(f"    {size / 1e6:8.0f} MB  {path}")


def watch_peak(state):
    """Keep a tracemalloc snapshot of the highest resident memory seen."""
    while not state["stop"]:
        rss = resident()[0]
        if rss > state["rss"] + 100e6:
            state.update(rss=rss, snapshot=tracemalloc.take_snapshot(),
                         traced=tracemalloc.get_traced_memory()[0], at=time.perf_counter())
        time.sleep(0.3)


def _print_peak(state, start, top):
    print(f"\nat the highest resident memory seen, {state['rss'] / 1e9:.2f} GB "
          f"({state['at'] - start:.0f} s into the solve):")
    print(f"  numpy and Python (tracemalloc): {state['traced'] / 1e9:.2f} GB; the rest, "
          f"{(state['rss'] - state['traced']) / 1e9:.2f} GB, is not theirs")
    snapshot = state["snapshot"].filter_traces([tracemalloc.Filter(False, tracemalloc.__file__)])
    for stat in snapshot.statistics("traceback")[:top]:
        frames = [f"{f.filename.split('site-packages/')[-1].split('srarap_cli/')[-1]}:{f.lineno}"
                  for f in stat.traceback if "tracemalloc" not in f.filename][-3:]
        print(f"    {stat.size / 1e6:8.0f} MB in {stat.count:3d}  " + " < ".join(reversed(frames)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mesh")
    ap.add_argument("handles")
    ap.add_argument("--top", type=int, default=20)
    args = ap.parse_args()
    tracemalloc.start(8)
    import srarap_cli.tasks.pipeline as pipeline
    from srarap_cli.io.handles import load_handles
    from srarap_cli.io.mesh import read_mesh

    mesh = read_mesh(args.mesh)
    constraints = load_handles(args.handles, mesh.vertices)
    print(f"{args.mesh}: {len(mesh.vertices)} vertices; resident after reading "
          f"{resident()[0] / 1e9:.2f} GB")
    state = {"stop": False, "rss": 0, "start": 0.0}
    command_solver = pipeline.command_solver

    def census_after_setup(*a, **k):
        solver, notes = command_solver(*a, **k)
        rss, hwm = resident()
        print(f"after the setup: resident {rss / 1e9:.2f} GB (peak so far {hwm / 1e9:.2f} GB)")
        _print_owners(owners(solver, "solver"), args.top)
        state["start"] = time.perf_counter()
        threading.Thread(target=watch_peak, args=(state,), daemon=True).start()
        return solver, notes

    pipeline.command_solver = census_after_setup
    pipeline.deform_mesh(mesh, constraints)
    state["stop"] = True
    _print_peak(state, state["start"], args.top)
    print(f"\npeak resident memory of the run: {resident()[1] / 1e9:.2f} GB")


if __name__ == "__main__":
    main()
