"""Re-solving after a small change of the targets: warm starts against cold solves.

For each case: solve the case's targets (cold), then change them (``--change``, by ``--size``)
and solve again three ways, each ``--repeat`` times: cold; warm from the first
result with the default warm start (``start="warm"``: the handles' rotations spread, and the
first-order response of the solved state to the move, :mod:`srarap_cli.solver.linear_response`);
and warm with the handles' rotations only (``start="extrapolated"``, the warm start before the
response). Prints full-resolution iterations, median seconds (the solve call; the response's
one-time preconditioner factor is paid by a first warm solve not counted, and reported apart),
the distance to a tight solve (tol 1e-11) over the bounding-box diagonal, and the ratios of
the warm solves to the cold one.

Changes: ``scale`` every target by 1 + size (default, size 0.01: a 1% change); ``shift`` the
handle group that moved most by size times the diagonal; ``turn`` that group by size degrees
about its centre; ``noise``: every target moved by size times the diagonal times a normal
sample (seeded); ``rest``: the case's own targets with the rest shape (rotors 1) as ``initial``.

Run: python benchmarks/warm_solve.py [--cases bar,cylinder,max,spot] [--repeat 5]
     [--change scale|shift|turn|noise|rest] [--size 0.01]
     (spot184k: out/spot-184k.obj, made by make_big_spot.py; coarse-to-fine)
"""
import argparse
import os
import statistics
import subprocess
import sys
import time

import numpy as np
from run_bench import CASES, HERE, OUT, ROOT

from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh
from srarap_cli.solver.oneshot import make_deformer
from srarap_cli.solver.quaternion import IDENTITY, from_axis_angle, to_matrix
from srarap_cli.tasks.pipeline import problem

CASES = {**CASES,
         "bar": (os.path.join(ROOT, "sample_meshes", "bar.obj"),
                 os.path.join(ROOT, "configs", "bar-twist.yaml")),
         "spot184k": (os.path.join(OUT, "spot-184k.obj"),
                      os.path.join(ROOT, "configs", "spot-nod.yaml"))}


def timed(solve, repeat):
    """(last result, median seconds) of ``repeat`` calls."""
    seconds = []
    for _ in range(repeat):
        mark = time.perf_counter()
        result = solve()
        seconds.append(time.perf_counter() - mark)
    return result, statistics.median(seconds)


def changed(p, first, change, size):
    """(new targets, initial) for the change ``change`` of size ``size`` (see above)."""
    diagonal = float(np.linalg.norm(np.ptp(p.V, axis=0)))
    labels = np.asarray(p.labels)
    moved = [np.abs(p.targets[labels == g] - p.V[p.ids][labels == g]).max()
             for g in range(labels.max() + 1)]
    group = labels == int(np.argmax(moved))
    T = p.targets.copy()
    initial = (first.positions, first.rotors)
    if change == "scale":
        T *= 1 + size
    elif change == "shift":
        T[group] += size * diagonal * np.array([0.6, 0.8, 0.0])
    elif change == "turn":
        centre = T[group].mean(axis=0)
        turn = to_matrix(from_axis_angle([0.3, 1.0, 0.2], size))
        T[group] = (T[group] - centre) @ turn.T + centre
    elif change == "noise":
        T += size * diagonal * np.random.default_rng(0).standard_normal(T.shape)
    else:
        initial = (p.V, np.tile(IDENTITY, (len(p.V), 1)))
    return T, initial


def run_case(name, args):
    mesh_path, handles = CASES[name]
    if name == "spot184k" and not os.path.exists(mesh_path):
        subprocess.run([sys.executable, os.path.join(HERE, "make_big_spot.py"), mesh_path],
                       check=True)
    mesh = read_mesh(mesh_path)
    p = problem(mesh, load_handles(handles, mesh.vertices))
    solver = make_deformer(p.V, p.F, p.ids, p.labels)
    first = solver.solve(p.targets)
    new, initial = changed(p, first, args.change, args.size)
    tight = solver.solve(new, tol=1e-11, max_iter=5000)
    diagonal = float(np.linalg.norm(np.ptp(p.V, axis=0)))
    mark = time.perf_counter()
    solver.solve(new, initial=initial)  # builds the response's preconditioner once
    once = time.perf_counter() - mark
    runs = {"cold": lambda: solver.solve(new),
            "warm": lambda: solver.solve(new, initial=initial),
            "extrapolated": lambda: solver.solve(new, initial=initial, start="extrapolated")}
    row = {"case": name, "vertices": len(p.V), "first warm solve s": once}
    for kind, solve in runs.items():
        result, seconds = timed(solve, args.repeat)
        row[kind] = (result.iterations, seconds,
                     float(np.abs(result.positions - tight.positions).max() / diagonal),
                     result.converged)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default="bar,cylinder,max,spot")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--change", default="scale",
                    choices=("scale", "shift", "turn", "noise", "rest"))
    ap.add_argument("--size", type=float, default=0.01)
    args = ap.parse_args()
    print(f"change {args.change} {args.size:g}; iterations / median seconds of {args.repeat} / "
          "distance to a tight solve over the diagonal\n")
    print("| case | vertices | cold | warm | warm, rotations only | warm/cold iterations, "
          "seconds | first warm solve |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name in args.cases.split(","):
        row = run_case(name, args)
        cells = [f"{it} / {s:.3f} s / {dist:.1e}" + ("" if ok else " (not converged)")
                 for it, s, dist, ok in (row[k] for k in ("cold", "warm", "extrapolated"))]
        ratio = (f"{row['warm'][0] / row['cold'][0]:.2f}, {row['warm'][1] / row['cold'][1]:.2f}")
        print(f"| {name} | {row['vertices']:,} | {' | '.join(cells)} | {ratio} | "
              f"{row['first warm solve s']:.3f} s |", flush=True)


if __name__ == "__main__":
    main()
