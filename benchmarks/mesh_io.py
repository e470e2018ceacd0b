"""Reading and writing large mesh files: srarap against meshio and trimesh, same run.

Generates a capped quad bar with texture coordinates (``v/vt`` corners, quads and triangle
caps; ``--rings``/``--segments``, default about 500k vertices) and from it three more files:
the same bar as a plain triangle OBJ, as a triangle OBJ with per-vertex normals (``v//vn``),
and as binary PLY and ASCII OFF. Each reader (srarap's ``read_mesh``; ``meshio.read``;
``trimesh.load(..., process=False)``) reads each file ``--repeat`` times, alternating; the table
gives medians and each peer's time over srarap's. Writing: srarap's ``format_mesh`` against
``meshio.write`` to the same format (meshio keeps neither uv nor normal ids in OBJ, so it
writes less). meshio and trimesh are test dependencies, not the default install.

Run: python benchmarks/mesh_io.py [--rings 1560] [--segments 320] [--repeat 3]
"""
import argparse
import os
import statistics
import sys
import tempfile
import time

import numpy as np
from run_bench import OUT

from srarap_cli.io.mesh import Mesh, format_mesh, read_mesh
from srarap_cli.io.mesh.normals import recompute_normals
from srarap_cli.tasks.samples import bar, obj_text


def files(rings, segments):
    """Paths of the generated files, written to out/ once per size."""
    stem = os.path.join(OUT, f"io-bar-{rings}x{segments}")
    paths = {kind: f"{stem}-{kind}" for kind in
             ("uv.obj", "plain.obj", "normals.obj", "plain.ply", "plain.off")}
    if all(os.path.exists(p) for p in paths.values()):
        return paths
    os.makedirs(OUT, exist_ok=True)
    V, faces, uv, tfaces = bar(rings=rings, segments=segments)
    with open(paths["uv.obj"], "w") as fh:
        fh.write(obj_text(V, faces, uv, tfaces))
    tri = Mesh.from_arrays(V, read_mesh(paths["uv.obj"]).triangles()[0])
    for kind in ("plain.obj", "plain.ply", "plain.off"):
        with open(paths[kind], "wb") as fh:
            fh.write(format_mesh(tri, os.path.splitext(kind)[1])[0])
    tri.normals, tri.face_normals = np.zeros_like(V), tri.face_vertices.copy()
    tri.normals = recompute_normals(tri)
    with open(paths["normals.obj"], "wb") as fh:
        fh.write(format_mesh(tri, ".obj")[0])
    return paths


def readers():
    import meshio
    import trimesh
    return {"srarap": read_mesh, "meshio": meshio.read,
            "trimesh": lambda p: trimesh.load(p, process=False)}


def writers(tmp):
    import meshio

    def ours(mesh, suffix):
        with open(os.path.join(tmp, "ours" + suffix), "wb") as fh:
            fh.write(format_mesh(mesh, suffix)[0])

    def theirs(mesh, suffix):
        F = mesh.face_vertices.reshape(-1, 3) if (mesh.face_sizes == 3).all() else None
        cells = [("triangle", F)] if F is not None else [
            ("polygon" if k > 4 else {3: "triangle", 4: "quad"}[k],
             mesh.face_vertices[np.repeat(mesh.face_sizes == k, mesh.face_sizes)].reshape(-1, k))
            for k in np.unique(mesh.face_sizes)]
        meshio.write(os.path.join(tmp, "theirs" + suffix), meshio.Mesh(mesh.vertices, cells))

    return {"srarap": ours, "meshio": theirs}


def median_times(funcs, arg_for, repeat):
    """Median seconds per function; a peer that refuses the file gets its error's name."""
    times = {name: [] for name in funcs}
    for _ in range(repeat):
        for name, func in funcs.items():
            if isinstance(times[name], str):
                continue
            arg = arg_for()
            start = time.perf_counter()
            try:
                func(*arg)
            except Exception as exc:  # noqa: BLE001 - a peer's refusal is a result here
                if name == "srarap":
                    raise
                times[name] = type(exc).__name__
                continue
            times[name].append(time.perf_counter() - start)
    return {name: t if isinstance(t, str) else statistics.median(t)
            for name, t in times.items()}


def row(what, times):
    ours = times["srarap"]
    peers = "  ".join(f"{name} fails ({t})" if isinstance(t, str) else
                      f"{name} {t:6.2f} s ({t / ours:4.1f}x)"
                      for name, t in times.items() if name != "srarap")
    print(f"{what:22s} srarap {ours:6.2f} s  {peers}")
    sys.stdout.flush()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rings", type=int, default=1560)
    ap.add_argument("--segments", type=int, default=320)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    paths = files(args.rings, args.segments)
    print(f"{len(read_mesh(paths['plain.off']).vertices):,} vertices; medians of {args.repeat}")
    for kind, path in paths.items():
        row(f"read {kind}", median_times(readers(), lambda p=path: (p,), args.repeat))
    with tempfile.TemporaryDirectory() as tmp:
        for kind in ("uv.obj", "plain.ply", "plain.off"):
            mesh = read_mesh(paths[kind])
            suffix = os.path.splitext(kind)[1]
            row(f"write {kind}", median_times(writers(tmp), lambda m=mesh, s=suffix: (m, s),
                                              args.repeat))


if __name__ == "__main__":
    main()
