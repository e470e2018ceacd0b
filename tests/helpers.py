"""Small meshes made in the tests (no files needed)."""
import os
import subprocess

import numpy as np
import pytest

from srarap_cli.io.mesh.mesh import Mesh
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix
from srarap_cli.tasks.samples import bar

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "meshes")
#: Tests of the team's larger meshes in ../shared skip without it, unless this variable is
#: set (``.ci/run`` sets it): then they run and fail, so CI can never skip them silently.
REQUIRE_SHARED = os.environ.get("SRARAP_REQUIRE_SHARED") == "1"
needs_shared = pytest.mark.skipif(
    not os.path.isdir(SHARED) and not REQUIRE_SHARED,
    reason="../shared/meshes (the team's mesh collection) is not beside the repository")


def rounded_turn(axis, degrees, decimals):
    """The (4, 4) matrix of a turn about ``axis`` through the origin, its entries rounded to
    ``decimals`` as a handle file writes them."""
    M = np.eye(4)
    M[:3, :3] = to_matrix(from_axis_angle(axis, degrees))
    return np.round(M, decimals)


def torus(rings=24, segments=12, R=2.0, r=0.7):
    """Closed genus-1 torus around z: V (n, 3), F (f, 3), outward triangles."""
    u, v = np.meshgrid(np.arange(rings), np.arange(segments), indexing="ij")
    a, b = 2 * np.pi * u.ravel() / rings, 2 * np.pi * v.ravel() / segments
    V = np.column_stack([(R + r * np.cos(b)) * np.cos(a), (R + r * np.cos(b)) * np.sin(a),
                         r * np.sin(b)])
    i, j = u.ravel(), v.ravel()
    p00 = i * segments + j
    p10 = (i + 1) % rings * segments + j
    p01 = i * segments + (j + 1) % segments
    p11 = (i + 1) % rings * segments + (j + 1) % segments
    return V, np.vstack([np.column_stack([p00, p10, p11]), np.column_stack([p00, p11, p01])])


def tube_mesh(length=6.0, rings=12, segments=8):
    """Capped tube along z (quads + triangle fans, UVs with a seam) as a Mesh."""
    V, faces, uv, tfaces = bar(length=length, rings=rings, segments=segments)
    return Mesh(vertices=V, face_sizes=np.array([len(f) for f in faces]),
                face_vertices=np.concatenate(faces), uv=uv, face_uv=np.concatenate(tfaces))


def tube(length=6.0, rings=12, segments=8):
    """Triangulated capped tube: V (n, 3), F (f, 3)."""
    m = tube_mesh(length, rings, segments)
    return m.vertices, m.triangles()[0]


def tube_handles(top, length=6.0, more=""):
    """A handle file (YAML text) for a tube along z of ``length``: its base ring held, its top
    ring doing ``top`` (a YAML flow action, ``rotate: {...}``), then the groups ``more``."""
    return ("groups:\n  base: {box: {min: [-2, -2, -0.01], max: [2, 2, 0.01]}, fixed: true}\n"
            f"  top: {{box: {{min: [-2, -2, {length - 0.01}], max: [2, 2, {length + 0.01}]}},"
            f" {top}}}\n" + more)


def ends(V, length=6.0):
    """Ids of the two end rings (and cap centres) of a tube."""
    return np.flatnonzero((V[:, 2] < 1e-9) | (V[:, 2] > length - 1e-9))


def random_rotation(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def symmetric_tube(length=6.0, rings=12, segments=8):
    """Tube whose triangles keep every symmetry of its quads: each quad splits into four
    triangles around its centre (a fan would orient all diagonals one way)."""
    m = tube_mesh(length, rings, segments)
    offsets = m.face_offsets
    V, F = [m.vertices], []
    nxt = len(m.vertices)
    for k, size in enumerate(m.face_sizes):
        f = m.face_vertices[offsets[k]:offsets[k + 1]]
        if size == 3:
            F.append(f)
            continue
        V.append(m.vertices[f].mean(axis=0, keepdims=True))
        F.extend([f[i], f[(i + 1) % 4], nxt] for i in range(4))
        nxt += 1
    return np.vstack(V), np.array(F)


def stderr_on_a_terminal(cmd, timeout=600):
    """What ``cmd`` writes to stderr when stderr is a terminal (a pseudo-terminal), decoded."""
    import pty
    import select
    master, slave = pty.openpty()
    subprocess.run(cmd, stderr=slave, stdout=subprocess.DEVNULL, check=True, timeout=timeout)
    os.close(slave)
    seen = b""
    while select.select([master], [], [], 0.5)[0]:
        try:
            chunk = os.read(master, 4096)
        except OSError:  # the other end is closed once everything is read
            break
        if not chunk:
            break
        seen += chunk
    os.close(master)
    return seen.decode(errors="replace")


def twist(V, ids, length, degrees):
    """Top end turned about the tube's axis, bottom end fixed."""
    T = V[ids].copy()
    top = T[:, 2] > length / 2
    T[top] = T[top] @ to_matrix(from_axis_angle([0, 0, 1], degrees)).T
    return T


def bent_tube(tol=1e-10):
    """A 54-vertex tube with one end held and the other moved sideways and down, solved to
    ``tol``: (Deformer, targets, result)."""
    from srarap_cli import Deformer

    V, F = tube(rings=8, segments=6)
    ids = ends(V)
    d = Deformer(V, F, ids)
    T = V[ids].copy()
    T[T[:, 2] > 1] += [1.0, 0.0, -0.5]
    return d, T, d.solve(T, tol=tol, max_iter=500)


def diagonal(V):
    return float(np.linalg.norm(np.ptp(V, axis=0)))


class Ran:
    """What a command run in-process gave: as subprocess.run's result reads it."""

    def __init__(self, result):
        self.returncode = result.exit_code
        self.stdout, self.stderr = result.stdout, result.stderr
        self.stdout_bytes = result.stdout_bytes


def run_cli(args, cwd=None, input=None):
    """``srarap ARGS`` in this process (Click's runner), in the folder ``cwd``: for tests of
    what a command says and writes, where a separate process is not what the test is about
    (about 0.5 s saved a run: numpy, scipy and libigl are imported once)."""
    from click.testing import CliRunner

    from srarap_cli.cli import main

    old = os.getcwd()
    if cwd is not None:
        os.chdir(cwd)
    try:
        return Ran(CliRunner().invoke(main, [str(a) for a in args], input=input))
    finally:
        os.chdir(old)


def children(parent=None):
    """Process ids whose parent is ``parent`` (this process by default; Linux), zombies
    included."""
    parent = os.getpid() if parent is None else parent
    found = set()
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/stat") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == parent:
            found.add(int(pid))
    return found
