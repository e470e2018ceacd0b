"""Subset simplification: srarap's own half-edge collapses against MeshLab's (peer).

For each mesh and coarse size prints, per simplifier: seconds (median of --repeat runs),
coarse vertices, triangles whose smallest angle is under 5 and 1 degrees, flipped triangles
(normal opposite to the mean of the fine vertex normals at its corners), whether the Euler
characteristic, parts and boundary loops were kept, and the largest and mean distance of the
fine vertices to the coarse surface over the bounding-box diagonal.

The peer is pymeshlab (GPL-3.0, not a dependency of srarap): it runs only when importable,
e.g. after ``pip install pymeshlab`` in a separate environment.

Run: python benchmarks/make_big_spot.py out/spot-738k.obj --levels 3
     python benchmarks/simplify_quality.py sample_meshes/spot.obj:800 \
         out/spot-738k.obj:5000 --repeat 3
"""
import argparse
import importlib.util
import statistics
import time

import igl
import numpy as np

from srarap_cli.io.mesh import read_mesh
from srarap_cli.solver.multires import simplify_to_subset
from srarap_cli.solver.multires.topology import topology_summary


def meshlab_subset(V, F, size):
    """MeshLab's quadric collapse with endpoint placement: (sorted fine ids, faces)."""
    import pymeshlab

    mesh = pymeshlab.Mesh(vertex_matrix=V, face_matrix=F.astype(np.int32),
                          v_scalar_array=np.arange(len(V), dtype=float))
    ms = pymeshlab.MeshSet()
    ms.add_mesh(mesh)
    ms.meshing_decimation_quadric_edge_collapse(
        targetfacenum=max(4, round(size * len(F) / len(np.unique(F)))), optimalplacement=False,
        preservetopology=True, preserveboundary=True, planarquadric=True, autoclean=True)
    out = ms.current_mesh()
    ids = np.rint(out.vertex_scalar_array()).astype(np.int64)
    if not np.array_equal(V[ids], out.vertex_matrix()):
        raise RuntimeError("pymeshlab moved a vertex")
    order = np.argsort(ids)
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    return ids[order], rank[out.face_matrix().astype(np.int64)]


def ours(V, F, size):
    c = simplify_to_subset(V, F, size)
    return c.vertices, c.faces


def quality(V, F, ids, G):
    X = V[ids]
    edge = np.stack([X[G[:, 1]] - X[G[:, 0]], X[G[:, 2]] - X[G[:, 1]],
                     X[G[:, 0]] - X[G[:, 2]]], axis=1)
    length = np.linalg.norm(edge, axis=2)
    cos = [np.einsum("ij,ij->i", -edge[:, k - 1], edge[:, k]) / (length[:, k - 1] * length[:, k])
           for k in range(3)]
    smallest = np.degrees(np.arccos(np.clip(np.max(cos, axis=0), -1, 1)))
    fine_n = igl.per_vertex_normals(V, F)[ids]
    normal = np.cross(X[G[:, 1]] - X[G[:, 0]], X[G[:, 2]] - X[G[:, 0]])
    flipped = int(np.sum(np.einsum("ij,ij->i", normal, fine_n[G].sum(axis=1)) < 0))
    d2 = igl.point_mesh_squared_distance(V, X, G)[0]
    diag = np.linalg.norm(np.ptp(V, axis=0))
    a, b = topology_summary(F, len(V)), topology_summary(G, len(ids))
    kept = all(a[k] == b[k] for k in ("euler", "components", "boundary_loops"))
    return {"vertices": len(ids), "angle<5": int(np.sum(smallest < 5)),
            "angle<1": int(np.sum(smallest < 1)), "flipped": flipped, "topology kept": kept,
            "max dist": float(np.sqrt(d2.max()) / diag),
            "mean dist": float(np.sqrt(d2).mean() / diag)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cases", nargs="+", help="MESH:SIZE")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    tools = {"srarap": ours}
    if importlib.util.find_spec("pymeshlab") is not None:
        tools["pymeshlab"] = meshlab_subset
    else:
        print("pymeshlab not importable: the peer is left out")
    for case in args.cases:
        path, size = case.rsplit(":", 1)
        mesh = read_mesh(path)
        V, F = mesh.vertices, mesh.triangles()[0]
        for name, tool in tools.items():
            seconds = []
            for _ in range(args.repeat):
                start = time.perf_counter()
                ids, G = tool(V, F, int(size))
                seconds.append(time.perf_counter() - start)
            q = quality(V, F, ids, G)
            row = " ".join(f"{k}={v:.3g}" if isinstance(v, float) else f"{k}={v}"
                           for k, v in q.items())
            print(f"{path} -> {size} {name}: {statistics.median(seconds):.2f} s {row}",
                  flush=True)


if __name__ == "__main__":
    main()
