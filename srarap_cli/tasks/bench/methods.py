"""Run several methods on one problem from the same start and compare them on wall time.

Every SR method shares one energy, so they are ranked by the time they need to come within
0.1% and 1% of the lowest energy any of them reached. Classic ARAP (ours, and libigl's in the
same process) minimizes another energy and is compared on iteration cost and final shape.
"""
import statistics
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ...solver.deformer import Deformer
from ...solver.libigl import igl
from ...solver.settings import Settings

ACCELERATED = "+anderson"
SR_METHODS = ("sr-linear", "sr-linear-sym", "sr-relax", "sr-linear-sym" + ACCELERATED)
ALL_METHODS = SR_METHODS + ("arap", "arap" + ACCELERATED)
IGL = "libigl-arap"
THRESHOLDS = (0.001, 0.01)


@dataclass
class MethodRun:
    """One method's run: its log rows, final positions and precompute time."""

    name: str
    log: list
    positions: np.ndarray
    precompute: float
    summary: dict = field(default_factory=dict)


def run_methods(V: np.ndarray, F: np.ndarray, ids: np.ndarray, targets: np.ndarray,
                methods: Sequence[str], *, settings: Settings,
                time_budget: float) -> list[MethodRun]:
    """Run ``methods`` (names from ALL_METHODS, plus ``libigl-arap``) on one problem.

    A plain method name runs the plain iteration from Laplacian editing (the paper's
    setting); ``<method>+anderson`` runs the tool's default, Anderson acceleration from the
    harmonic start. ``arap`` and ``libigl-arap`` use unclamped cotangent weights, as libigl
    does, so the two can be compared; the SR methods use ``settings.weights``. Every other
    setting comes from ``settings`` (a :class:`~srarap_cli.solver.settings.Settings`):
    ``max_iter`` and ``tol`` stop each method, as does ``time_budget`` (seconds).

    Returns
    -------
    list of MethodRun, in the order given
    """
    runs = []
    for name in methods:
        if name == IGL:
            runs.append(_run_igl(V, F, ids, targets, time_budget, settings.max_iter))
            continue
        t0 = time.perf_counter()
        method = name.removesuffix(ACCELERATED)
        variant = ({"accel": "anderson", "start": "harmonic"} if name.endswith(ACCELERATED)
                   else {"accel": "none", "start": "laplacian"})
        chosen = settings.replace(method=method, time_limit=time_budget, **variant,
                                  **({"weights": "cotan"} if method == "arap" else {}))
        d = Deformer(V, F, ids, settings=chosen)
        pre = time.perf_counter() - t0
        r = d.solve(targets)
        runs.append(MethodRun(name, r.log, r.positions, pre))
    _summarize(runs, ids, targets)
    return runs


def _run_igl(V, F, ids, targets, time_budget, max_iter):
    """libigl's ARAP one iteration per call, from our ``arap``'s start (Laplacian editing
    with the same weights), timed, and scored with our classic-ARAP energy."""
    t0 = time.perf_counter()
    data = igl.ARAPData()
    data.max_iter = 1
    data.energy = igl.ARAP_ENERGY_TYPE_SPOKES  # its default for 3D surfaces is spokes-and-rims
    igl.arap_precomputation(V, F, 3, ids.astype(np.int32), data)
    pre = time.perf_counter() - t0
    scorer = Deformer(V, F, ids, weights="cotan", method="arap")
    U = scorer.solve(targets, max_iter=0, start="laplacian").positions
    log, elapsed = [_igl_row(scorer, U, 0, 0.0, None)], 0.0
    for k in range(1, max_iter + 1):
        t = time.perf_counter()
        U_new = igl.arap_solve(targets, data, U)
        elapsed += time.perf_counter() - t
        log.append(_igl_row(scorer, U_new, k, elapsed, U))
        U = U_new
        if elapsed >= time_budget:
            break
    return MethodRun(IGL, log, U, pre)


def _igl_row(scorer, P, k, seconds, P_prev):
    """Our classic-ARAP energy of libigl's positions (best-fit rotations per cell)."""
    R = scorer.best_rotors(P, np.tile([1.0, 0, 0, 0], (len(P), 1)))
    e = scorer.energy(P, R)["membrane"]
    move = 0.0 if P_prev is None else float(np.linalg.norm(P - P_prev, axis=1).max())
    return {"iteration": k, "membrane": e, "bending": 0.0, "total": e, "rel_change": float("nan"),
            "max_move": move, "seconds": seconds, "step": "start" if P_prev is None else "plain",
            "stop": ""}


def _summarize(runs, ids, targets):
    """Per-run figures; thresholds are relative to the lowest energy of the run's family
    (SR energy, or classic ARAP's energy for arap, arap+anderson and libigl)."""
    family = {r.name: r.name in SR_METHODS for r in runs}
    best = {sr: min((row["total"] for r in runs if family[r.name] == sr for row in r.log),
                    default=None) for sr in (True, False)}
    for r in runs:
        low = best[family[r.name]]
        times = np.diff([row["seconds"] for row in r.log])
        s = {"method": r.name, "iterations": len(r.log) - 1,
             "ms_per_iteration": 1e3 * statistics.median(times) if times.size else float("nan"),
             "precompute_s": r.precompute, "final_energy": r.log[-1]["total"],
             "seconds": r.log[-1]["seconds"],
             "max_constraint_error": float(np.abs(r.positions[ids] - targets).max())}
        for frac in THRESHOLDS:
            # an unclamped classic ARAP energy can be negative: ``within`` means above it
            assert low is not None  # every method logged its start
            hit = next((row for row in r.log if row["total"] <= low + frac * abs(low)), None)
            key = f"{frac * 100:g}%"
            s[f"iterations_to_{key}"] = hit["iteration"] if hit else None
            s[f"seconds_to_{key}"] = hit["seconds"] if hit else None
        r.summary = s
    ours = next((r for r in runs if r.name == "arap"), None)
    peer = next((r for r in runs if r.name == IGL), None)
    if ours and peer:
        peer.summary["ratio_to_arap"] = (peer.summary["ms_per_iteration"]
                                         / ours.summary["ms_per_iteration"])
        peer.summary["max_distance_to_arap"] = float(
            np.linalg.norm(peer.positions - ours.positions, axis=1).max())
    return best[True]
