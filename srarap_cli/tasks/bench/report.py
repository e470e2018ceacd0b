"""Files and table of a benchmark: curves CSV, summary JSON, energy-vs-time PNG."""
import io
import json
from typing import Any

from ...io.solve_log import LOG_FIELDS, format_log
from .methods import IGL, SR_METHODS, MethodRun

COLUMNS = [("method", "method", "{}"), ("iterations", "iters", "{}"),
           ("ms_per_iteration", "ms/iter", "{:.2f}"), ("iterations_to_1%", "it@1%", "{}"),
           ("seconds_to_1%", "s@1%", "{:.3f}"), ("iterations_to_0.1%", "it@0.1%", "{}"),
           ("seconds_to_0.1%", "s@0.1%", "{:.3f}"), ("final_energy", "energy", "{:.6g}"),
           ("max_constraint_error", "constraint err", "{:.2e}"),
           ("precompute_s", "precompute s", "{:.3f}")]


def curves_csv(runs: list[MethodRun]) -> str:
    rows = [{"method": r.name, **row} for r in runs for row in r.log]
    return format_log(rows, ".csv", ("method",) + LOG_FIELDS)


def summary_json(runs: list[MethodRun], info: dict[str, Any]) -> str:
    return json.dumps({"problem": info, "methods": [r.summary for r in runs]}, indent=2) + "\n"


def table(runs: list[MethodRun]) -> str:
    """A fixed-width text table, one row per method, plus the libigl comparison."""
    rows = [[h for _, h, _ in COLUMNS]]
    for r in runs:
        rows.append(["-" if r.summary.get(k) is None else fmt.format(r.summary[k])
                     for k, _, fmt in COLUMNS])
    widths = [max(len(row[i]) for row in rows) for i in range(len(COLUMNS))]
    lines = ["  ".join(c.rjust(w) if i else c.ljust(w) for i, (c, w) in
                       enumerate(zip(row, widths))) for row in rows]
    peer = next((r for r in runs if r.name == IGL and "ratio_to_arap" in r.summary), None)
    if peer:
        lines.append(f"libigl ARAP / our arap time per iteration: "
                     f"{peer.summary['ratio_to_arap']:.2f}; max vertex distance between their "
                     f"results: {peer.summary['max_distance_to_arap']:.3g}")
    lines.append("it@x / s@x: iterations / seconds until the energy is within x of the lowest "
                 "energy any SR method reached (arap minimizes another energy: '-')")
    return "\n".join(lines) + "\n"


def plot_png(runs: list[MethodRun], title: str) -> bytes:
    """PNG bytes: SR energy minus the best against time (log-log), and classic ARAP."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sr = [r for r in runs if r.name in SR_METHODS]
    classic = [r for r in runs if r.name not in SR_METHODS]
    both = bool(sr) and bool(classic)
    fig, axes = plt.subplots(1, 2 if both else 1, figsize=(11 if both else 6, 4.2),
                             squeeze=False)
    panels = [(ax, group, label) for ax, group, label in zip(
        axes[0], [g for g in (sr, classic) if g],
        [t for g, t in ((sr, "SR-ARAP energy above the best reached"),
                        (classic, "classic ARAP energy above the best reached")) if g])]
    for ax, group, label in panels:
        best = min((row["total"] for r in group for row in r.log), default=0.0)
        for r in group:
            t = [max(row["seconds"], 1e-4) for row in r.log]
            e = [max(row["total"] - best, 1e-12 * max(abs(best), 1e-300)) for row in r.log]
            ax.loglog(t, e, label=r.name, marker=".", markersize=2, linewidth=1)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("energy - best")
        ax.set_title(label, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()
