"""Multiresolution against the direct full-resolution solve, for several coarse sizes.

Prints one row per coarse size: coarse vertices, seconds, the full-resolution energy of the
multires result relative to the direct result's (with the rotors it returns, and with rotors
refitted to its positions by one full-resolution local step), and the max and mean vertex
distance to the direct result relative to the bounding-box diagonal.

``--mode refine`` measures the default coarse-to-fine solve instead of the transfer alone;
``--meshlab`` swaps in MeshLab's simplification (pymeshlab, GPL, installed separately) so the
two simplifiers can be compared in one run.

Run: python benchmarks/make_big_spot.py out/spot-46k.obj --levels 1
     python benchmarks/multires_quality.py out/spot-46k.obj configs/spot-nod.yaml \
         --sizes 1000 2500 5000 10000 --json out/multires-quality.json
"""
import argparse
import json
import os
import time

import numpy as np

from srarap_cli import DeformResult
from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh
from srarap_cli.solver.oneshot import make_deformer
from srarap_cli.solver.settings import resolve
from srarap_cli.solver.stop import StopReason
from srarap_cli.tasks.pipeline import problem


def use_meshlab():
    """Route the multires simplification through MeshLab's collapse (benchmark peer)."""
    import sys

    import srarap_cli.solver.multires.cache as cache
    from srarap_cli.solver.multires.simplify import CoarseMesh
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from simplify_quality import meshlab_subset

    def simplify(V, F, size, groups=()):
        ids, G = meshlab_subset(V, F, size)
        if any(not np.isin(g, ids).any() for g in groups):
            raise RuntimeError("MeshLab dropped a handle group; try another size")
        return CoarseMesh(ids, G, [])
    cache.simplify_to_subset = simplify


def refit_energy(direct, P, R):
    """Energy of positions P with rotors from one full-resolution local step."""
    return direct.energy(P, direct.best_rotors(P, R))["total"]


def run(p, opts, size, tol, max_iter):
    start = time.perf_counter()
    d = make_deformer(p.V, p.F, p.ids, p.labels, settings=opts.replace(multires=size))
    r = d.solve(p.targets, max_iter=max_iter, tol=tol)
    return d, r, time.perf_counter() - start


def reference(p, opts, args):
    """The direct solve: computed, or read from ``args.reference`` (same inputs assumed)."""
    if args.reference and os.path.exists(args.reference):
        direct = make_deformer(p.V, p.F, p.ids, p.labels, settings=opts.replace(multires="off"))
        with np.load(args.reference) as z:
            log = json.loads(str(z["log"]))
            ref = DeformResult(z["positions"], z["rotors"], log, StopReason.CONVERGED,
                               len(log) - 1)
            return direct, ref, float(z["seconds"])
    direct, ref, seconds = run(p, opts, "off", args.tol, args.max_iter)
    if args.reference:
        np.savez(args.reference, positions=ref.positions, rotors=ref.rotors,
                 log=json.dumps(ref.log), seconds=seconds)
    return direct, ref, seconds


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mesh")
    ap.add_argument("handles")
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 2500, 5000, 10000])
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--max-iter", type=int, default=5000)
    ap.add_argument("--json")
    ap.add_argument("--mode", choices=["transfer", "refine"], default="transfer",
                    help="multires mode measured (transfer: the paper's approximation)")
    ap.add_argument("--meshlab", action="store_true",
                    help="simplify with MeshLab (the GPL peer; needs pymeshlab installed)")
    ap.add_argument("--reference", help="npz keeping the direct solve between runs (it takes "
                    "long); reused when it exists")
    args = ap.parse_args()
    mesh = read_mesh(args.mesh)
    c = load_handles(args.handles, mesh.vertices)
    p = problem(mesh, c)
    opts = resolve(c.solver, {"multires_mode": args.mode})
    if args.meshlab:
        use_meshlab()
    direct, ref, direct_s = reference(p, opts, args)
    diag = float(np.linalg.norm(np.ptp(p.V, axis=0)))
    e_ref = ref.energy
    rows = [{"coarse": len(p.V), "seconds": direct_s, "iterations": ref.iterations,
             "energy": e_ref, "rel_energy": 1.0, "rel_energy_refit":
             refit_energy(direct, ref.positions, ref.rotors) / e_ref, "max_dist": 0.0,
             "mean_dist": 0.0}]
    for size in args.sizes:
        _, r, s = run(p, opts, size, args.tol, args.max_iter)
        dist = np.linalg.norm(r.positions - ref.positions, axis=1) / diag
        rows.append({"coarse": r.multires.coarse_vertices, "seconds": s, "iterations": r.iterations,
                     "energy": r.energy, "rel_energy": r.energy / e_ref,
                     "rel_energy_refit": refit_energy(direct, r.positions, r.rotors) / e_ref,
                     "max_dist": float(dist.max()), "mean_dist": float(dist.mean())})
    print(f"{args.mesh}: {len(p.V)} vertices; direct solve: {ref.iterations} iterations, "
          f"energy {e_ref:.6g}, converged {ref.converged}")
    print("| coarse vertices | seconds | coarse iterations | E / E_direct | E (refit rotors) "
          "/ E_direct | max dist / diag | mean dist / diag |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for row in rows:
        print(f"| {row['coarse']} | {row['seconds']:.1f} | {row['iterations']} | "
              f"{row['rel_energy']:.3f} | {row['rel_energy_refit']:.3f} | "
              f"{row['max_dist']:.2e} | {row['mean_dist']:.2e} |")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
