"""Time a manifest of jobs run with 1 and 2 worker processes and on a local Dask cluster.

Writes tubes (srarap_cli.tasks.samples, as the sample bar) and a manifest of N jobs bending
them, runs `srarap batch` with --workers 1, --workers 2 and --scheduler local --workers 2 in
fresh output folders, each --repeat times, and prints the median wall times, jobs per hour and
the ratios to one worker. One job is deliberately broken: it must be reported, not fatal.

Run: python benchmarks/batch_speedup.py [--jobs 20] [--rings 60] [--repeat 3]
"""
import argparse
import os
import statistics
import subprocess
import tempfile
import time

import yaml

from srarap_cli.tasks.samples import bar, obj_text


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=20)
    ap.add_argument("--rings", type=int, default=60, help="tube rings (60: 5k vertices)")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="srarap-batch-")
    jobs = []
    for k in range(args.jobs):
        mesh = os.path.join(work, f"tube{k}.obj")
        with open(mesh, "w") as fh:
            fh.write(obj_text(*bar(length=6, rings=args.rings + k % 5, segments=80)))
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
    modes = {"--workers 1": ["--workers", "1"], "--workers 2": ["--workers", "2"],
             "dask local, 2 workers": ["--scheduler", "local", "--workers", "2"]}
    times = {}
    for name, extra in modes.items():
        runs = []
        for r in range(args.repeat):
            start = time.perf_counter()
            p = subprocess.run(["srarap", "batch", manifest, "-o",
                                os.path.join(work, f"{name.replace(' ', '_')}{r}"), "-q",
                                *extra], check=False)
            runs.append(time.perf_counter() - start)
        times[name] = statistics.median(runs)
        print(f"{name:24} {times[name]:6.1f} s median of {args.repeat} "
              f"({3600 * args.jobs / times[name]:7.0f} jobs/hour; exit code {p.returncode}, "
              "8 = the broken job was reported)")
    base = times["--workers 1"]
    for name, t in times.items():
        print(f"{name:24} {base / t:.2f}x one worker")
    print(f"dask local / --workers 2: {times['dask local, 2 workers'] / times['--workers 2']:.2f}")


if __name__ == "__main__":
    main()
