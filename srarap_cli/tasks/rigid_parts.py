"""Connected parts that handles carry off as rigid pieces: a part held only by handles whose
targets are one rigid motion of their rest positions (a teapot's spout held by the moving
group alone; a whole mesh whose fixed group was forgotten) moves as one piece. The solve then
converges in one iteration at zero energy, which reads as an excellent result: say what
happened."""
import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph

from ..io.handles import Constraints
from ..io.handles.transforms import ROUNDING
from ..runtime.warning_codes import note


def rigid_part_warnings(V: np.ndarray, F: np.ndarray, constraints: Constraints) -> list[str]:
    """One warning naming the groups and the parts' sizes when some connected part is held
    only by handles that move it rigidly (not at rest): the whole mesh, when that is every
    part the handles hold.

    Parameters
    ----------
    V : (n, 3) float array; F : (f, 3) int array
    constraints : Constraints, ids (k,) and targets (k, 3), groups by name

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]])
    >>> F = np.array([[0, 1, 2], [3, 4, 5]])
    >>> c = Constraints(ids=np.array([0, 3, 4]), targets=V[[0, 3, 4]] + [0, 0, 1],
    ...                 groups={"lift": np.array([0, 3, 4])})
    >>> rigid_part_warnings(V, F, c)[0][:70]
    'the whole mesh (2 connected parts, 6 vertices) is held only by handles'
    >>> rigid_part_warnings(V[:3], F[:1], Constraints(ids=np.array([0]),
    ...                     targets=V[[0]] + 1, groups={"trunk": np.array([0])}))[0][:80]
    'the whole mesh (1 connected part, 3 vertices) is held only by handles that move '
    """
    n = len(V)
    if not len(F) or not len(constraints.ids):
        return []
    edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    graph = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    n_parts, label = csgraph.connected_components(graph, directed=False)
    rigid = _rigidly_moved(V[constraints.ids], constraints.targets, label[constraints.ids],
                           n_parts, float(np.linalg.norm(np.ptp(V, axis=0))))
    if not rigid.any():
        return []
    sizes = np.bincount(label, minlength=n_parts)[rigid]
    held = np.isin(label, np.flatnonzero(rigid))
    names = [name for name, ids in constraints.groups.items() if held[np.asarray(ids)].any()]
    by = f" by group(s) {', '.join(map(repr, names))}" if names else ""
    if held[constraints.ids].all():  # nothing the handles hold can bend
        parts = f"{n_parts} connected part{'s' if n_parts > 1 else ''}"
        return [note("rigid-part", f"the whole mesh ({parts}, {sizes.sum()} vertices) is held "
                     f"only by handles that move it rigidly{by}: it moves as one piece, at no "
                     "energy, and nothing bends (a fixed group forgotten? hold what should "
                     "stay with one)")]
    return [note("rigid-part", f"{rigid.sum()} connected part(s) ({sizes.sum()} vertices, the "
                 f"largest {sizes.max()}) are held only by handles that move each rigidly{by}: "
                 "each moves as one piece, apart from the rest of the mesh, at no energy (hold "
                 "it with a fixed group too if it should bend)")]


def _rigidly_moved(X, Y, part, n_parts, diagonal):
    """(n_parts,) bool: the part's constrained rest positions ``X`` go to ``Y`` by one rigid
    motion that is not the identity (a batched Kabsch fit per part)."""
    count = np.bincount(part, minlength=n_parts).astype(float)
    has = count > 0
    safe = np.maximum(count, 1)[:, None]
    cx = np.stack([np.bincount(part, X[:, d], n_parts) for d in range(3)], 1) / safe
    cy = np.stack([np.bincount(part, Y[:, d], n_parts) for d in range(3)], 1) / safe
    x, y = X - cx[part], Y - cy[part]
    H = np.zeros((n_parts, 3, 3))
    np.add.at(H, part, x[:, :, None] * y[:, None, :])
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(np.transpose(Vt, (0, 2, 1)) @ np.transpose(U, (0, 2, 1))))
    D = np.ones((n_parts, 3))
    D[:, 2] = np.where(d == 0, 1, d)
    R = np.transpose(Vt, (0, 2, 1)) @ (D[:, :, None] * np.transpose(U, (0, 2, 1)))
    fitted = np.einsum("kij,kj->ki", R[part], x)
    residual = np.zeros(n_parts)
    np.maximum.at(residual, part, np.linalg.norm(fitted - y, axis=1))
    moved = np.zeros(n_parts)
    np.maximum.at(moved, part, np.linalg.norm(Y - X, axis=1))
    extent = np.zeros(n_parts)
    np.maximum.at(extent, part, np.linalg.norm(x, axis=1))
    # a handle file's rotation is rigid up to its decimals' rounding, which moves a vertex by
    # about that much of its distance from the part's centre
    tol = 1e-9 * max(diagonal, 1e-300)
    return has & (residual <= ROUNDING * extent + tol) & (moved > tol)
