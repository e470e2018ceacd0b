"""Iterations until converged over many handle sets: a check that a solver change is general.

The benchmark cases each have one handle set; a change tuned on them may not carry over. This
sweep builds 9 handle sets per mesh (for each axis: the lowest 10% of the vertices fixed, the
highest 10% turned by 60 degrees, or shifted by a quarter of the extent, or turned by 120
degrees and shifted by a tenth) and reports, per set, the default solver's full-resolution
iterations until within 0.1% and 0.01% of the best energy (a tight solve, tol 1e-11) and where
it stopped (tol 1e-6), with the totals per mesh. ``--plain`` adds the plain iteration from
Laplacian editing, the peer, in the same run (slow: hundreds of iterations per set).

To compare two versions of the solver, run the sweep on each (the other one through
``PYTHONPATH=<worktree of it>``) and compare the totals.

``--multires`` solves as ``deform`` does, through ``make_deformer`` (meshes of 20,000 vertices
or more coarse-to-fine), and counts full-resolution iterations.

Run: python benchmarks/handle_sweep.py [MESH ...] [--plain] [--multires]
     (default meshes: the shared torus, hand, armadillo and the 6k bar of make_big_bar.py)
"""
import argparse
import os
import subprocess
import sys

import igl
import numpy as np
from run_bench import HERE, OUT, SHARED

from srarap_cli import Deformer
from srarap_cli.solver.oneshot import make_deformer
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix

BAR = os.path.join(OUT, "bar-6k.obj")
MESHES = [os.path.join(SHARED, name) for name in ("torus.obj", "hand_lowres.obj",
                                                  "armadillo1.obj")] + [BAR]
MOVES = ((60, 0.0), (0, 0.25), (120, 0.1))  # degrees, shift as a fraction of the extent


def handle_sets(V):
    """(name, constrained ids, targets, labels) for each axis and move."""
    lo, ext = V.min(axis=0), np.ptp(V, axis=0)
    for axis, up in ((0, 1), (1, 2), (2, 0)):
        t = (V[:, axis] - lo[axis]) / ext[axis]
        bottom, top = np.flatnonzero(t < 0.1), np.flatnonzero(t > 0.9)
        centre = V[top].mean(axis=0)
        turn_axis = np.eye(3)[up]
        for degrees, shift in MOVES:
            turn = to_matrix(from_axis_angle(turn_axis, degrees)[None])[0]
            moved = (V[top] - centre) @ turn.T + centre
            moved[:, up] += shift * ext[axis]
            labels = np.r_[np.zeros(bottom.size, int), np.ones(top.size, int)]
            yield (f"axis {'xyz'[axis]}, turn {degrees}, shift {shift}", np.r_[bottom, top],
                   np.r_[V[bottom], moved], labels)


def within(log, best, frac):
    return next((k for k, row in enumerate(log) if row["total"] <= best * (1 + frac)), None)


def fine_rows(log):
    """The full-resolution rows of a log (a coarse-to-fine log starts with coarse ones)."""
    return [row for row in log if not row["step"].startswith("coarse-")]


def sweep(path, plain, multires):
    V, F = igl.read_triangle_mesh(path)[:2]
    diag = float(np.linalg.norm(np.ptp(V, axis=0)))
    totals = np.zeros(3, int)
    for name, ids, targets, labels in handle_sets(V):
        d = (make_deformer if multires else Deformer)(V, F, ids, labels=labels)
        tight = d.solve(targets, tol=1e-11, max_iter=20000)
        run = d.solve(targets, max_iter=3000)
        rows = fine_rows(run.log)
        best = min(tight.energy, min(row["total"] for row in rows))
        counts = [within(rows, best, 1e-3), within(rows, best, 1e-4), len(rows) - 1]
        totals += [c if c is not None else 3000 for c in counts]
        dist = np.linalg.norm(run.positions - tight.positions, axis=1).max() / diag
        line = (f"| {os.path.basename(path)} | {name} | {counts[0]} | {counts[1]} | {counts[2]} "
                f"| {dist:.1e} |")
        if plain:
            slow = Deformer(V, F, ids, labels=labels).solve(
                targets, accel="none", start="laplacian", tol=1e-9, max_iter=20000)
            line += f" {within(slow.log, best, 1e-3)} |"
        print(line, flush=True)
    print(f"| {os.path.basename(path)} | total | {totals[0]} | {totals[1]} | {totals[2]} | |"
          + (" |" if plain else ""), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("meshes", nargs="*", default=MESHES)
    ap.add_argument("--plain", action="store_true", help="also run the plain iteration")
    ap.add_argument("--multires", action="store_true",
                    help="solve as deform does (multires auto: coarse-to-fine from 20,000 "
                         "vertices), the tight reference too; iterations at full resolution")
    args = ap.parse_args()
    if BAR in args.meshes and not os.path.exists(BAR):
        subprocess.run([sys.executable, os.path.join(HERE, "make_big_bar.py"), BAR,
                        "--rings", "120", "--segments", "48"], check=True)
    print("| mesh | handles | it to 0.1% | it to 0.01% | stop it | stop dist/diag |"
          + (" plain it to 0.1% |" if args.plain else ""))
    print("|---|---|---:|---:|---:|---:|" + ("---:|" if args.plain else ""))
    for path in args.meshes:
        sweep(path, args.plain, args.multires)


if __name__ == "__main__":
    main()
