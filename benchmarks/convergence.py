"""Iterations and seconds until converged: the default solver against the plain iteration.

For each case: a tight direct solve (tol 1e-10) gives the reference shape and, with every
other run, the best energy. Then the plain iteration from Laplacian editing (the paper's
setting, `--accel none --start laplacian --handle-rotors lagged`, direct) and the default
solver as `deform` builds it (Anderson acceleration, harmonic start, handle-boundary rotors
from their own rows, tol 1e-6; `multires auto`: coarse-to-fine with
coarse-grid corrections from 20k vertices) run `--repeat` times each; the table gives the
medians of the seconds to come within 1% and 0.1% of the best energy, the full-resolution
iterations (deterministic), the ratios plain/default, and where the default run stopped: its
iterations, seconds and distance to the tight shape relative to the bounding-box diagonal. A
coarse-to-fine run's seconds include its coarse solve (its iterations are given apart); no
column includes setup (factorizations, simplification): `setup s` gives the default solver's.
`ms/it` is the median time per logged full-resolution iteration; `ms/step` the default's time
per local step (a rejected Anderson candidate costs one more local step than its iteration).
`rule shift` is how far the default's rotor rule (``handle_rotors``) moves the tight shape from
the paper's rule; `plain same rule` runs the plain iteration with the default's rule once
(what acceleration and the start add on their own, and the per-iteration overhead of
acceleration for the same local step).

Run: python benchmarks/convergence.py [--cases cylinder,max,spot,bar100k,bar135,spot46k]
     [--repeat 3] [--plain-budget 300] [--json out/convergence.json]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np
from run_bench import BIG_BAR, CASES, HERE, OUT

from srarap_cli import Deformer
from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh
from srarap_cli.solver.oneshot import make_deformer
from srarap_cli.tasks.pipeline import problem

BARS = {os.path.basename(BIG_BAR): [],
        "bar-6k.obj": ["--rings", "120", "--segments", "48"]}
CASES = {**CASES, "bar135": (os.path.join(OUT, "bar-6k.obj"),
                             os.path.join(HERE, "cases", "bar-6k-twist135.yaml")),
         "spot46k": (os.path.join(OUT, "spot-46k.obj"),
                     os.path.join(HERE, "..", "configs", "spot-nod.yaml"))}
PLAIN = {"accel": "none", "start": "laplacian"}
PAPER = {"handle_rotors": "lagged"}  # the plain iteration's setup: the paper's section 6.2
DEFAULT = {"accel": "anderson", "start": "harmonic"}


def fine_rows(log):
    """The full-resolution rows of a log (a coarse-to-fine log starts with coarse ones)."""
    return [r for r in log if not r["step"].startswith("coarse-")]


def hits(log, best):
    """(full-resolution iterations, seconds) until within 1% and 0.1% of ``best`` (None:
    never)."""
    out = []
    rows = fine_rows(log)
    for frac in (1e-2, 1e-3):
        k = next((k for k, r in enumerate(rows) if r["total"] <= best * (1 + frac)), None)
        out.append((k, rows[k]["seconds"]) if k is not None else (None, None))
    return out


def median_or_none(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def run_case(name, args):
    mesh_path, handles = CASES[name]
    bar = BARS.get(os.path.basename(mesh_path))
    if bar is not None and not os.path.exists(mesh_path):
        subprocess.run([sys.executable, os.path.join(HERE, "make_big_bar.py"), mesh_path, *bar],
                       check=True)
    if name == "spot46k" and not os.path.exists(mesh_path):
        subprocess.run([sys.executable, os.path.join(HERE, "make_big_spot.py"), mesh_path,
                        "--levels", "1"], check=True)
    mesh = read_mesh(mesh_path)
    p = problem(mesh, load_handles(handles, mesh.vertices))
    d = Deformer(p.V, p.F, p.ids, labels=p.labels)
    paper = Deformer(p.V, p.F, p.ids, labels=p.labels, **PAPER)
    diag = float(np.linalg.norm(np.ptp(p.V, axis=0)))
    tight = d.solve(p.targets, tol=1e-10, max_iter=5000)
    tight_paper = paper.solve(p.targets, tol=1e-10, max_iter=5000)
    plain = [paper.solve(p.targets, tol=1e-9, max_iter=20000, time_limit=args.plain_budget,
                         **PLAIN) for _ in range(args.repeat)]
    # the plain iteration with the default's rotor rule: what acceleration alone gains, and
    # the per-iteration overhead of acceleration with the same local step
    same_rule = d.solve(p.targets, tol=1e-9, max_iter=20000, time_limit=args.plain_budget,
                        **PLAIN)
    mark = time.perf_counter()
    solver = make_deformer(p.V, p.F, p.ids, p.labels)
    setup = time.perf_counter() - mark
    fast = [solver.solve(p.targets, tol=1e-6, **DEFAULT) for _ in range(args.repeat)]
    best = min(row["total"] for r in [tight, tight_paper, *plain, *fast]
               for row in fine_rows(r.log))
    row = {"case": name, "vertices": len(p.V), "best_energy": best, "default_setup_s": setup,
           "default_coarse_it": len(fast[0].log) - len(fine_rows(fast[0].log))}
    for label, runs in (("plain", plain), ("default", fast)):
        marks = [hits(r.log, best) for r in runs]
        for k, key in enumerate(("1%", "0.1%")):
            row[f"{label}_it@{key}"] = marks[0][k][0]
            row[f"{label}_s@{key}"] = median_or_none([m[k][1] for m in marks])
        row[f"{label}_ms/it"] = 1e3 * statistics.median(
            _fine_seconds(r) / max(len(fine_rows(r.log)) - 1, 1) for r in runs)
    row["plain_same_rule_it@0.1%"] = hits(same_rule.log, best)[1][0]
    row["plain_same_rule_ms/it"] = 1e3 * _fine_seconds(same_rule) / max(
        len(same_rule.log) - 1, 1)
    rows = fine_rows(fast[0].log)
    steps = len(rows) - 1 + sum(x["step"] == "fallback" for x in rows)
    row["default_ms/step"] = 1e3 * statistics.median(_fine_seconds(r) for r in fast) / steps
    row["default_fallbacks"] = sum(x["step"] == "fallback" for x in rows)
    row["default_stop_it"] = len(rows) - 1
    row["default_stop_s"] = statistics.median(r.log[-1]["seconds"] for r in fast)
    row["default_converged"] = fast[0].converged
    row["default_dist/diag"] = float(np.linalg.norm(fast[0].positions - tight.positions,
                                                    axis=1).max() / diag)
    row["rule_shift/diag"] = float(np.linalg.norm(tight.positions - tight_paper.positions,
                                                  axis=1).max() / diag)
    for key in ("1%", "0.1%"):
        a, b = row[f"plain_it@{key}"], row[f"default_it@{key}"]
        row[f"ratio_it@{key}"] = a / b if a and b else None
        a, b = row[f"plain_s@{key}"], row[f"default_s@{key}"]
        row[f"ratio_s@{key}"] = a / b if a and b else None
    return row


def _fine_seconds(result):
    """Seconds of a run's full-resolution iterations (from its start row to its end)."""
    rows = fine_rows(result.log)
    return rows[-1]["seconds"] - rows[0]["seconds"]


def fmt(value, spec):
    return "-" if value is None else format(value, spec)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--plain-budget", type=float, default=300.0,
                    help="seconds the plain iteration may run per repeat")
    ap.add_argument("--json")
    args = ap.parse_args()
    rows = []
    print("| case | n | plain it@1% | s@1% | it@0.1% | s@0.1% | default it@1% | s@1% | "
          "it@0.1% | s@0.1% | ratio it / s @0.1% | default stop: it, s, dist/diag | "
          "rule shift/diag | plain same rule it@0.1% | ms/it plain, same rule, default; "
          "ms/step | default setup s (coarse it) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name in args.cases.split(","):
        r = run_case(name, args)
        rows.append(r)
        print(f"| {name} | {r['vertices']} | {fmt(r['plain_it@1%'], 'd')} | "
              f"{fmt(r['plain_s@1%'], '.2f')} | {fmt(r['plain_it@0.1%'], 'd')} | "
              f"{fmt(r['plain_s@0.1%'], '.2f')} | {fmt(r['default_it@1%'], 'd')} | "
              f"{fmt(r['default_s@1%'], '.2f')} | {fmt(r['default_it@0.1%'], 'd')} | "
              f"{fmt(r['default_s@0.1%'], '.2f')} | {fmt(r['ratio_it@0.1%'], '.1f')} / "
              f"{fmt(r['ratio_s@0.1%'], '.1f')} | {r['default_stop_it']}, "
              f"{r['default_stop_s']:.2f}, {r['default_dist/diag']:.1e} | "
              f"{r['rule_shift/diag']:.1e} | {fmt(r['plain_same_rule_it@0.1%'], 'd')} | "
              f"{r['plain_ms/it']:.1f}, {r['plain_same_rule_ms/it']:.1f}, "
              f"{r['default_ms/it']:.1f}; {r['default_ms/step']:.1f} | "
              f"{r['default_setup_s']:.2f} ({r['default_coarse_it']}) |", flush=True)
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=2)


if __name__ == "__main__":
    main()
