"""Experiment: how much of multires' energy excess is the spiky transferred rotor field?

Smooths the transferred rotors K times (half-step toward the neighbours' mean, normalized), then
redoes the final Poisson solve with the same factorization, and prints the full-resolution
energy over the direct solve's and the distances to it. Not what `deform` does (it keeps the
paper's transfer); see README "Multiresolution".

Run after benchmarks/multires_quality.py ... --reference out/spot46-direct.npz:
  python benchmarks/multires_rotor_smoothing.py out/spot-46k.obj configs/spot-nod.yaml \
      out/spot46-direct.npz --sizes 2500 5000
"""
import argparse
import json

import numpy as np
import scipy.sparse as sp

from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh
from srarap_cli.solver.multires import MultiresDeformer
from srarap_cli.solver.quaternion import IDENTITY, normalize
from srarap_cli.tasks.pipeline import problem


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mesh")
    ap.add_argument("handles")
    ap.add_argument("reference")
    ap.add_argument("--sizes", type=int, nargs="+", default=[2500, 5000])
    args = ap.parse_args()
    mesh = read_mesh(args.mesh)
    p = problem(mesh, load_handles(args.handles, mesh.vertices))
    with np.load(args.reference) as z:
        P_direct, e_direct = z["positions"], json.loads(str(z["log"]))[-1]["total"]
    diag = np.linalg.norm(np.ptp(p.V, axis=0))
    for size in args.sizes:
        d = MultiresDeformer(p.V, p.F, p.ids, p.labels, size=size, multires_mode="transfer")
        r = d.solve(p.targets, max_iter=5000, tol=1e-6)
        g = d.fine.graph
        W = sp.csr_matrix((np.ones(len(g.I)), (g.I, g.J)), shape=(g.n, g.n))
        W = sp.diags(1 / np.maximum(np.asarray(W.sum(1)).ravel(), 1)) @ W
        known = d.known_positions(p.targets, r.positions[d.coarse.vertices])
        for k in (0, 2, 5, 10, 20):
            R = r.rotors
            for _ in range(k):
                R = normalize(0.5 * R + 0.5 * (W @ R), np.broadcast_to(IDENTITY, R.shape))
            P = d.solver.solve(known, d.fine.edges.rotated_divergence(R))
            e = d.fine.energy(P, R)
            m, b = e["membrane"], e["bending"]
            dist = np.linalg.norm(P - P_direct, axis=1) / diag
            print(f"coarse {size}, smoothing passes {k}: E/E_direct {(m + b) / e_direct:.3f} "
                  f"(membrane {m:.4f}, bending {b:.4f}), max dist {dist.max():.2e}, "
                  f"mean {dist.mean():.2e}", flush=True)


if __name__ == "__main__":
    main()
