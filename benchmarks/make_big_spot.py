"""Write the sample cow (sample_meshes/spot.obj, public domain) Loop-subdivided N times.

Run: python benchmarks/make_big_spot.py OUT.obj [--levels 3] [--mesh MESH]
Levels 1, 2, 3 give 46k, 184k and 738k vertices; configs/spot-nod.yaml selects by position,
so it applies to every level. ``--mesh`` subdivides another mesh: the shared cylinder
(../shared/meshes/cylinder.off) 4 times gives 1,228,802 vertices, for
benchmarks/cases/cylinder-subdivided.yaml.
"""
import argparse
import os

import igl
import numpy as np

from srarap_cli.io.mesh import read_mesh

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--levels", type=int, default=3)
    ap.add_argument("--mesh", default=os.path.join(HERE, "..", "sample_meshes", "spot.obj"))
    args = ap.parse_args()
    mesh = read_mesh(args.mesh)
    V, F = mesh.vertices, mesh.triangles()[0]
    for _ in range(args.levels):
        V, F = igl.loop(V, F)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as fh:
        fh.write(f"# {os.path.basename(args.mesh)} Loop-subdivided {args.levels} times\n")
        np.savetxt(fh, V, fmt="v %.9g %.9g %.9g")
        np.savetxt(fh, F + 1, fmt="f %d %d %d")
    print(f"wrote {args.out}: {len(V)} vertices, {len(F)} faces")


if __name__ == "__main__":
    main()
