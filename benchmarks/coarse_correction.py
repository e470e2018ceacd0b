"""Seconds a large multiresolution solve spends in its coarse-grid corrections, for a base
revision and the working tree, in alternating processes (#72).

Each process deforms the mesh as ``srarap deform`` does (``tasks.pipeline.deform_mesh``,
default settings over the handle file's) and times every top-level correction
(``CoarseCorrection.__call__``: its coarse steps and the nested level's corrections inside
them), besides the full-resolution iterations and the whole solve; it prints the output's
hash, so that both trees can be seen to write the same bytes. Default: the 1.2M-vertex
cylinder (``out/cylinder-1m.obj``, made if missing).

Run: python benchmarks/coarse_correction.py --base REV [--rounds 1] [--mesh M --handles H]
"""
import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from paired import alternating  # noqa: E402  (after the sys.path entry)

ROOT = os.path.dirname(HERE)
OUT = os.path.join(ROOT, "out")
CYLINDER = os.path.join(OUT, "cylinder-1m.obj")
HANDLES = os.path.join(HERE, "cases", "cylinder-subdivided.yaml")


def one_run(mesh_path, handles):
    """This process's tree: one solve, its figures as JSON."""
    import numpy as np

    from srarap_cli.io.handles import load_handles
    from srarap_cli.io.mesh import read_mesh
    from srarap_cli.solver.multires.correction import CoarseCorrection
    from srarap_cli.tasks.pipeline import deform_mesh

    spent = {"seconds": 0.0, "calls": 0}
    real = CoarseCorrection.__call__

    def timed(self, *args):
        begin = time.perf_counter()
        try:
            return real(self, *args)
        finally:
            spent["seconds"] += time.perf_counter() - begin
            spent["calls"] += 1
    CoarseCorrection.__call__ = timed
    mesh = read_mesh(mesh_path)
    constraints = load_handles(handles, mesh.vertices)
    begin = time.perf_counter()
    deformed, result, _ = deform_mesh(mesh, constraints)
    solve = time.perf_counter() - begin
    digest = hashlib.sha256(np.ascontiguousarray(deformed.vertices).tobytes()).hexdigest()
    print(json.dumps({"corrections": spent["calls"], "correction_s": spent["seconds"],
                      "solve_s": solve, "iterations": result.iterations,
                      "hash": digest[:16]}))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", required=False)
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--mesh", default=CYLINDER)
    ap.add_argument("--handles", default=HANDLES)
    ap.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.mesh == CYLINDER and not os.path.exists(CYLINDER):
        subprocess.run([sys.executable, os.path.join(HERE, "make_big_spot.py"), CYLINDER,
                        "--levels", "4", "--mesh",
                        os.path.join(ROOT, "..", "shared", "meshes", "cylinder.off")],
                       check=True)
    if args.one or not args.base:
        return one_run(args.mesh, args.handles)
    runs = alternating(__file__, ["--one", "--mesh", args.mesh, "--handles", args.handles],
                       args.base, args.rounds)
    print(f"{os.path.basename(args.mesh)}: base {args.base} against the working tree, "
          f"medians of {args.rounds} alternating processes")
    print(f"{'tree':>5} {'iterations':>10} {'corrections':>11} {'correction s':>12} "
          f"{'solve s':>8} {'bytes':>17}")
    for name in ("base", "head"):
        rows = runs[name]
        med = {k: statistics.median(r[k] for r in rows)
               for k in ("iterations", "corrections", "correction_s", "solve_s")}
        hashes = ",".join(sorted({r["hash"] for r in rows}))
        print(f"{name:>5} {med['iterations']:10.0f} {med['corrections']:11.0f} "
              f"{med['correction_s']:12.1f} {med['solve_s']:8.1f} {hashes:>17}")


if __name__ == "__main__":
    main()
