"""Whole-process time of `srarap deform` against CGAL's SRE_ARAP, measured in the same run.

CGAL's Surface_mesh_deformation with the SRE_ARAP tag is the C++ implementation of
smooth-rotation ARAP people use today; it runs a fixed number of iterations (or stops on a
relative energy change that ignores its bending term), so it is timed at --iterations
(default 1000, what a user runs to be safe on a twist), srarap with its default settings to
its own stopping test. Both are whole processes (start, reading, solving, writing), timed
alternately, --runs times each; the medians and their ratio are printed, with srarap's
iterations and the largest distance between the two results over the mesh's diagonal (the
energies differ in their normalization and bending term: the distance says how alike the
shapes are, not which is right).

The driver (benchmarks/cgal/sre_arap.cpp) is compiled into out/ with g++ where CGAL's and
Eigen's headers are installed (Debian: apt install libcgal-dev libeigen3-dev); elsewhere this
benchmark says so and exits 0. CGAL is never a dependency of srarap.

srarap runs as an installed package does: with its bytecode cached (PYTHONDONTWRITEBYTECODE,
set on some machines, is dropped for the child processes, and one untimed run writes the
caches); without a cache every run compiles srarap's modules again (about 50 ms).

Run: python benchmarks/cgal_sre_arap.py [--runs 5] [--iterations 1000]
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import time

import numpy as np

from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(ROOT, "out", "cgal")
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "meshes")
CASES = [
    ("cylinder 4,802", os.path.join(SHARED, "cylinder.off"), os.path.join(SHARED, "cylinder.sel")),
    ("Max bust 5,272", os.path.join(SHARED, "decimated-max.obj"),
     os.path.join(HERE, "cases", "decimated-max.yaml")),
]
INCLUDES = ["/usr/include/CGAL/Surface_mesh_deformation.h", "/usr/include/eigen3/Eigen/Core"]


def build():
    """Path of the compiled driver, or None with the reason printed."""
    missing = [p for p in INCLUDES if not os.path.exists(p)]
    if missing or shutil.which("g++") is None:
        print("skipped: CGAL's SRE_ARAP cannot be built here (needs g++ and "
              f"{', '.join(missing) or 'the headers'}; Debian: apt install libcgal-dev "
              "libeigen3-dev)")
        return None
    os.makedirs(OUT, exist_ok=True)
    exe = os.path.join(OUT, "sre_arap")
    source = os.path.join(HERE, "cgal", "sre_arap.cpp")
    if not os.path.exists(exe) or os.path.getmtime(exe) < os.path.getmtime(source):
        subprocess.run(["g++", "-O2", "-DNDEBUG", "-DCGAL_EIGEN3_ENABLED", "-I/usr/include/eigen3",
                        source, "-o", exe, "-lgmp", "-lmpfr"], check=True)
    return exe


def prepare(name, mesh_path, handles_path):
    """The case as CGAL reads it: an OFF mesh and "id x y z" constraint lines."""
    mesh = read_mesh(mesh_path)
    V, F = mesh.vertices, mesh.triangles()[0]
    c = load_handles(handles_path, V, fps=24)
    stem = os.path.join(OUT, name.split()[0])
    with open(stem + ".off", "w") as fh:
        fh.write(f"OFF\n{len(V)} {len(F)} 0\n")
        np.savetxt(fh, V, fmt="%.17g")
        np.savetxt(fh, np.column_stack([np.full(len(F), 3), F]), fmt="%d")
    np.savetxt(stem + ".txt", np.column_stack([c.ids, c.targets]), fmt=["%d", "%.17g", "%.17g",
                                                                         "%.17g"])
    return stem, V


ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def timed(cmd):
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False, env=ENV)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        sys.exit(f"{cmd[0]} failed ({proc.returncode}): {proc.stderr.strip()[-500:]}")
    return wall, proc.stderr


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--iterations", type=int, default=1000)
    args = ap.parse_args()
    exe = build()
    if exe is None:
        return
    srarap = os.path.join(os.path.dirname(sys.executable), "srarap")
    print(f"| case | srarap: iterations, s (median of {args.runs}) | CGAL SRE_ARAP "
          f"{args.iterations} it, s | ratio | shapes apart (of diagonal) |")
    print("|---|---:|---:|---:|---:|")
    for name, mesh_path, handles_path in CASES:
        stem, V = prepare(name, mesh_path, handles_path)
        ours, theirs, summary = [], [], ""
        timed([srarap, "deform", mesh_path, handles_path, "-o", stem + "-srarap.off"])
        for _ in range(args.runs):
            wall, err = timed([srarap, "deform", mesh_path, handles_path, "-o",
                               stem + "-srarap.off"])
            ours.append(wall)
            summary = err
            theirs.append(timed([exe, stem + ".off", stem + ".txt", stem + "-cgal.off",
                                 str(args.iterations)])[0])
        its = summary.split("converged in ")[-1].split()[0] if "converged in" in summary else "?"
        a = read_mesh(stem + "-srarap.off").vertices
        b = read_mesh(stem + "-cgal.off").vertices
        apart = np.linalg.norm(a - b, axis=1).max() / np.linalg.norm(np.ptp(V, axis=0))
        mine, peer = statistics.median(ours), statistics.median(theirs)
        print(f"| {name} | {its}, {mine:.3f} | {peer:.3f} | {mine / peer:.3f}x | {apart:.1e} |")


if __name__ == "__main__":
    main()
