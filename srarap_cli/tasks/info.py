"""What a mesh is, and what a handle file does to it, before any solve (``srarap info``)."""
import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph

from ..io.handles import Constraints
from ..io.handles.transforms import ROUNDING, vector_text
from ..io.mesh import Mesh
from ..runtime.parallel import map_blocks
from ..solver.group_rotations import group_rotors
from ..solver.mesh_checks import distinct_ids, edge_counts, mesh_warnings
from ..solver.quaternion import to_matrix
from ..solver.settings import resolve
from .pipeline import model_warnings, problem, request_warnings

AXES = "xyz"


def up_axis(mesh: Mesh) -> str:
    """The axis ``render`` draws upward by default: ``y`` or ``z``, :func:`mesh_info`'s
    guess (``up_guess`` without its sign)."""
    return _up_guess(mesh.vertices, mesh.triangles()[0])[1:]


def mesh_info(mesh: Mesh) -> dict:
    """Counts, extent and problems of ``mesh``.

    Returns
    -------
    dict with ``vertices``, ``faces`` (polygons), ``triangles``, ``components`` (connected
    parts of the faces), ``boundary_loops``, ``bbox_min`` / ``bbox_max`` / ``extent`` (per
    axis), ``diagonal``, ``up_guess``, ``euler`` (V - E + F of the triangles' vertices),
    ``genus`` (of a surface with ``components`` parts and ``boundary_loops`` holes: the
    number of handles, e.g. a torus's 1; None where that is not a whole number, a mesh that
    is not a manifold) and ``problems`` (list of str, every mesh warning deform gives)
    """
    V = mesh.vertices
    F = mesh.triangles()[0]
    lo, hi = V.min(axis=0), V.max(axis=0)
    edges, counts = edge_counts(F)  # once: parts, loops, Euler and the mesh's warnings
    components, loops = _components(edges, F, len(V)), _boundary_loops(edges[counts == 1])
    used = distinct_ids(F, len(V)).size
    euler = used - len(edges) + len(F)
    twice_genus = 2 * components - loops - euler
    problems = mesh_warnings(V, F, edges=(edges, counts))
    if used < len(V):  # deform keeps them at rest and says so: say it before
        problems.append(f"{len(V) - used} unreferenced vertices (in no face): a solve keeps "
                        "them at rest")
    return {"vertices": len(V), "faces": int(mesh.face_sizes.size), "triangles": len(F),
            "components": components, "boundary_loops": loops,
            "bbox_min": lo.tolist(), "bbox_max": hi.tolist(), "extent": (hi - lo).tolist(),
            "diagonal": float(np.linalg.norm(hi - lo)), "up_guess": _up_guess(V, F),
            "euler": int(euler),
            "genus": twice_genus // 2 if twice_genus >= 0 and twice_genus % 2 == 0 else None,
            "problems": problems}


def describe(mesh: Mesh, constraints: Constraints | None = None, name: str = "mesh"
             ) -> tuple[dict, dict | None]:
    """:func:`mesh_info` and, given ``constraints``, :func:`handles_info` (else None), the two
    side by side on the threads there are (their sparse and sorting passes release the GIL):
    on a 1.2M-vertex bar with 2 CPUs, 7.2 s in turn, about 4.5 s side by side, so that
    ``info`` costs what ``deform``'s read and checks do though it also counts the parts,
    loops and genus and runs the setup's weight checks."""
    parts = [lambda: mesh_info(mesh)]
    if constraints is not None:
        parts.append(lambda: handles_info(mesh, constraints, name))
    facts = map_blocks(lambda part: part(), parts)
    return facts[0], facts[1] if constraints is not None else None


def handles_info(mesh: Mesh, constraints: Constraints, name: str = "mesh") -> dict:
    """Per group of ``constraints``: vertices selected, the action in words, overlaps; the
    region's size and how many vertices are free; ``warnings``, what deform would warn about
    the file and the request (an angle's unit, a motion beyond the mesh's size, parts carried
    off rigidly or held by nothing, edge weights), from the functions deform calls. Runs the
    checks a solve would (a dry run); the mesh's own problems are :func:`mesh_info`'s.
    """
    p = problem(mesh, constraints, name)  # the same validation as deform
    said = (list(constraints.warnings) + request_warnings(mesh, p, constraints)
            + model_warnings(p, resolve(constraints.solver)))
    slots = {g: np.searchsorted(constraints.ids, ids) for g, ids in constraints.groups.items()}
    groups = []
    for g, ids in constraints.groups.items():
        track = next((t for s, _, t in constraints.tracks
                      if np.array_equal(constraints.ids[s], ids)), None)
        action = ("keyframed, keys given by time (the pose at frame 0 is checked; --fps "
                  "places the others)" if track is not None and track.first_only else
                  f"keyframed ({len(track.frames)} keys, last at frame {track.frames[-1]:g})"
                  if track is not None else constraints.actions.get(g) or
                  describe_motion(mesh.vertices[ids], constraints.targets[slots[g]]))
        groups.append({"name": g, "vertices": int(len(ids)), "action": action})
    n = len(mesh.vertices)
    region = None if constraints.region is None else int(np.unique(constraints.region).size)
    return {"groups": groups, "overlaps": _overlaps(constraints.groups, n),
            "constrained": int(constraints.ids.size), "region": region,
            "free": int(len(p.V) - p.ids.size), "of": n,
            "warnings": list(dict.fromkeys(said))}


def describe_motion(rest: np.ndarray, targets: np.ndarray) -> str:
    """The rigid motion that best takes ``rest`` (k, 3) to ``targets``, in words.

    Examples
    --------
    >>> rest = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> describe_motion(rest, rest + [3, 0, -1.5])
    'translate (3, 0, -1.5)'
    >>> turned = rest @ np.array([[0., 0, 1], [0, 1, 0], [-1, 0, 0]]).T
    >>> describe_motion(rest, turned)
    'rotate 90 degrees about +y through (0.333333, 0.333333, 0), then translate (-0.333333, 0, -0.333333)'
    """
    if not len(rest):
        return "selects no vertex"
    if np.allclose(rest, targets, rtol=0, atol=1e-12 * max(np.abs(rest).max(), 1.0)):
        return "fixed"
    labels = np.zeros(len(rest), np.int64)
    q, determined = group_rotors(rest, targets, labels, 1)
    if not determined.all():  # collinear or single vertices: no rotation can be told
        moved = float(np.linalg.norm(targets - rest, axis=1).max())
        shift = targets.mean(axis=0) - rest.mean(axis=0)
        if np.abs(rest + shift - targets).max() <= 1e-9 * max(np.ptp(rest, axis=0).max(),
                                                              1e-300):
            return f"translate {vector_text(shift)}"
        return (f"moves its vertices by up to {moved:.6g} (they lie on a line: the rotation "
                "is not determined by them)")
    q = q[0]
    q = q if q[0] >= 0 else -q
    angle = float(np.degrees(2 * np.arctan2(np.linalg.norm(q[1:]), q[0])))
    scale = max(np.abs(rest).max(), 1.0)
    c, d = rest.mean(axis=0), targets.mean(axis=0) - rest.mean(axis=0)
    words = []
    if angle > 1e-9:
        axis = q[1:] / np.linalg.norm(q[1:])
        words.append(f"rotate {angle:.6g} degrees about {_direction(axis)} through {vector_text(c, scale)}")
    if np.linalg.norm(d) > 1e-12 * scale:
        words.append(f"translate {vector_text(d)}")
    text = ", then ".join(words) or "fixed"
    if determined.all():
        R = to_matrix(q)
        residual = np.abs((rest - c) @ R.T + c + d - targets).max()
        # a motion written with rounded decimals is rigid to that rounding of its reach
        reach = float(np.linalg.norm(rest - c, axis=1).max())
        if residual > ROUNDING * reach + 1e-9 * max(np.ptp(rest, axis=0).max(), 1e-300):
            text += f" (not rigid: up to {residual:.3g} off that motion)"
    return text


def _overlaps(groups, n):
    """``{"groups": [a, b], "vertices": k}`` for each pair of groups sharing k > 0 vertices,
    in the order of the file: a sparse product, so its cost follows the shared vertices, not
    the square of the group count (2,000 one-vertex groups took 39 s pair by pair)."""
    names = list(groups)
    sizes = [len(ids) for ids in groups.values()]
    rows = np.repeat(np.arange(len(names)), sizes)
    cols = np.concatenate([np.asarray(ids, np.int64) for ids in groups.values()]
                          or [np.zeros(0, np.int64)])
    member = sp.csr_matrix((np.ones(rows.size), (rows, cols.astype(np.int64))),
                           shape=(len(names), n))
    member.data[:] = 1.0  # a vertex a group lists twice counts once
    shared = sp.triu(member @ member.T, k=1).tocoo()
    order = np.lexsort((shared.col, shared.row))
    return [{"groups": [names[i], names[j]], "vertices": int(k)}
            for i, j, k in zip(shared.row[order], shared.col[order], shared.data[order]) if k]


def _direction(axis):
    k = int(np.argmax(np.abs(axis)))
    if np.abs(axis[k]) > 1 - 1e-9:
        return ("+" if axis[k] > 0 else "-") + AXES[k]
    return vector_text(axis)


def _components(edges, F, n):
    A = sp.csr_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    used = np.zeros(n, bool)
    used[F.ravel()] = True
    labels = csgraph.connected_components(A, directed=False)[1]
    return int(np.unique(labels[used]).size)


def _boundary_loops(boundary):
    if not len(boundary):
        return 0
    ids, inverse = np.unique(boundary, return_inverse=True)
    inverse = inverse.reshape(-1, 2)
    A = sp.csr_matrix((np.ones(len(inverse)), (inverse[:, 0], inverse[:, 1])),
                      shape=(len(ids),) * 2)
    return int(csgraph.connected_components(A, directed=False)[0])


def _up_guess(V, F):
    """y or z, whichever the mesh stands on, when its extents tell: an object at least twice
    as long along one of them as across (a bar, a column, a standing figure) stands on its
    length. Extents are taken between the 1st and 99th percentile of the used vertices, so a
    few stray vertices do not decide. Otherwise +y, as most OBJ and PLY files are y-up
    (:func:`up_decided` says which case it was)."""
    axis, _ = _up(V, F)
    return axis


def up_decided(mesh: Mesh) -> bool:
    """Whether :func:`up_axis` was told by the mesh's extents (False: +y was assumed)."""
    return _up(mesh.vertices, mesh.triangles()[0])[1]


def _up(V, F):
    if not len(V) or not len(F):
        return "+y", False
    used = np.zeros(len(V), bool)
    used[F.ravel()] = True
    lo, hi = np.percentile(V[used], [1, 99], axis=0)
    extent = hi - lo
    for k in (1, 2):
        if extent[k] >= 2 * max(extent[j] for j in range(3) if j != k):
            return "+" + AXES[k], True
    return "+y", False
