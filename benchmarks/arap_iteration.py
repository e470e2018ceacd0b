"""Per-iteration time of our classic `arap` against libigl's ARAP, interleaved.

`srarap bench` runs the methods one after the other, so a machine that slows down midway
skews their ratio. Here both solvers advance the same problem in alternating blocks of
iterations (ours: `Deformer(method="arap", weights="cotan")`, the setting `bench` uses;
libigl: `arap_precomputation` with the spokes energy and `arap_solve` one iteration per
call), so drift hits both alike. Our iteration includes what `deform` does every iteration
(the energy for the log and stopping test at `--tol`); libigl's does not evaluate an energy.

Prints per case the median milliseconds per iteration of each, and libigl/ours (> 1: ours is
faster), as the median over `--rounds` rounds of per-round ratios.

Run: python benchmarks/arap_iteration.py [--cases cylinder,max,spot,bar100k] [--rounds 15]
"""
import argparse
import os
import statistics
import sys
import time

import igl
import numpy as np

from srarap_cli import Deformer
from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh
from srarap_cli.tasks.pipeline import problem

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from run_bench import BIG_BAR, CASES  # noqa: E402  (after the sys.path entry)


def interleaved(p, rounds, block, tol):
    """Median ms/iteration of ours and libigl's, and the median of per-round ratios."""
    ours_solver = Deformer(p.V, p.F, p.ids, weights="cotan", method="arap")
    data = igl.ARAPData()
    data.max_iter = 1
    data.energy = igl.ARAP_ENERGY_TYPE_SPOKES
    igl.arap_precomputation(p.V, p.F, 3, p.ids.astype(np.int32), data)
    start = ours_solver.solve(p.targets, max_iter=0)
    state, U = (start.positions, start.rotors), start.positions.copy()
    ours, theirs, ratios = [], [], []
    for _ in range(rounds):
        r = ours_solver.solve(p.targets, max_iter=block, tol=tol, initial=state)
        state = (r.positions, r.rotors)
        mine = list(np.diff([row["seconds"] for row in r.log]))
        peer = []
        for _ in range(block):
            t = time.perf_counter()
            U = igl.arap_solve(p.targets, data, U)
            peer.append(time.perf_counter() - t)
        ours += mine
        theirs += peer
        ratios.append(statistics.median(peer) / statistics.median(mine))
    return 1e3 * statistics.median(ours), 1e3 * statistics.median(theirs), statistics.median(ratios)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default="cylinder,max,spot,bar100k")
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--block", type=int, default=10, help="iterations per solver per round")
    ap.add_argument("--tol", type=float, default=1e-9, help="ours: as bench's default")
    args = ap.parse_args()
    print(f"{'case':10} {'vertices':>8} {'ours ms/it':>11} {'libigl ms/it':>13} {'libigl/ours':>12}")
    for name in args.cases.split(","):
        mesh_path, handles = CASES[name]
        if name == "bar100k" and not os.path.exists(BIG_BAR):
            sys.exit(f"{BIG_BAR} missing: python benchmarks/make_big_bar.py {BIG_BAR}")
        mesh = read_mesh(mesh_path)
        p = problem(mesh, load_handles(handles, mesh.vertices))
        rounds = args.rounds if len(p.V) < 50_000 else max(3, args.rounds // 5)
        ours, theirs, ratio = interleaved(p, rounds, args.block, args.tol)
        print(f"{name:10} {len(p.V):8d} {ours:11.2f} {theirs:13.2f} {ratio:12.2f}", flush=True)


if __name__ == "__main__":
    main()
