"""rslab's factorization and solves of a case's Poisson matrix (or rotor preconditioner), by
worker count and precision, and SuperLU's with METIS's order beside them.

The Poisson matrix is the one :class:`srarap_cli.solver.global_step.PoissonSolver` factors
(the cotangent Laplacian with identity rows and columns at the held vertices), the rotor
preconditioner the scalar matrix the local step's conjugate gradients factor
(``--matrix rotor``, 4 right-hand sides, brought to unit size as ``linalg.factor`` does);
both captured from the solver's own setup. For each worker count and factor precision: the
factorization's seconds and stored entries, a solve (medians of ``--repeat``, C- and
Fortran-ordered right-hand sides) and its relative residual; in single precision also with
one refinement step. ``--superlu`` adds SuperLU in the precision the solver uses.

Run: python benchmarks/poisson_solve.py [--cases bar500k,bar2m] [--matrix poisson|rotor]
     [--threads 1,2] [--dtypes float64,float32] [--repeat 7] [--superlu]
"""
import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from multires_error_split import _case  # noqa: E402

from srarap_cli.io.handles import load_handles  # noqa: E402
from srarap_cli.io.mesh import read_mesh  # noqa: E402
from srarap_cli.solver import global_step  # noqa: E402
from srarap_cli.solver.operators import cell_graph  # noqa: E402
from srarap_cli.tasks.pipeline import problem  # noqa: E402


def poisson_matrix(name):
    """The case's Poisson matrix, as PoissonSolver builds it (its factorization skipped)."""
    mesh_path, handles_path = _case(name)
    mesh = read_mesh(mesh_path)
    p = problem(mesh, load_handles(handles_path, mesh.vertices), mesh_path)
    graph = cell_graph(np.asarray(p.V), np.asarray(p.F))
    held = np.zeros(graph.n, dtype=bool)
    held[p.ids] = True
    captured = {}
    real = global_step.factor
    global_step.factor = lambda A, **_: captured.setdefault("A", A)
    try:
        global_step.PoissonSolver(graph, held)
    finally:
        global_step.factor = real
    return captured["A"].tocsr()


def rotor_matrix(name):
    """The case's rotor preconditioner (free rows), as the default local step builds it
    (factorizations skipped), divided by its largest entry as ``linalg.factor`` does."""
    from srarap_cli.solver.deformer import Deformer
    from srarap_cli.solver.local_step import rotor_system
    from srarap_cli.solver.settings import resolve

    mesh_path, handles_path = _case(name)
    mesh = read_mesh(mesh_path)
    handles = load_handles(handles_path, mesh.vertices)
    p = problem(mesh, handles, mesh_path)
    captured = {}
    real = global_step.factor, rotor_system.factor
    global_step.factor = lambda A, **_: None
    rotor_system.factor = lambda A, **_: captured.setdefault("A", A)
    try:
        Deformer(p.V, p.F, p.ids, settings=resolve(handles.solver)).prepare()
    finally:
        global_step.factor, rotor_system.factor = real
    A = captured["A"].tocsr()
    return A / float(abs(A).max())


def superlu(name, A, dtype, columns, repeat):
    """SuperLU with METIS's order in ``dtype`` (the solver's path for large matrices)."""
    from srarap_cli.solver import linalg

    B = np.random.default_rng(0).standard_normal((A.shape[0], columns))
    start = time.perf_counter()
    solve = linalg._nested_dissection(A.astype(dtype), linalg.fill_order(A))
    factor_seconds = time.perf_counter() - start
    X, seconds = median_seconds(lambda: solve(B), repeat)
    residual = np.linalg.norm(B - A @ X) / np.linalg.norm(B)
    print(f"{name} ({A.shape[0]} rows) SuperLU {dtype}, METIS order: factor and order "
          f"{factor_seconds:.2f} s; {columns}-column solve {seconds:.3f} s, residual "
          f"{residual:.1e}", flush=True)


def median_seconds(call, repeat):
    seconds, out = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        out = call()
        seconds.append(time.perf_counter() - start)
    return out, float(np.median(seconds))


def measure(name, A, threads, dtype, repeat, columns=3):
    import rslab

    B = np.ascontiguousarray(np.random.default_rng(0).standard_normal((A.shape[0], columns)))
    start = time.perf_counter()
    f = rslab.analyze(A, path="ldlt", ordering="amd", threads=threads,
                      factor_dtype=dtype).factor(A)
    factor_seconds = time.perf_counter() - start
    X, c_order = median_seconds(lambda: f.solve_many(B), repeat)
    _, f_order = median_seconds(lambda: f.solve_many(np.asfortranarray(B)), repeat)
    residual = np.linalg.norm(B - A @ X) / np.linalg.norm(B)
    line = (f"{name} ({A.shape[0]} rows) {threads} worker(s) {dtype}: factor {factor_seconds:.2f} s, "
            f"{f.factor_nnz / 1e6:.1f}M stored; {columns}-column solve {c_order:.3f} s (Fortran order "
            f"{f_order:.3f} s), residual {residual:.1e}")
    if dtype == "float32":
        def refined():
            X = f.solve_many(B)
            return X + f.solve_many(np.ascontiguousarray(B - A @ X))
        X, seconds = median_seconds(refined, repeat)
        line += (f"; one refinement {seconds:.3f} s, residual "
                 f"{np.linalg.norm(B - A @ X) / np.linalg.norm(B):.1e}")
    print(line, flush=True)
    return X


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default="bar500k")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--dtypes", default="float64,float32")
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--matrix", choices=("poisson", "rotor"), default="poisson")
    ap.add_argument("--superlu", action="store_true")
    args = ap.parse_args()
    columns = 3 if args.matrix == "poisson" else 4
    for name in args.cases.split(","):
        A = poisson_matrix(name) if args.matrix == "poisson" else rotor_matrix(name)
        for dtype in args.dtypes.split(","):
            answers = [measure(name, A, int(t), dtype, args.repeat, columns)
                       for t in args.threads.split(",")]
            same = all(np.array_equal(answers[0], X) for X in answers[1:])
            print(f"{name} {dtype}: the same answer bit for bit with every worker count: {same}")
        if args.superlu:
            superlu(name, A, np.float64 if args.matrix == "poisson" else np.float32, columns,
                    args.repeat)


if __name__ == "__main__":
    main()
