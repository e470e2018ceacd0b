"""Large meshes end to end: the stage table (seconds and peak memory per stage) of default
``srarap deform`` on the 0.5M bar, the 1.2M cylinder and the 2M bar, optionally for a base
revision too, in one run.

Each run is a separate process (``srarap deform -v``, wall time of the whole process: reading,
setup, solve, writing); the stages come from its ``-v`` lines, the peak per stage from the
process's high-water mark reset at each stage (Linux). The simplification and the
full-resolution setup run side by side on two cores, so the stages add up to more than the
wall time. Missing meshes are generated into ``out/``:

    out/bar-500k.obj       benchmarks/make_big_bar.py --rings 1560 --segments 320
    out/cylinder-1m.obj    benchmarks/make_big_spot.py --levels 4 --mesh ../shared/meshes/cylinder.off
    out/bar-2m.obj         benchmarks/make_big_bar.py --rings 3120 --segments 640

``--base REV`` checks REV out into a git worktree (``out/base-REV``) and runs it with the
same interpreter (``PYTHONPATH`` at the worktree), alternating base and HEAD per case, so
both see the same machine. ``--cases`` picks some (``bar500k,cylinder1m,bar2m``), ``--mesh
M --handles H`` runs another one; ``--runs`` repeats and prints medians.

``--threads 1,2`` runs the working tree at each thread count instead (alternating), and
prints each count's whole-process and full-resolution-iteration ratios against the first,
and whether every run wrote the same bytes (#59).

Run: python benchmarks/multires_large.py [--cases bar500k,cylinder1m] [--base REV] [--runs 1]
     [--threads 1,2]
"""
import argparse
import hashlib
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(ROOT, "out")
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "meshes")
TWIST = os.path.join(HERE, "cases", "bar-100k-twist.yaml")
CASES = {
    "bar500k": ("bar-500k.obj", TWIST,
                ["make_big_bar.py", "--rings", "1560", "--segments", "320"]),
    "cylinder1m": ("cylinder-1m.obj", os.path.join(HERE, "cases", "cylinder-subdivided.yaml"),
                   ["make_big_spot.py", "--levels", "4", "--mesh",
                    os.path.join(SHARED, "cylinder.off")]),
    "bar2m": ("bar-2m.obj", TWIST, ["make_big_bar.py", "--rings", "3120", "--segments", "640"]),
}
STAGES = ["simplify", "fine setup", "coarse setup", "coarse solve", "full-resolution start",
          "full-resolution iterations"]
# the setup stages share one memory window (they run side by side)
SETUP_WINDOW = {"simplify": "setup", "fine setup": "setup", "coarse setup": "setup"}


def _mesh(name):
    file, handles, make = CASES[name]
    path = os.path.join(OUT, file)
    if not os.path.exists(path):
        subprocess.run([sys.executable, os.path.join(HERE, make[0]), path, *make[1:]],
                       check=True)
    return path, handles


# the package from the folder given, even where an editable install's finder would answer
CHILD = """import runpy, sys
sys.meta_path[:] = [f for f in sys.meta_path if "__editable__" not in getattr(f, "__module__", "")]
sys.path.insert(0, sys.argv.pop(1))
runpy.run_module("srarap_cli", run_name="__main__", alter_sys=True)
"""


def run_once(mesh, handles, code_root, extra=()):
    """One ``srarap deform -v`` of ``mesh`` with the package at ``code_root`` (and the
    options ``extra``)."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-c", CHILD, code_root, "deform", "-v", mesh, handles,
               "-o", os.path.join(tmp, "out.obj"), *extra]
        with open(os.path.join(tmp, "stderr"), "w+") as err:
            start = time.perf_counter()
            proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err)
            _, status, usage = os.wait4(proc.pid, 0)  # this child's own peak, not the max of all
            wall = time.perf_counter() - start
            err.seek(0)
            text = err.read()
        written = os.path.join(tmp, "out.obj")
        digest = (hashlib.sha256(open(written, "rb").read()).hexdigest()
                  if os.path.exists(written) else None)
    peak = usage.ru_maxrss / 1024
    stages = {k: float(v) for k, v in re.findall(r"([a-z -]+?) ([0-9.]+) s(?=[,\n]|$)",
                                                 _line(text, "srarap: multires: ") or "")}
    memory = {k.strip(): float(v) for k, v in re.findall(
        r"([a-z -]+?) ([0-9.]+) GB", _line(text, "peak memory per stage:") or "")}
    whole = {k.strip(): float(v) for k, v in re.findall(
        r"([a-z -]+?) ([0-9.]+) GB", _line(text, "srarap: peak memory:") or "")}
    summary = _line(text, "srarap deform:") or text.strip().splitlines()[-1:]
    iterations = re.search(r"(\d+) full-resolution iterations \(\+ (\d+) coarse\)", summary)
    return {"exit": os.waitstatus_to_exitcode(status), "wall_s": wall, "max_rss_mb": peak,
            "stages_s": {k.strip(): v for k, v in stages.items()}, "stage_peak_gb": memory,
            "peak_gb": whole, "iterations": iterations.groups() if iterations else None,
            "summary": summary, "sha256": digest}


def _line(text, marker):
    return next((x for x in text.splitlines() if marker in x), None)


def _worktree(rev):
    path = os.path.join(OUT, f"base-{rev}")
    if not os.path.isdir(path):
        subprocess.run(["git", "-C", ROOT, "worktree", "add", "--detach", path, rev],
                       check=True, capture_output=True)
    return path


def _row(label, runs):
    def med(get):
        values = [v for v in (get(r) for r in runs) if v is not None]
        return statistics.median(values) if values else None

    def fmt(v, unit):
        return "-" if v is None else f"{v:.1f}{unit}" if unit == " s" else f"{v:.2f}{unit}"

    first = runs[0]
    its = "/".join(first["iterations"]) if first["iterations"] else "-"
    # -v resets the high-water mark per stage, after which ru_maxrss covers the last stage
    # only: the largest stage peak where there are any
    peak = med(lambda r: max([*r["stage_peak_gb"].values(), *r["peak_gb"].values(),
                              r["max_rss_mb"] * 1.048576e-3]))
    cells = [label, str(first["exit"]), fmt(med(lambda r: r["wall_s"]), " s"),
             fmt(peak, " GB"), its]
    for stage in STAGES:
        window = SETUP_WINDOW.get(stage, stage)
        s = med(lambda r, stage=stage: r["stages_s"].get(stage))
        m = med(lambda r, window=window: r["stage_peak_gb"].get(window))
        cells.append(f"{fmt(s, ' s')} / {fmt(m, ' GB')}")
    return "| " + " | ".join(cells) + " |"


def _thread_ratios(results, names, counts):
    """Each thread count against the first, same run: whole process and full-resolution
    iterations (medians), and whether every run wrote the same bytes."""
    print("\n| case | threads | wall ratio | full-resolution iterations ratio | same bytes |")
    print("|---|---|---|---|---|")
    for name in names:
        base = results[f"{name} HEAD t{counts[0]}"]
        digests = {r["sha256"] for n in counts for r in results[f"{name} HEAD t{n}"]}
        for n in counts[1:]:
            runs = results[f"{name} HEAD t{n}"]

            def ratio(get, runs=runs, base=base):
                a = [get(r) for r in runs if get(r) is not None]
                b = [get(r) for r in base if get(r) is not None]
                return (f"{statistics.median(a) / statistics.median(b):.3f}" if a and b
                        else "-")

            print(f"| {name} | {n} vs {counts[0]} | {ratio(lambda r: r['wall_s'])} | "
                  f"{ratio(lambda r: r['stages_s'].get('full-resolution iterations'))} | "
                  f"{'yes' if len(digests) == 1 else 'NO'} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default="bar500k,cylinder1m,bar2m")
    ap.add_argument("--mesh")
    ap.add_argument("--handles")
    ap.add_argument("--base", help="a git revision to measure beside the working tree")
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--threads", help="thread counts to run the working tree at, e.g. 1,2 "
                    "(--threads N each; ratios against the first, outputs compared)")
    ap.add_argument("--json")
    args = ap.parse_args()
    cases = ([(os.path.basename(args.mesh), (args.mesh, args.handles))] if args.mesh
             else [(name, _mesh(name)) for name in args.cases.split(",")])
    counts = args.threads.split(",") if args.threads else [None]
    codes = [(f"HEAD t{n}" if n else "HEAD", ROOT, ("--threads", n) if n else ())
             for n in counts[::-1]]
    codes += [(args.base, _worktree(args.base), ())] if args.base else []
    results = {}
    for name, (mesh, handles) in cases:
        for _ in range(args.runs):
            for label, root, extra in codes[::-1]:  # base first, then the working tree
                run = run_once(mesh, handles, root, extra)
                results.setdefault(f"{name} {label}", []).append(run)
                print(f"{name} {label}: exit {run['exit']}, {run['wall_s']:.1f} s, "
                      f"{run['summary']}", file=sys.stderr, flush=True)
    print("| case | exit | wall | peak | iterations (fine/coarse) | "
          + " | ".join(f"{s} (s / peak)" for s in STAGES) + " |")
    print("|---" * (5 + len(STAGES)) + "|")
    for label, runs in results.items():
        print(_row(label, runs))
    if len(counts) > 1:
        _thread_ratios(results, [name for name, _ in cases], counts)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=1)


if __name__ == "__main__":
    main()
