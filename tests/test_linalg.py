"""The factorization paths (rslab; SuperLU in nested-dissection or minimum-degree order) solve
the same systems. SuperLU's own tests ask for it through $SRARAP_FACTOR."""
import igl
import numpy as np
import pytest
import scipy.sparse as sp
from helpers import ends, tube

from srarap_cli import Deformer
from srarap_cli.solver import linalg, one_triangle
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix

PATHS = ["nested dissection", "minimum degree", "rslab"]


@pytest.fixture
def superlu(monkeypatch):
    monkeypatch.setenv(one_triangle.ENV, "superlu")


def _use(path, monkeypatch):
    monkeypatch.setenv(one_triangle.ENV, "rslab" if path == "rslab" else "superlu")
    if path == "nested dissection":
        monkeypatch.setattr(linalg, "LARGE", 0)


def test_nested_dissection_back_end_solves_spd_systems(monkeypatch, superlu):
    rng = np.random.default_rng(1)
    M = sp.random(30, 30, density=0.2, random_state=2)
    A = (M @ M.T + sp.eye(30) * 0.5).tocsr()
    b = rng.standard_normal((30, 4))
    monkeypatch.setattr(linalg, "LARGE", 0)
    solve = linalg.factor(A, symmetric=True)
    assert np.abs(A @ solve(b) - b).max() < 1e-10
    assert np.abs(A @ solve(b[:, 0]) - b[:, 0]).max() < 1e-10
    assert solve(b[:, 0]).shape == (30,)


@pytest.mark.parametrize("approximate", [False, True])
@pytest.mark.parametrize("path", PATHS + ["unsymmetric"])
def test_every_path_answers_row_major(monkeypatch, path, approximate):
    """A block of rows of the answer is gathered and multiplied many times a step: an answer
    in column order (SuperLU's own) made each of those copy the whole array first."""
    rng = np.random.default_rng(3)
    M = sp.random(40, 40, density=0.2, random_state=4)
    A = (M @ M.T + sp.eye(40)).tocsr()
    _use("minimum degree" if path == "unsymmetric" else path, monkeypatch)
    monkeypatch.setattr(linalg, "ONE_TRIANGLE_FROM", 0)
    b = rng.standard_normal((40, 3))
    x = linalg.factor(A, symmetric=path != "unsymmetric", approximate=approximate)(b)
    assert x.flags.c_contiguous and x.dtype == np.float64
    assert np.abs(A @ x - b).max() < (1e-4 if approximate else 1e-10)


def test_large_mesh_back_end_gives_the_same_deformation(monkeypatch, superlu):
    V, F = tube(length=6.0, rings=12, segments=8)
    ids = ends(V, 6.0)
    T = V[ids].copy()
    top = T[:, 2] > 3
    T[top] = T[top] @ to_matrix(from_axis_angle([0, 0, 1], 90)).T
    # solved tightly: the orderings round differently, and the inexact local step passes
    # that on to the iterates (1e-6 at tol 1e-6). Not tighter than 1e-11: the energy jitters
    # by ~1e-11 relative there (the cap centres' rotors join the sparse solve), and a tol
    # 1e-12 run may never see three quiet steps in a row
    small = Deformer(V, F, ids).solve(T, tol=1e-11, max_iter=300)
    monkeypatch.setattr(linalg, "LARGE", 0)
    large = Deformer(V, F, ids).solve(T, tol=1e-11, max_iter=300)
    assert small.converged and large.converged
    assert np.abs(small.positions - large.positions).max() < 1e-7  # 1.4e-8 measured


@pytest.mark.slow
def test_nested_dissection_back_end_is_deterministic_across_processes():
    """Outputs must be byte-identical run to run: METIS's ordering is seeded, so two fresh
    interpreters factor and solve alike."""
    import subprocess
    import sys

    from helpers import ROOT
    script = (
        "import sys, hashlib; sys.path.insert(0, 'tests')\n"
        "from helpers import ends, tube\n"
        "from srarap_cli import Deformer\n"
        "import os; os.environ['SRARAP_FACTOR'] = 'superlu'\n"
        "from srarap_cli.solver import linalg\n"
        "linalg.LARGE = 0\n"
        "V, F = tube(length=10.0, rings=30, segments=16)\n"
        "ids = ends(V, 10.0)\n"
        "T = V[ids].copy(); T[T[:, 2] > 5] += [4.0, 0, -1.0]\n"
        "r = Deformer(V, F, ids).solve(T, max_iter=20)\n"
        "print(hashlib.sha256(r.positions.tobytes()).hexdigest())\n")
    digests = {subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True,
                              text=True, check=True).stdout for _ in range(2)}
    assert len(digests) == 1 and len(next(iter(digests)).strip()) == 64


def test_one_nested_dissection_serves_the_poisson_matrix_and_the_rotor_preconditioner(
        monkeypatch, superlu):
    """Their free vertices differ (the rotor system keeps a handle's interior), yet one METIS
    run of the mesh graph, restricted to each matrix's rows, orders both."""
    import pymetis

    runs = []
    real = pymetis.nested_dissection
    monkeypatch.setattr(pymetis, "nested_dissection",
                        lambda *a, **k: runs.append(1) or real(*a, **k))
    monkeypatch.setattr(linalg, "APART_FROM", 10**12)  # METIS in this process: counted here
    monkeypatch.setattr(linalg, "LARGE", 0)
    V, F = tube(length=6.0, rings=12, segments=8)
    ids = ends(V, 6.0)
    d = Deformer(V, F, ids)
    assert len(runs) == 1
    assert d.local_step.free.size != len(V) - ids.size  # two different row sets were ordered


def test_restricted_order_is_the_mesh_order_of_the_rows():
    V, F = tube(length=6.0, rings=12, segments=8)
    graph = Deformer(V, F, ends(V, 6.0), prepare=False).graph
    full = graph.fill_order()
    assert np.array_equal(np.sort(full), np.arange(len(V)))
    rows = np.arange(0, len(V), 3)
    sub = graph.fill_order(rows)
    assert np.array_equal(np.sort(sub), np.arange(rows.size))
    rank = np.argsort(full)  # position of each vertex in the full order
    assert np.all(np.diff(rank[rows[sub]]) > 0)


@pytest.mark.parametrize("path", PATHS)
def test_an_approximate_factor_is_single_precision_and_answers_in_double(monkeypatch, path):
    rng = np.random.default_rng(3)
    M = sp.random(40, 40, density=0.2, random_state=4)
    A = (M @ M.T + sp.eye(40)).tocsr()
    b = rng.standard_normal((40, 4))
    _use(path, monkeypatch)
    x = linalg.factor(A, symmetric=True, approximate=True)(b)
    exact = linalg.factor(A, symmetric=True)(b)
    assert x.dtype == np.float64
    error = np.abs(x - exact).max() / np.abs(exact).max()
    assert 1e-12 < error < 1e-5  # single precision: neither exact nor far off



@pytest.mark.parametrize("path", PATHS)
@pytest.mark.parametrize("matrix_scale, rhs_scale", [(1e-45, 1.0), (1e40, 1.0), (1.0, 1e-300),
                                                     (1e-30, 1e200), (1e35, 1e-40)])
def test_an_approximate_factor_solves_at_scales_single_precision_cannot_hold(
        monkeypatch, path, matrix_scale, rhs_scale):
    # a mesh in other units scales its matrices: 1e-45 and 1e40 lie outside float32's range
    # (and 1e-300 far below it), yet the solve must still be the exact one to single precision
    rng = np.random.default_rng(5)
    M = sp.random(40, 40, density=0.2, random_state=6)
    A = (M @ M.T + sp.eye(40)).tocsr()
    b = rng.standard_normal((40, 4))
    _use(path, monkeypatch)
    x = linalg.factor(A * matrix_scale, symmetric=True, approximate=True)(b * rhs_scale)
    exact = linalg.factor(A, symmetric=True)(b) * (rhs_scale / matrix_scale)
    assert np.isfinite(x).all()
    assert np.abs(x - exact).max() < 1e-5 * np.abs(exact).max()
    assert not linalg.factor(A, symmetric=True, approximate=True)(np.zeros((40, 4))).any()

def _fill(A, order):
    import scipy.sparse.linalg as spla
    P = sp.csc_matrix(sp.csr_matrix(A)[order][:, order])
    lu = spla.splu(P, permc_spec="NATURAL", options={"SymmetricMode": True})
    return lu.L.nnz + lu.U.nnz


def test_the_mesh_order_dissects_every_edge_even_of_zero_weight():
    """A tube of rectangles split in two has right angles: their diagonals' clamped cotangent
    weights are 0 and the Laplacian stores no entry for them, but the rotor matrix couples
    them. The mesh order, restricted to any rows, must fill a matrix on all the edges about
    as well as that matrix's own nested dissection."""
    V, F = tube(length=20.0, rings=80, segments=24)
    graph = Deformer(V, F, ends(V, 20.0), prepare=False).graph
    assert graph.laplacian.nnz < graph.I.size + graph.n  # zero weights were dropped
    every_edge = sp.csr_matrix((np.full(graph.I.size, -1.0), (graph.I, graph.J)),
                               shape=(graph.n,) * 2)
    M = (every_edge + sp.diags(graph.degree + 1.0)).tocsr()
    rows = np.flatnonzero((V[:, 2] > 0.5) & (V[:, 2] < 19.5))
    sub = M[rows][:, rows]
    assert _fill(sub, graph.fill_order(rows)) <= 1.2 * _fill(sub, linalg.fill_order(sub))


def test_the_order_from_another_process_is_the_order_computed_here(monkeypatch):
    """METIS runs in a fresh interpreter for large graphs (it holds the GIL); where that
    fails or answers nonsense, the parent computes the very same order itself."""
    V, F = tube(length=6.0, rings=16, segments=10)
    A = igl.cotmatrix(V, F)
    here = linalg.fill_order(A)  # small: in this process
    assert np.array_equal(np.sort(here), np.arange(len(V)))
    monkeypatch.setattr(linalg, "APART_FROM", 0)
    calls = []
    real = linalg.run_fresh
    monkeypatch.setattr(linalg, "run_fresh", lambda *a: calls.append(real(*a)) or calls[-1])
    assert np.array_equal(linalg.fill_order(A), here)
    assert calls[0] is not None  # the child answered: every vertex is linked, so its order
    assert np.array_equal(np.frombuffer(calls[0], dtype="<i8"), here)  # is the result itself
    for answer in (None, b"", b"\x00" * 8 * len(V)):
        monkeypatch.setattr(linalg, "run_fresh", lambda *a, out=answer: out)
        assert np.array_equal(linalg.fill_order(A), here)


def test_a_fresh_process_reports_failure_and_gives_back_what_it_wrote():
    from srarap_cli.runtime.fresh_process import run_fresh

    assert run_fresh("raise RuntimeError('in the child')", b"") is None
    big = bytes(range(256)) * 40_000  # more than a pipe's buffer, both ways
    assert run_fresh("sys.stdout.buffer.write(payload[::-1])", big) == big[::-1]
