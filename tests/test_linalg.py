"""Both factorization back ends solve the same systems."""
import numpy as np
import scipy.sparse as sp
from helpers import ends, tube

from srarap_cli import Deformer
from srarap_cli.solver import linalg
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix


def test_nested_dissection_back_end_solves_spd_systems(monkeypatch):
    rng = np.random.default_rng(1)
    M = sp.random(30, 30, density=0.2, random_state=2)
    A = (M @ M.T + sp.eye(30) * 0.5).tocsr()
    b = rng.standard_normal((30, 4))
    monkeypatch.setattr(linalg, "LARGE", 0)
    solve = linalg.factor(A, symmetric=True)
    assert np.abs(A @ solve(b) - b).max() < 1e-10
    assert np.abs(A @ solve(b[:, 0]) - b[:, 0]).max() < 1e-10
    assert solve(b[:, 0]).shape == (30,)


def test_large_mesh_back_end_gives_the_same_deformation(monkeypatch):
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
