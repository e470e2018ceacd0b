"""Which part of the error limits the coarse-to-fine iteration (issue 51, item 2).

For each case: a tight solve (tol 1e-11, the same coarse-to-fine solver) gives the reference
rotors R* and positions P*. Then the default solve (tol 1e-6) runs, and each full-resolution
iterate's rotor error e = R_k - R* (same hemispheres) is split in two:

- the part the coarse-grid correction can represent: its range is one 4-vector per coarse
  cell (the correction adds ``(y - y0 - r)[cell]``, constant over each coarse vertex's
  cell), so that part is e averaged over each cell, spread back over it;
- the rest: e minus that, what only the full-resolution step can remove.

The table gives, per iteration, the energy gap to the tight solve (relative), the rotor
error (RMS over vertices), its two parts (their squares add up to the whole), the part's
share and the positions' largest distance to P* (relative to the bounding-box diagonal).
Where the rest dominates, the coarse level has done its work and the fine step is the weak
link; where the coarse part dominates, a better or more frequent correction would pay.

It also prints, for each full-resolution correction, how much of the smooth error of the
rotors it is added to it removes (gain; 1 is exact) and the cosine between the two. Flags for
experiments patch the correction at run time (nothing of them is shipped): ``--every 1`` (a
correction every iteration), ``--coarse-steps`` / ``--nested-steps`` (the correction's coarse
steps), ``--scale`` (the correction times a factor), ``--kappa`` (the averaged residual
times a factor before the coarse solve), ``--smooth`` (neighbour-averaging sweeps of the
correction), ``--galerkin`` (the Galerkin correction of ``galerkin_correction.py`` instead,
``--aggregates N`` its largest aggregate count). The tight solves are kept in
``out/tight-<case>.npz``: delete them when the solver changes.

Run: python benchmarks/multires_error_split.py [--cases spot46k,spot184k,bar500k]
     [--no-table] [--every 1] [--coarse-steps N] [--nested-steps N] [--scale S] [--kappa K]
     [--smooth N] [--galerkin [--aggregates N]]
"""
import argparse
import os
import sys
import time
from types import SimpleNamespace

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from error_split_cases import case as _case  # noqa: E402
from run_bench import OUT  # noqa: E402

from srarap_cli.io.handles import load_handles  # noqa: E402
from srarap_cli.io.mesh import read_mesh  # noqa: E402
from srarap_cli.solver.drivers import monitor  # noqa: E402
from srarap_cli.solver.oneshot import make_deformer  # noqa: E402
from srarap_cli.solver.quaternion import align_hemisphere  # noqa: E402
from srarap_cli.solver.settings import resolve  # noqa: E402
from srarap_cli.tasks.pipeline import problem  # noqa: E402


class Recorder:
    """Keeps a copy of each full-resolution iterate's rotors and positions (the Monitor
    sees every level's; the full mesh's are the ones of ``n`` rows)."""

    def __init__(self, n):
        self.n, self.rows, self.real = n, [], monitor.Monitor.record
        recorder = self

        def record(mon, state, previous=None, kind=None):
            if len(state.rotors) == recorder.n:
                recorder.rows.append((state.rotors.copy(), state.positions.copy(), state.total))
            return recorder.real(mon, state, previous, kind)
        monitor.Monitor.record = record
        import galerkin_correction

        from srarap_cli.solver.multires import correction
        self.corrections = []
        # both corrections, so that a --galerkin run is recorded as well
        self.patched = [(cls, cls.__call__) for cls in (correction.CoarseCorrection,
                                                         galerkin_correction.GalerkinCorrection)]

        def recorded(call):
            def corrected(corr, state, residual):
                out = call(corr, state, residual)
                if len(state.rotors) == recorder.n and out is not None:
                    # the driver adds the correction to its mixed rotors (its local)
                    mixed = sys._getframe(1).f_locals["mixed"]
                    recorder.corrections.append((mixed.copy(), out.copy()))
                return out
            return corrected
        for cls, call in self.patched:
            cls.__call__ = recorded(call)

    def stop(self):
        monitor.Monitor.record = self.real
        for cls, call in self.patched:
            cls.__call__ = call


def variant(every=None, coarse_steps=None, nested_steps=None, scale=None, kappa=None):
    """Patch the correction's constants for an experiment (None: as shipped)."""
    from srarap_cli.solver.multires import correction as c
    if kappa:
        def scaled_residual(self, state, residual):
            rotors = state.rotors
            y0 = rotors[self.vertices]
            r = self._average(residual)
            tau = self._map(y0) - y0 - kappa * r
            y = self._fixed_point(y0, tau, y0 + kappa * r)
            if not np.isfinite(y).all():
                return None
            out = np.zeros_like(rotors)
            out[self._in_cell] = (y - y0 - r)[self._cell]
            return out
        c.CoarseCorrection.__call__ = scaled_residual
    if coarse_steps:
        c.COARSE_STEPS = coarse_steps
    if nested_steps:
        c.NESTED_STEPS = nested_steps
    if every == 1:
        c.EVERY_STEP_RATIO = 0
    if scale:
        call = c.CoarseCorrection.__call__

        def scaled(self, state, residual):
            out = call(self, state, residual)
            return None if out is None else out * scale
        c.CoarseCorrection.__call__ = scaled


def _cell_mean(e, cells, count):
    mean = np.stack([np.bincount(cells, e[:, j]) for j in range(4)], axis=1) / count[:, None]
    return mean[cells]


def gains(corrections, best, cells, count):
    """Per correction: how much of the smooth error of the rotors it is added to (the
    driver's mixed rotors) it removes: its projection on minus their cell-averaged error,
    relative to that error (1 exact, 0 nothing), and the cosine between the two."""
    out = []
    for rotors, delta in corrections:
        sign = np.sign(np.einsum("ij,ij->i", rotors, best))[:, None]
        ideal = -_cell_mean(sign * rotors - best, cells, count)
        d = sign * delta
        dot = float(np.einsum("ij,ij->", d, ideal))
        norm = float(np.einsum("ij,ij->", ideal, ideal))
        out.append((dot / norm, dot / np.sqrt(norm * float(np.einsum("ij,ij->", d, d)))))
    return out


SMOOTH = {"sweeps": 0, "graph": None}


def smoothing(sweeps):
    """Experiment: the full-resolution correction smoothed by ``sweeps`` neighbour-averaging
    sweeps on the fine graph before it is added (the piecewise-constant one jumps between
    cells)."""
    from srarap_cli.solver.multires import correction as c
    SMOOTH["sweeps"] = sweeps
    call = c.CoarseCorrection.__call__

    def smoothed(self, state, residual):
        out = call(self, state, residual)
        graph = SMOOTH["graph"]
        if out is None or graph is None or len(state.rotors) != graph.shape[0]:
            return out
        for _ in range(SMOOTH["sweeps"]):
            out = 0.5 * (out + graph @ out)
        return out
    c.CoarseCorrection.__call__ = smoothed


def _averaging(F, n):
    import scipy.sparse as sp
    i = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
    j = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    A = sp.csr_matrix((np.ones(2 * i.size), (np.r_[i, j], np.r_[j, i])), shape=(n, n))
    A.data[:] = 1.0
    return sp.diags(1.0 / np.maximum(np.asarray(A.sum(axis=1)).ravel(), 1)) @ A


def split(name, table=True):
    mesh_path, handles_path = _case(name)
    mesh = read_mesh(mesh_path)
    c = load_handles(handles_path, mesh.vertices)
    p = problem(mesh, c, mesh_path)
    settings = resolve(c.solver)
    start = time.perf_counter()
    d = make_deformer(p.V, p.F, p.ids, settings=settings)
    print(f"== {name}: {len(p.V)} vertices, setup {time.perf_counter() - start:.1f} s",
          flush=True)
    start = time.perf_counter()
    tight = _tight(d, p.targets, name)
    print(f"tight: {tight.iterations} iterations, {time.perf_counter() - start:.1f} s, "
          f"{tight.stop_reason}", flush=True)
    if SMOOTH["sweeps"]:
        SMOOTH["graph"] = _averaging(np.asarray(p.F), len(p.V))
    rec = Recorder(len(p.V))
    try:
        run = d.solve(p.targets)
    finally:
        rec.stop()
    diag = float(np.linalg.norm(p.V.max(axis=0) - p.V.min(axis=0)))
    far = float(np.sqrt(np.einsum("ij,ij->i", run.positions - tight.positions,
                                  run.positions - tight.positions).max())) / diag
    print(f"SUMMARY {name}: {run.iterations} iterations (+ {run.coarse_iterations} coarse), "
          f"full-resolution phase {run.multires.stages['fine_iterations']:.2f} s, solve "
          f"{run.multires.wall:.2f} s, fallbacks "
          f"{sum(row['step'] == 'fallback' for row in run.log)}, "
          f"gap {(run.energy - tight.energy) / tight.energy:.1e}, "
          f"max dist {far:.1e} of the diagonal", flush=True)
    if not table:
        return
    cells = getattr(d, "_nearest", None)
    if cells is None:
        print("not coarse-to-fine: nothing to split")
        return
    cells = np.where(cells < 0, cells.max() + 1, cells)
    count = np.bincount(cells).astype(float)
    best = tight.energy
    print(f"default: {run.iterations} full-resolution iterations (+ {run.coarse_iterations} "
          f"coarse); coarse cells {int(count.size)}")
    print("corrections, gain and cosine against minus the smooth error: " + ", ".join(
        f"{g:.2f} ({c:.2f})" for g, c in gains(rec.corrections, tight.rotors, cells, count)))
    print("| it | energy gap | rotor error | coarse part | rest | coarse share | max dist |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for k, (R, P, total) in enumerate(rec.rows):
        e = align_hemisphere(R, tight.rotors) - tight.rotors
        coarse = _cell_mean(e, cells, count)
        rest = e - coarse
        rms = [float(np.sqrt(np.einsum("ij,ij->", x, x) / len(x))) for x in (e, coarse, rest)]
        dist = float(np.sqrt(np.einsum("ij,ij->i", P - tight.positions,
                                       P - tight.positions).max())) / diag
        share = rms[1] ** 2 / max(rms[0] ** 2, 1e-300)
        print(f"| {k} | {(total - best) / best:.2e} | {rms[0]:.2e} | {rms[1]:.2e} | "
              f"{rms[2]:.2e} | {share:.2f} | {dist:.1e} |", flush=True)


def _tight(d, targets, name):
    """The tight solve, kept in out/ between runs (it takes longer than the rest)."""
    path = os.path.join(OUT, f"tight-{name}.npz")
    if os.path.exists(path):
        saved = np.load(path)
        return SimpleNamespace(positions=saved["P"], rotors=saved["R"],
                               energy=float(saved["E"]), iterations=int(saved["it"]),
                               stop_reason="(saved)")
    tight = d.solve(targets, tol=1e-11, max_iter=400)
    np.savez(path, P=tight.positions, R=tight.rotors, E=tight.energy, it=tight.iterations)
    return tight


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default="spot46k,spot184k,bar500k")
    ap.add_argument("--every", type=int, default=None, help="experiment: 1 = every iteration")
    ap.add_argument("--coarse-steps", type=int, default=None)
    ap.add_argument("--nested-steps", type=int, default=None)
    ap.add_argument("--scale", type=float, default=None, help="experiment: scale corrections")
    ap.add_argument("--kappa", type=float, default=None,
                    help="experiment: the averaged residual scaled before the coarse solve")
    ap.add_argument("--smooth", type=int, default=0, help="experiment: smoothing sweeps")
    ap.add_argument("--galerkin", action="store_true",
                    help="experiment: the Galerkin correction of galerkin_correction.py")
    ap.add_argument("--aggregates", type=int, default=None,
                    help="experiment: the Galerkin correction's MAX_AGGREGATES")
    ap.add_argument("--no-table", action="store_true")
    args = ap.parse_args()
    if args.galerkin:
        import galerkin_correction
        galerkin_correction.install()
        if args.aggregates:
            galerkin_correction.MAX_AGGREGATES = args.aggregates
    variant(args.every, args.coarse_steps, args.nested_steps, args.scale, args.kappa)
    if args.smooth:
        smoothing(args.smooth)
    for name in args.cases.split(","):
        split(name, not args.no_table)


if __name__ == "__main__":
    main()
