"""Time `srarap deform`'s solver on the shared cases, beside libigl's classic ARAP.

Prints, per case: iterations to reach tol, median seconds per local/global iteration of
srarap (the chosen method), median seconds per iteration of libigl's ARAP (spokes energy,
same constraints) measured in the same run, and their ratio. libigl's ARAP is a different
energy (no bending, per-cell rotation fit), so the ratio compares iteration cost, not results.
For the method comparison on wall time to a given energy, see run_bench.py.

Run: python benchmarks/deform_timing.py [--runs 3] [--tol 1e-6] [--method sr-linear-sym]
"""
import argparse
import os
import statistics
import time

import igl
import numpy as np

from srarap_cli import Deformer
from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh
from srarap_cli.solver.settings import resolve

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "meshes")
CASES = [
    ("cylinder (shared .sel/.def)", os.path.join(SHARED, "cylinder.off"),
     os.path.join(SHARED, "cylinder.sel")),
    ("spot (configs/spot-nod.yaml)", os.path.join(ROOT, "sample_meshes", "spot.obj"),
     os.path.join(ROOT, "configs", "spot-nod.yaml")),
]


def srarap_run(V, F, c, tol, method):
    opts = resolve(c.solver, {"tol": tol, "method": method})
    t0 = time.perf_counter()
    d = Deformer(V, F, c.ids, settings=opts)
    pre = time.perf_counter() - t0
    r = d.solve(c.targets)
    per_iter = (r.log[-1]["seconds"] - r.log[0]["seconds"]) / max(r.iterations, 1)
    return pre, per_iter, r


def igl_per_iteration(V, F, c, iterations=20):
    data = igl.ARAPData()
    data.max_iter = iterations
    data.energy = igl.ARAP_ENERGY_TYPE_SPOKES
    igl.arap_precomputation(V, F, 3, c.ids.astype(np.int32), data)
    t0 = time.perf_counter()
    igl.arap_solve(c.targets, data, V.copy())
    return (time.perf_counter() - t0) / iterations


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--method", default=None, help="default: the handle file's or srarap's")
    args = ap.parse_args()
    print(f"{'case':32} {'verts':>6} {'iters':>6} {'energy':>10} {'ms/iter':>8} "
          f"{'igl ms/iter':>11} {'ratio':>6} {'precompute s':>12}")
    for name, mesh_path, handle_path in CASES:
        mesh = read_mesh(mesh_path)
        V, F = mesh.vertices, mesh.triangles()[0]
        c = load_handles(handle_path, V)
        ours, peer, pre, result = [], [], [], None
        for _ in range(args.runs):
            p, it, result = srarap_run(V, F, c, args.tol, args.method)
            ours.append(it)
            pre.append(p)
            peer.append(igl_per_iteration(V, F, c))
        a, b = statistics.median(ours), statistics.median(peer)
        print(f"{name:32} {len(V):6d} {result.iterations:6d} {result.energy:10.5g} "
              f"{1e3 * a:8.1f} {1e3 * b:11.1f} {a / b:6.2f} {statistics.median(pre):12.3f}")


if __name__ == "__main__":
    main()
