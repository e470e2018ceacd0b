"""Small meshes made in the tests (no files needed)."""
import os

import numpy as np

from srarap_cli.mesh_io.mesh import Mesh
from srarap_cli.samples import bar

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "meshes")


def tube_mesh(length=6.0, rings=12, segments=8):
    """Capped tube along z (quads + triangle fans, UVs with a seam) as a Mesh."""
    V, faces, uv, tfaces = bar(length=length, rings=rings, segments=segments)
    return Mesh(vertices=V, face_sizes=np.array([len(f) for f in faces]),
                face_vertices=np.concatenate(faces), uv=uv, face_uv=np.concatenate(tfaces))


def tube(length=6.0, rings=12, segments=8):
    """Triangulated capped tube: V (n, 3), F (f, 3)."""
    m = tube_mesh(length, rings, segments)
    return m.vertices, m.triangles()[0]


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
