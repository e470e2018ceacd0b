"""Converged animation: frames per second and iterations per frame of `srarap animate`.

Writes capped tubes (srarap_cli.tasks.samples.bar, as the sample bar) of about 5k and 50k
vertices and a handle file that holds the base and turns the top 180 degrees over 60 frames
(3 degrees a frame), then runs `srarap animate` on each (every frame to the default --tol) as
a separate process, --repeat times. Prints the medians of: frames per second over the frames
after the first (the solve of each frame, from the per-frame log: the rate a long animation
runs at), the whole process's wall time (start-up, setup and writing included), and the median
and largest iterations per frame.

Run: python benchmarks/animation_rate.py [--repeat 3] [--sizes 5000 50000] [-- EXTRA ANIMATE OPTIONS]
"""
import argparse
import csv
import os
import statistics
import subprocess
import sys
import tempfile
import time

import yaml

from srarap_cli.tasks.samples import bar, obj_text

FRAMES = 60
DEGREES = 180


def tube(path, vertices):
    """A tube of length 6 and about ``vertices`` vertices (segments ~ rings / 3)."""
    rings = max(8, round((3 * vertices) ** 0.5))
    segments = max(8, round(vertices / rings))
    with open(path, "w") as fh:
        V, faces, uv, tfaces = bar(length=6, rings=rings, segments=segments)
        fh.write(obj_text(V, faces, uv, tfaces))
    return len(V)


def handles(path):
    with open(path, "w") as fh:
        yaml.safe_dump({"groups": {
            "base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True},
            "top": {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]},
                    "keyframes": [{"frame": 0},
                                  {"frame": FRAMES, "rotate": {"axis": [0, 0, 1],
                                                               "angle_deg": DEGREES}}]}}}, fh)


def run(mesh, handle_file, work, extra):
    log = os.path.join(work, "frames.csv")
    cmd = [os.path.join(os.path.dirname(sys.executable), "srarap"), "animate", mesh,
           handle_file, "-o", os.path.join(work, "f_{:03d}.obj"), "--log", log, "-q", *extra]
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        sys.exit(f"srarap animate exited {proc.returncode}: {proc.stderr.strip()[-400:]}")
    with open(log, newline="") as fh:
        rows = list(csv.DictReader(fh))
    later = rows[1:]
    solve = sum(float(r["seconds"]) for r in later)
    its = [int(r["iterations"]) for r in later]
    return {"fps": len(later) / solve, "wall": wall, "its": its}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--sizes", type=int, nargs="+", default=[5000, 50000])
    ap.add_argument("extra", nargs="*", help="options passed to srarap animate (after --)")
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="srarap-animation-")
    handle_file = os.path.join(work, "twist.yaml")
    handles(handle_file)
    print(f"| tube | frames | frames/s (solve) | whole process, s | iterations per frame: "
          f"median, max |  (medians of {args.repeat})")
    print("|---:|---:|---:|---:|---:|")
    for size in args.sizes:
        mesh = os.path.join(work, f"tube{size}.obj")
        n = tube(mesh, size)
        runs = [run(mesh, handle_file, work, args.extra) for _ in range(args.repeat)]
        its = runs[0]["its"]
        print(f"| {n:,} | {FRAMES + 1} | {statistics.median(r['fps'] for r in runs):.1f} | "
              f"{statistics.median(r['wall'] for r in runs):.1f} | "
              f"{statistics.median(its):g}, {max(its)} |")


if __name__ == "__main__":
    main()
