"""One coarse step of a multiresolution correction, as the nested levels run it: its
milliseconds at each thread count, the share of them inside the factorizations' solves, and
its Python function calls and thread hand-offs (#72).

A correction of the 1.2M cylinder runs ``NESTED_STEPS`` steps of its 153.6k-vertex level,
each corrected in turn by steps of a 19.2k-vertex level (the shared cylinder subdivided once,
the default here): there a step is small enough that what surrounds its two solves (block
maps, thread hand-offs, small numpy calls) shows. The step is the one
``CoarseCorrection._map`` takes: positions from rotors, then the rotors' step, on their
hemispheres.

Thread counts run interleaved, round by round, so a machine that slows down midway hits
them alike; figures are medians. Missing meshes are made into ``out/``. ``--base REV`` runs
REV (a git worktree in ``out/base-REV``, on ``PYTHONPATH``) and the working tree in
alternating processes (each alternating the counts five times) and prints both.

Run: python benchmarks/coarse_step.py [--levels 1] [--threads 1,2] [--rounds 7] [--steps 10]
     [--base REV]
"""
import argparse
import cProfile
import json
import os
import pstats
import statistics
import subprocess
import sys
import time

import numpy as np

from srarap_cli import Deformer
from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh
from srarap_cli.runtime import parallel
from srarap_cli.solver.multires.correction import CoarseCorrection
from srarap_cli.tasks.pipeline import problem

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from paired import alternating  # noqa: E402  (after the sys.path entry)

OUT = os.path.join(os.path.dirname(HERE), "out")
CYLINDER = os.path.join(os.path.dirname(HERE), "..", "shared", "meshes", "cylinder.off")
HANDLES = os.path.join(HERE, "cases", "cylinder-subdivided.yaml")


def coarse_map(levels):
    """The coarse step ``y -> G_c(y)`` of the cylinder subdivided ``levels`` times, and the
    rotors it starts from (three solver iterations in)."""
    path = os.path.join(OUT, f"cylinder-l{levels}.obj")
    if not os.path.exists(path):
        subprocess.run([sys.executable, os.path.join(HERE, "make_big_spot.py"), path,
                        "--levels", str(levels), "--mesh", CYLINDER], check=True)
    mesh = read_mesh(path)
    p = problem(mesh, load_handles(HANDLES, mesh.vertices))
    solver = Deformer(p.V, p.F, p.ids)
    start = solver.solve(p.targets, max_iter=3, tol=0.0)
    n = len(p.V)
    correction = CoarseCorrection(solver.step_for(p.targets), np.arange(n), np.arange(n))
    return correction._map, start.rotors, n


def timed(step, y, threads, steps):
    with parallel.using_threads(threads):
        step(y)  # warm: pools, caches
        begin = time.perf_counter()
        for _ in range(steps):
            step(y)
        return (time.perf_counter() - begin) / steps


def profiled(step, y, threads, steps):
    """Python calls a step, milliseconds a step inside the factorizations' solves, and block
    maps that handed blocks to other threads, a step."""
    handed = [0]
    real = parallel._pool

    def counting(count):
        handed[0] += 1
        return real(count)
    parallel._pool = counting
    profile = cProfile.Profile()
    try:
        with parallel.using_threads(threads):
            profile.enable()
            for _ in range(steps):
                step(y)
            profile.disable()
    finally:
        parallel._pool = real
    stats = pstats.Stats(profile)
    calls = sum(v[1] for v in stats.stats.values())
    solves = sum(v[3] for k, v in stats.stats.items()
                 if k[2] in ("<method 'solve' of 'SuperLU' objects>",)
                 or (k[2] == "solve" and "one_triangle" in k[0]))
    return calls / steps, 1e3 * solves / steps, handed[0] / steps


def one_round(args, counts):
    """This process's tree, one round: per thread count, seconds a step, then the profile's
    figures (printed as JSON)."""
    step, y, n = coarse_map(args.levels)
    seconds = {t: [] for t in counts}
    for _ in range(5):  # the counts alternated inside the process too
        for t in counts:
            seconds[t].append(timed(step, y, t, args.steps))
    out = {"n": n}
    for t in counts:
        out[t] = [statistics.median(seconds[t]), *profiled(step, y, t, args.steps)]
    print(json.dumps(out))


def paired(args, counts):
    """Base and head in alternating processes; medians per tree and thread count."""
    runs = alternating(__file__, ["--one", "--levels", str(args.levels), "--threads",
                                  args.threads, "--steps", str(args.steps)],
                       args.base, args.rounds)
    n = runs["head"][0]["n"]
    print(f"coarse step of {n} vertices, base {args.base} against the working tree, "
          f"medians of {args.rounds} alternating processes of {args.steps} steps "
          f"({parallel.available_cpus()} CPUs)")
    print(f"{'tree':>5} {'threads':>7} {'ms/step':>8} {'solves ms':>9} {'calls':>7} "
          f"{'hand-offs':>9}")
    for name in ("base", "head"):
        for t in counts:
            rows = [r[str(t)] for r in runs[name]]
            ms, calls, solves, handed = (statistics.median(r[k] for r in rows) for k in range(4))
            print(f"{name:>5} {t:>7} {1e3 * ms:8.1f} {solves:9.1f} {calls:7.0f} {handed:9.1f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", type=int, default=1)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--base")
    ap.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    counts = [int(t) for t in args.threads.split(",")]
    if args.one:
        return one_round(args, counts)
    if args.base:
        return paired(args, counts)
    step, y, n = coarse_map(args.levels)
    seconds = {t: [] for t in counts}
    for _ in range(args.rounds):
        for t in counts:
            seconds[t].append(timed(step, y, t, args.steps))
    base = statistics.median(seconds[counts[0]])
    print(f"coarse step of {n} vertices, medians of {args.rounds} rounds of {args.steps} "
          f"steps ({parallel.available_cpus()} CPUs)")
    print(f"{'threads':>7} {'ms/step':>8} {'ratio':>6} {'solves ms':>9} {'outside':>7} "
          f"{'calls':>7} {'hand-offs':>9}")
    for t in counts:
        ms = 1e3 * statistics.median(seconds[t])
        calls, solves, handed = profiled(step, y, t, args.steps)
        print(f"{t:>7} {ms:8.1f} {statistics.median(seconds[t]) / base:6.2f} {solves:9.1f} "
              f"{1 - solves / ms:7.0%} {calls:7.0f} {handed:9.1f}")


if __name__ == "__main__":
    main()
