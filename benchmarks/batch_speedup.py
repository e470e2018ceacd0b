"""Time a manifest of many small jobs run sequentially and with 2 worker processes.

Writes small tubes (srarap_cli.tasks.samples, as the sample bar) and a manifest of N jobs bending them,
runs `srarap batch` with --workers 1 and --workers 2 in fresh output folders, and prints both
wall times and their ratio. One job is deliberately broken: it must be reported, not fatal.

Run: python benchmarks/batch_speedup.py [--jobs 200]
"""
import argparse
import os
import subprocess
import tempfile
import time

import yaml

from srarap_cli.tasks.samples import bar, obj_text


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=200)
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="srarap-batch-")
    jobs = []
    for k in range(args.jobs):
        mesh = os.path.join(work, f"tube{k}.obj")
        with open(mesh, "w") as fh:
            fh.write(obj_text(*bar(length=6, rings=8 + k % 5, segments=8)))
        handles = os.path.join(work, f"h{k}.yaml")
        with open(handles, "w") as fh:
            yaml.safe_dump({"groups": {
                "base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True},
                "tip": {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]},
                        "rotate": {"axis": [0, 1, 0], "angle": 10 + k % 50}}}}, fh)
        jobs.append({"name": f"job{k}", "mesh": mesh, "handles": handles, "output": f"out{k}.obj"})
    jobs[len(jobs) // 2]["mesh"] = os.path.join(work, "missing.obj")
    manifest = os.path.join(work, "jobs.yaml")
    with open(manifest, "w") as fh:
        yaml.safe_dump({"defaults": {"max_iter": 200}, "jobs": jobs}, fh)
    times = {}
    for workers in (1, 2):
        start = time.perf_counter()
        p = subprocess.run(["srarap", "batch", manifest, "-o", os.path.join(work, f"w{workers}"),
                            "--workers", str(workers), "-q"], check=False)
        times[workers] = time.perf_counter() - start
        print(f"--workers {workers}: {times[workers]:.1f} s (exit code {p.returncode}, "
              "8 = the broken job was reported)")
    print(f"speed-up with 2 workers: {times[1] / times[2]:.2f}x for {args.jobs} jobs")


if __name__ == "__main__":
    main()
