"""What srarap relies on rslab for (solver/one_triangle.py), and the fallback to SuperLU."""
import os
import subprocess
import sys
import threading

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import ROOT, ends, tube

from srarap_cli import Deformer
from srarap_cli.solver import linalg, one_triangle
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix


def _grid(k, shift=1e-3):
    e = np.ones(k)
    T = sp.diags([-e[:-1], 2 * e, -e[:-1]], [-1, 0, 1])
    return (sp.kron(T, sp.eye(k)) + sp.kron(sp.eye(k), T) + shift * sp.eye(k * k)).tocsr()


def test_a_positive_definite_matrix_is_factored_in_double_or_single_precision():
    A = _grid(30)
    B = np.random.default_rng(0).standard_normal((900, 4))
    exact = one_triangle.rslab_factor(A, single=False)
    single = one_triangle.rslab_factor(A, single=True)
    assert exact.factor_dtype == "float64" and single.factor_dtype == "float32"
    X = exact.solve_many(B)  # several right-hand sides in one pass
    assert np.abs(A @ X - B).max() < 1e-10 * np.abs(B).max()
    error = np.abs(single.solve_many(B) - X).max() / np.abs(X).max()
    assert 1e-12 < error < 1e-4  # single precision: neither exact nor far off


@pytest.mark.parametrize("matrix", ["singular", "indefinite", "negative definite"])
def test_a_matrix_that_is_not_positive_definite_is_left_to_superlu(matrix):
    keep = sp.diags(np.r_[0.0, np.ones(99)])  # vertex 0 linked to nothing, not even itself
    A = {"singular": keep @ _grid(10) @ keep,
         "indefinite": _grid(10) - 2.0 * sp.eye(100),
         "negative definite": -_grid(10)}[matrix].tocsr()
    assert one_triangle.rslab_factor(A, single=False) is None
    if matrix == "singular":  # SuperLU then reports it as before
        with pytest.raises(linalg.SingularSystemError):
            linalg.factor(A, symmetric=True)
    else:  # ... or solves it
        b = np.ones(100)
        assert np.abs(A @ linalg.factor(A, symmetric=True)(b) - b).max() < 1e-9


def test_unasked_rslab_takes_large_matrices_only(monkeypatch):
    monkeypatch.delenv(one_triangle.ENV, raising=False)
    calls = []
    real = linalg.rslab_factor
    monkeypatch.setattr(linalg, "rslab_factor", lambda A, single: calls.append(A.shape[0]) or
                        real(A, single))
    monkeypatch.setattr(linalg, "ONE_TRIANGLE_FROM", 900)
    for k in (29, 30):  # 841 and 900 rows
        b = np.ones(k * k)
        assert np.abs(_grid(k) @ linalg.factor(_grid(k), symmetric=True)(b) - b).max() < 1e-9
    assert calls == [900]


def test_superlu_is_used_when_the_environment_asks_for_it(monkeypatch):
    A = _grid(10)
    monkeypatch.setenv(one_triangle.ENV, "superlu")
    assert one_triangle.rslab_factor(A, single=False) is None
    b = np.ones(100)
    assert np.abs(A @ linalg.factor(A, symmetric=True)(b) - b).max() < 1e-10


def test_an_unknown_factorization_asked_for_is_one_line_and_invalid_input(tmp_path):
    env = {**os.environ, one_triangle.ENV: "supperlu"}
    done = subprocess.run([sys.executable, "-m", "srarap_cli", "deform",
                           os.path.join(ROOT, "sample_meshes", "bar.obj"),
                           os.path.join(ROOT, "configs", "bar-twist.yaml"), "-o", "o.obj"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120, env=env)
    assert done.returncode == 4, done.stderr
    assert done.stderr == ("srarap: error: SRARAP_FACTOR='supperlu': expected rslab, superlu "
                           "or auto\n")
    assert not (tmp_path / "o.obj").exists()


def test_a_factorization_that_would_not_fit_is_left_to_superlu(monkeypatch):
    """SuperLU allocates what it uses and reports a failure; rslab's allocation failures end
    the process, so a plan beyond the memory there is is not rslab's."""
    monkeypatch.setenv("SRARAP_MEMORY_LIMIT", "1000")
    assert one_triangle.rslab_factor(_grid(30), single=False) is None


def test_the_factorization_lets_other_python_threads_run():
    """The setup factors in a background thread beside the simplification: a factorization
    holding the interpreter lock would stall it (METIS did). Counted work, not time: with
    the lock held for the whole factorization, the main thread could not count at all."""
    A = _grid(300)
    counted, done = [0], threading.Event()

    def factor():
        one_triangle.rslab_factor(A, single=False)
        done.set()

    worker = threading.Thread(target=factor)
    worker.start()
    while not done.is_set():
        counted[0] += 1
    worker.join()
    assert counted[0] > 1000


def test_a_process_forked_after_rslab_was_used_falls_back_instead_of_hanging():
    """rslab's thread pool does not survive a fork: a child's factorization waited forever."""
    done = _run("import os\n"
                "assert one_triangle.rslab_factor(_grid(100), single=False) is not None\n"
                "pid = os.fork()\n"
                "if pid == 0:\n"
                "    got = one_triangle.rslab_factor(_grid(100), single=False)\n"
                  "    x = linalg.factor(_grid(100), symmetric=True)(np.ones(10000))\n"
                "    os._exit(0 if got is None and np.isfinite(x).all() else 3)\n"
                "print(os.waitpid(pid, 0)[1])\n")
    assert done.stdout.strip() == "0", done.stderr


@pytest.mark.parametrize("room, used", [(60_000_000, "no"), (3_000_000_000, "no")])
def test_under_an_address_space_limit_superlu_takes_every_matrix(room, used):
    """A Rust allocation that fails aborts the process (seen: SIGABRT in the analysis with 60
    MB to spare), rslab's threads may not get their stacks (a panic, printing a Rust
    backtrace), and its allocator's reservations made fitting not monotonic in the limit
    (issue 71, MEM-3): under a limit, with little room or much, SuperLU takes the matrix,
    and solves it or reports a failed allocation as MemoryError (exit 4 in the command)."""
    # OpenBLAS takes its buffer on first use and, under a limit, retries forever: linalg
    # warms it at import when the limit is set before the process starts; here it comes after
    done = _run("import resource\nfrom scipy.linalg import blas\n"
                "one = np.ones((1, 1), order='F')\n"
                "blas.dtrsv(one, np.ones(1)); blas.dgemm(1.0, one, one)\n"
                "A = _grid(200); b = np.ones(40000)\n"
                "mapped = int(open('/proc/self/status').read().split('VmSize:')[1].split()[0])\n"
                f"resource.setrlimit(resource.RLIMIT_AS, (mapped * 1024 + {room},) * 2)\n"
                "f = one_triangle.rslab_factor(A, single=False)\n"
                "print('yes' if f is not None else 'no')\n"
                "try:\n"
                "    x = linalg.factor(A, symmetric=True)(b)\n"
                "    print(float(np.abs(A @ x - b).max()) < 1e-8)\n"
                "except MemoryError:\n"
                "    print('MemoryError')\n")
    assert done.returncode == 0 and done.stderr == "", done.stderr[-800:]
    lines = done.stdout.split()
    assert lines[0] == used and lines[1] in ("True", "MemoryError")


def test_a_first_factorization_in_another_thread_leaves_the_main_thread_working():
    """Loaded by another thread, rslab's allocator crashed the process, at once or in the main
    thread's next solve after that thread ended (seen under pytest-xdist): the solver's import
    loads it in the main thread."""
    done = _run("import threading\n"
                "got = []\n"
                "t = threading.Thread(target=lambda: got.append(\n"
                "    one_triangle.rslab_factor(_grid(50), single=False)))\n"
                "t.start(); t.join()\n"
                "f = one_triangle.rslab_factor(_grid(60), single=False)\n"
                "x = f.solve_many(np.ones((3600, 3)))\n"
                "print(got[0] is not None, np.isfinite(x).all())\n")
    assert done.returncode == 0 and done.stdout.split() == ["True", "True"], done.stderr[-800:]


def _run(script, env=None):
    """``script`` in a fresh interpreter, with numpy, ``_grid``, linalg and one_triangle."""
    head = ("import sys, numpy as np; sys.path.insert(0, 'tests')\n"
            "from test_one_triangle import _grid\n"
            "from srarap_cli.solver import linalg, one_triangle\n")
    return subprocess.run([sys.executable, "-c", head + script], cwd=ROOT, capture_output=True,
                          text=True, timeout=120, env={**os.environ, **(env or {})})


def _twisted_tube():
    V, F = tube(length=6.0, rings=12, segments=8)
    ids = ends(V, 6.0)
    T = V[ids].copy()
    top = T[:, 2] > 3
    T[top] = T[top] @ to_matrix(from_axis_angle([0, 0, 1], 90)).T
    return V, F, ids, T


def test_both_factorizations_give_the_same_deformation(monkeypatch):
    V, F, ids, T = _twisted_tube()
    monkeypatch.setenv(one_triangle.ENV, "rslab")  # at every size, this small tube's too
    ours = Deformer(V, F, ids).solve(T, tol=1e-11, max_iter=300)
    monkeypatch.setenv(one_triangle.ENV, "superlu")
    theirs = Deformer(V, F, ids).solve(T, tol=1e-11, max_iter=300)
    assert ours.converged and theirs.converged
    diagonal = np.linalg.norm(np.ptp(V, axis=0))
    assert np.abs(ours.positions - theirs.positions).max() < 1e-6 * diagonal


@pytest.mark.slow
def test_rslab_solves_are_deterministic_across_processes():
    script = (
        "import sys, hashlib; sys.path.insert(0, 'tests')\n"
        "from test_one_triangle import _twisted_tube\n"
        "from srarap_cli import Deformer\n"
        "V, F, ids, T = _twisted_tube()\n"
        "r = Deformer(V, F, ids).solve(T, max_iter=20)\n"
        "print(hashlib.sha256(r.positions.tobytes()).hexdigest())\n")
    env = {**os.environ, one_triangle.ENV: "rslab"}
    digests = {subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True,
                              text=True, check=True, env=env).stdout for _ in range(2)}
    assert len(digests) == 1 and len(next(iter(digests)).strip()) == 64


def test_a_multiresolution_deform_whose_first_factorization_runs_in_the_background(tmp_path):
    """The full-resolution setup (the process's first factorization) runs in a thread beside
    the simplification: rslab's allocator, set up there first, crashed the process (SIGSEGV,
    every run from 20,000 vertices, where coarse-to-fine begins) until the solver's import
    set it up in the main thread."""
    from helpers import tube_mesh

    from srarap_cli.io.mesh import write_mesh

    write_mesh(str(tmp_path / "m.obj"), tube_mesh(length=10.0, rings=200, segments=128))
    (tmp_path / "h.yaml").write_text(
        "groups:\n  base: {box: {min: [-2, -2, -0.01], max: [2, 2, 0.01]}, fixed: true}\n"
        "  tip: {box: {min: [-2, -2, 9.99], max: [2, 2, 10.01]}, rotate: "
        "{axis: [0, 1, 0], angle_deg: 40}}\n")
    env = {**os.environ, one_triangle.ENV: "rslab"}  # at every size, these 25,600 vertices too
    done = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", "m.obj", "h.yaml",
                           "-o", "o.obj", "--max-iter", "3", "--keep-unconverged"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode in (0, 3), done.stderr[-800:]
    assert "coarse" in done.stderr and (tmp_path / "o.obj").exists()
