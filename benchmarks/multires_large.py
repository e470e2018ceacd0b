"""End-to-end multiresolution deform of a large mesh: stage times and peak memory.

Generates out/spot-738k.obj (sample cow Loop-subdivided 3 times, 737,986 vertices) when it
is missing, then runs `srarap deform` on it with configs/spot-nod.yaml (hooves fixed, head
turned 30 degrees) twice: with an empty cache folder, then with the cache filled. Each run is
a separate process; its wall time includes interpreter start, loading and writing.
``--mesh``/``--handles`` run another case (``--cold-only``: without the cached run), e.g. the
stage table of the performance page:

    python benchmarks/make_big_bar.py out/bar-500k.obj --rings 1560 --segments 320
    python benchmarks/make_big_spot.py out/cylinder-1m.obj --levels 4 --mesh ../shared/meshes/cylinder.off
    python benchmarks/make_big_bar.py out/bar-2m.obj --rings 3120 --segments 640
    python benchmarks/multires_large.py --cold-only --mesh out/bar-500k.obj \
        --handles benchmarks/cases/bar-100k-twist.yaml

Run: python benchmarks/multires_large.py [--multires auto] [--runs 1] [--mesh M --handles H]
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(ROOT, "out")
MESH = os.path.join(OUT, "spot-738k.obj")
HANDLES = os.path.join(ROOT, "configs", "spot-nod.yaml")

CHILD = """
import resource, sys
from srarap_cli.cli import main
try:
    main(sys.argv[1:], standalone_mode=False)
finally:
    print("peak_rss_mb", resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
          file=sys.stderr)
"""


def run_once(args, cache):
    stem = os.path.join(OUT, os.path.splitext(os.path.basename(args.mesh))[0] + "-deformed")
    cmd = [sys.executable, "-c", CHILD, "deform", "-v", args.mesh, args.handles, "-o",
           stem + ".obj", "--log", stem + ".csv", "--multires", str(args.multires),
           "--cache", cache]
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - start
    lines = proc.stderr.strip().splitlines()
    peak = next(float(x.split()[1]) for x in lines if x.startswith("peak_rss_mb"))
    stages = next((x for x in lines if x.startswith("srarap: multires:")), "")
    summary = next((x for x in lines if x.startswith("srarap deform:")), proc.stderr)
    return {"exit": proc.returncode, "wall_s": wall, "peak_rss_mb": peak, "stages": stages,
            "summary": summary}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--multires", default="auto")
    ap.add_argument("--mesh", default=MESH)
    ap.add_argument("--handles", default=HANDLES)
    ap.add_argument("--cold-only", action="store_true", help="no second run from the cache")
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--json")
    args = ap.parse_args()
    if args.mesh == MESH and not os.path.exists(MESH):
        subprocess.run([sys.executable, os.path.join(HERE, "make_big_spot.py"), MESH,
                        "--levels", "3"], check=True)
    results = []
    for _ in range(args.runs):
        cache = os.path.join(OUT, "multires-cache")
        shutil.rmtree(cache, ignore_errors=True)
        results.append({"cold": run_once(args, cache)})
        if not args.cold_only:
            results[-1]["warm"] = run_once(args, cache)
    for r in results:
        for kind in r:
            x = r[kind]
            print(f"{kind} cache: exit {x['exit']}, wall {x['wall_s']:.1f} s, "
                  f"peak {x['peak_rss_mb']:.0f} MB\n  {x['stages']}\n  {x['summary']}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=1)


if __name__ == "__main__":
    main()
