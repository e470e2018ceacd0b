"""Deform a mesh held by trimesh, pick handles with numpy, save through trimesh.

    pip install trimesh
    srarap samples samples
    python deform_with_trimesh.py samples/sample_meshes/spot.obj spot-nod.ply

Spot keeps her hooves where they are and lowers her head 30 degrees about a neck axis.
"""
import sys

import numpy as np
import trimesh

import srarap_cli

source, target = sys.argv[1], sys.argv[2]
mesh = trimesh.load(source, process=False)
# trimesh splits vertices where corners carry different normals or texture coordinates;
# welded again, the faces share vertices (otherwise srarap warns: the surface is cut open)
mesh.merge_vertices(merge_tex=True, merge_norm=True)
V = np.asarray(mesh.vertices)

hooves = np.flatnonzero(V[:, 1] < -0.62)
head = np.flatnonzero(np.linalg.norm(V - [0.0, 0.55, -0.5], axis=1) < 0.3)
angle = np.radians(-30.0)
turn = np.array([[1, 0, 0],
                 [0, np.cos(angle), -np.sin(angle)],
                 [0, np.sin(angle), np.cos(angle)]])
pivot = np.array([0.0, 0.3, -0.2])
targets = np.vstack([V[hooves], (V[head] - pivot) @ turn.T + pivot])

result = srarap_cli.deform(mesh, (np.concatenate([hooves, head]), targets))
if not result.converged:
    sys.exit(f"not converged after {result.iterations} iterations")
result.to_trimesh().export(target)
print(f"{len(V)} vertices, {len(hooves)} fixed, {len(head)} turned: converged in "
      f"{result.iterations} iterations, energy {result.energy:.4g}; wrote {target}")
