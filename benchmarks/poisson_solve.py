"""rslab's factorization and solves of a case's Poisson matrix, by worker count and precision.

The matrix is the one :class:`srarap_cli.solver.global_step.PoissonSolver` factors (the
cotangent Laplacian with identity rows and columns at the held vertices), captured from it.
For each worker count and factor precision: the factorization's seconds and stored entries,
a 3-column solve (medians of ``--repeat``, C- and Fortran-ordered right-hand sides) and its
relative residual; in single precision also with one refinement step.

Run: python benchmarks/poisson_solve.py [--cases bar500k,bar2m] [--threads 1,2]
     [--dtypes float64,float32] [--repeat 7]
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


def median_seconds(call, repeat):
    seconds, out = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        out = call()
        seconds.append(time.perf_counter() - start)
    return out, float(np.median(seconds))


def measure(name, A, threads, dtype, repeat):
    import rslab

    B = np.ascontiguousarray(np.random.default_rng(0).standard_normal((A.shape[0], 3)))
    start = time.perf_counter()
    f = rslab.analyze(A, path="ldlt", ordering="amd", threads=threads,
                      factor_dtype=dtype).factor(A)
    factor_seconds = time.perf_counter() - start
    X, c_order = median_seconds(lambda: f.solve_many(B), repeat)
    _, f_order = median_seconds(lambda: f.solve_many(np.asfortranarray(B)), repeat)
    residual = np.linalg.norm(B - A @ X) / np.linalg.norm(B)
    line = (f"{name} ({A.shape[0]} rows) {threads} worker(s) {dtype}: factor {factor_seconds:.2f} s, "
            f"{f.factor_nnz / 1e6:.1f}M stored; 3-column solve {c_order:.3f} s (Fortran order "
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
    args = ap.parse_args()
    for name in args.cases.split(","):
        A = poisson_matrix(name)
        for dtype in args.dtypes.split(","):
            answers = [measure(name, A, int(t), dtype, args.repeat)
                       for t in args.threads.split(",")]
            same = all(np.array_equal(answers[0], X) for X in answers[1:])
            print(f"{name} {dtype}: the same answer bit for bit with every worker count: {same}")


if __name__ == "__main__":
    main()
