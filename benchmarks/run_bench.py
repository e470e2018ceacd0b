"""Run `srarap bench` on the shared cases and a generated ~100k-vertex bar; print the tables.

Cases: the Botsch-Sorkine cylinder (.sel/.def), libigl's decimated Max Planck bust with its
.dmat moved as in libigl's tutorial 401, Spot with configs/spot-nod.yaml, and a finely
subdivided bar of about 100k vertices twisted by 90 degrees. Each run writes its curves,
summary and plot to out/bench/<case>/.

Run: python benchmarks/run_bench.py [--time-budget 60] [--cases cylinder,max,spot,bar100k]
"""
import argparse
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "meshes")
OUT = os.path.join(ROOT, "out")
BIG_BAR = os.path.join(OUT, "bar-100k.obj")
CASES = {
    "cylinder": (os.path.join(SHARED, "cylinder.off"), os.path.join(SHARED, "cylinder.sel")),
    "max": (os.path.join(SHARED, "decimated-max.obj"),
            os.path.join(HERE, "cases", "decimated-max.yaml")),
    "spot": (os.path.join(ROOT, "sample_meshes", "spot.obj"),
             os.path.join(ROOT, "configs", "spot-nod.yaml")),
    "bar100k": (BIG_BAR, os.path.join(HERE, "cases", "bar-100k-twist.yaml")),
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--time-budget", type=float, default=60.0)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--methods", default=None, help="passed on to srarap bench --methods")
    args = ap.parse_args()
    for name in args.cases.split(","):
        mesh, handles = CASES[name]
        if name == "bar100k" and not os.path.exists(BIG_BAR):
            subprocess.run([sys.executable, os.path.join(HERE, "make_big_bar.py"), BIG_BAR],
                           check=True)
        cmd = ["srarap", "bench", mesh, handles, "--time-budget", str(args.time_budget),
               "-o", os.path.join(ROOT, "out", "bench", name)]
        if args.methods:
            cmd += ["--methods", args.methods]
        print(f"== {name}: {os.path.basename(mesh)}", flush=True)
        subprocess.run(cmd, check=True)


if __name__ == "__main__":
    main()
