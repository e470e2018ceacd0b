"""Actions: where a handle group's vertices go."""
import os

import numpy as np

from ...runtime.limits import MAX_COORDINATE
from ...solver.quaternion import from_axis_angle, to_matrix
from .fields import Context
from .formats import read_def

ACTION_KEYS = ("fixed", "translate", "rotate", "pivot", "matrix")
#: the actions that say where a group goes once (``pivot`` only says about what a rotation
#: turns, keyframed or not): keyframes take none of them beside (the parser and the schema)
STATIC_ACTIONS = tuple(k for k in ACTION_KEYS if k != "pivot")


#: rotation angle keys and the factor to degrees: ``angle`` is degrees (kept for files
#: written before the explicit keys)
ANGLE_KEYS = {"angle_deg": 1.0, "angle_rad": 180.0 / np.pi, "angle": 1.0}
#: quaternion keys and the order of their components; ``quaternion`` is w, x, y, z (scipy's
#: ``Rotation.from_quat`` takes x, y, z, w: say ``quaternion_xyzw`` for that order)
QUATERNION_KEYS = {"quaternion_wxyz": [0, 1, 2, 3], "quaternion_xyzw": [3, 0, 1, 2],
                   "quaternion": [0, 1, 2, 3]}


def rotation_matrix(ctx: Context, spec: dict) -> np.ndarray:
    """3x3 matrix of a ``rotate`` entry: ``axis`` with ``angle_deg``, ``angle_rad`` or
    ``angle`` (degrees), or one of ``quaternion_wxyz``, ``quaternion_xyzw``, ``quaternion``
    (w, x, y, z)."""
    spec = ctx.mapping(spec, "rotate", ("axis", *ANGLE_KEYS, *QUATERNION_KEYS))
    angles = [k for k in ANGLE_KEYS if k in spec]
    quats = [k for k in QUATERNION_KEYS if k in spec]
    if len(quats) + (len(angles) > 0 or "axis" in spec) != 1 or len(quats) > 1:
        raise ctx.error("rotate takes 'axis' with one angle (angle_deg, angle_rad, or angle in "
                        "degrees), or one quaternion (quaternion_wxyz, quaternion_xyzw, or "
                        "quaternion as w, x, y, z)")
    if quats:
        key = quats[0]
        order = "x, y, z, w" if key == "quaternion_xyzw" else "w, x, y, z"
        raw = ctx.vector(spec[key], f"{key} [{order}]", 4)[QUATERNION_KEYS[key]]
        q = _scaled(raw)
        norm = float(np.linalg.norm(q))
        if norm < 1e-12:
            raise ctx.error(f"{key} must not be zero")
        length = norm * float(np.abs(raw).max())  # of the components as written
        if abs(length - 1) > 1e-3:  # beyond its decimals' rounding: a typo, or not a rotation
            ctx.warn("non-unit-quaternion", f"{key} has length {length:.4g}, not 1: it was "
                     "normalized (a component mistyped, or a vector given as a quaternion?)")
        return to_matrix(q / norm)
    if len(angles) > 1:
        raise ctx.error(f"rotate takes one angle, got {' and '.join(angles)}: keep angle_deg "
                        "(degrees) or angle_rad (radians)")
    if "axis" not in spec or len(angles) != 1:
        raise ctx.error("rotate needs 'axis' and one of angle_deg, angle_rad or angle (degrees)")
    axis = _scaled(ctx.vector(spec["axis"], "axis", 3))
    if np.linalg.norm(axis) < 1e-12:
        raise ctx.error("axis must not be zero")
    key = angles[0]
    value = ctx.number(spec[key], key)
    _check_angle(ctx, key, value)
    return to_matrix(from_axis_angle(axis, value * ANGLE_KEYS[key]))


def _check_angle(ctx, key, value):
    """Warn where the unit looks mistaken: radians beyond a full turn (degrees meant), or
    ``angle``, whose unit the reader has to know."""
    if key == "angle_rad" and abs(value) > 2 * np.pi:
        ctx.warn("angle-unit", f"angle_rad {value:g} is {np.degrees(value):g} degrees, more than a full "
                 "turn: if degrees were meant, write angle_deg")
    elif key == "angle":
        hint = (" (a value this small looks like radians: write angle_rad if so)"
                if 0 < abs(value) <= 2 * np.pi else "")
        ctx.warn("angle-unit", f"angle {value:g} is read as degrees{hint}; write angle_deg or angle_rad "
                 "to say which")


# A rotation written with six decimals (a Botsch-Sorkine .def file, printf's %f and %g) is
# a rotation to about 1e-6 in A^T A, with four decimals to about 1e-4: a file's rounding is
# not a stretch, and the targets it gives differ from the exact rotation's by that rounding.
ROUNDING = 1e-4


def not_rigid(A: np.ndarray) -> str:
    """What keeps the 3x3 matrix ``A`` from being a rotation (``"is a mirror ..."``), or ""
    for a rotation up to the rounding of a matrix written with four or more decimals.

    Examples
    --------
    >>> not_rigid(np.diag([1.0, 1.0, -1.0]))
    'is a mirror (determinant -1)'
    >>> not_rigid(np.round([[0.5, 0, -np.sqrt(0.75)], [0, 1, 0], [np.sqrt(0.75), 0, 0.5]], 6))
    ''
    >>> not_rigid(np.diag([1.0, 1.001, 1.0]))
    'scales unevenly (by 1, 1.001, 1 along x, y, z)'
    """
    det = float(np.linalg.det(A))
    if det < 0:
        return f"is a mirror (determinant {det:.3g})"
    gram = A.T @ A
    scale = max(float(np.abs(gram).max()), 1e-300)
    if np.abs(gram - np.diag(np.diag(gram))).max() > ROUNDING * scale:
        return "shears (its columns are not at right angles)"
    lengths = np.sqrt(np.diag(gram))
    if np.ptp(lengths) > ROUNDING * lengths.max():
        return f"scales unevenly (by {', '.join(f'{x:.6g}' for x in lengths)} along x, y, z)"
    if abs(lengths[0] - 1) > ROUNDING:
        return f"scales by {lengths[0]:.6g}"
    return ""


def _check_turn(ctx, spec):
    """Warn where a static rotation's angle says more than its targets can: a solve sees
    only where the vertices end, so whole turns are the rest pose and 270 degrees is -90."""
    if not isinstance(spec, dict):
        return
    for key, factor in (("angle_deg", 1.0), ("angle_rad", ANGLE_KEYS["angle_rad"])):
        value = spec.get(key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not np.isfinite(value) or (key == "angle_rad" and
                                              abs(value) > 2 * np.pi + 1e-9):
            continue  # beyond a turn in radians: the unit is suspect, and said so
        degrees = value * factor
        turns, rest = divmod(abs(degrees), 360.0)
        rest = min(rest, 360.0 - rest)
        if turns >= 1 and rest < 1e-9:
            ctx.warn("whole-turns", f"{key} {value:g} is {int(turns)} whole turn(s): the "
                     "targets are the rest pose and nothing turns (a static solve sees only "
                     "where vertices end; keyframes turn it step by step)")
        elif abs(degrees) > 180:
            same = (degrees + 180.0) % 360.0 - 180.0
            ctx.warn("short-way", f"{key} {value:g} reaches the same targets as {same:.6g} degrees: a static "
                     "solve sees only where vertices end and turns the short way (keyframes "
                     "turn it step by step)")


def _scaled(v):
    """``v`` divided by its largest component: only its direction counts, and the norm of a
    vector with components above about 1e154 overflows (it made such a quaternion the
    identity), below about 1e-154 underflows. A zero vector is left as it is, for the
    caller to refuse."""
    top = float(np.abs(v).max())
    return v / top if top > 0 else v


def _matrix(ctx, value, base):
    if isinstance(value, str):
        return read_def(os.path.join(base, value))
    M = ctx.matrix4(value, "matrix")
    if not np.allclose(M[3], [0, 0, 0, 1]):
        raise ctx.error("matrix: last row must be [0, 0, 0, 1]")
    return M


def targets(ctx: Context, spec: dict, rest: np.ndarray, base: str) -> np.ndarray:
    """Target positions (k, 3) of a group whose rest positions are ``rest`` (k, 3).

    ``fixed: true`` keeps rest positions; otherwise ``x' = Rot (x - pivot) + pivot +
    translate`` (pivot defaults to the group's centroid), or ``x' = matrix @ [x, 1]`` with a
    4x4 matrix given inline or as the path of a ``.def`` file.
    """
    out = _moved(ctx, spec, rest, base)
    where = f" ({spec['matrix']})" if isinstance(spec.get("matrix"), str) else ""
    check_bounds(ctx, out, f"the action{where}")
    return out


def check_bounds(ctx: Context, moved: np.ndarray, what: str) -> None:
    """Refuse targets ``moved`` (k, 3) that are not finite or lie beyond MAX_COORDINATE
    (squares of such coordinates overflow in the solve)."""
    if not np.isfinite(moved).all() or np.abs(moved).max(initial=0) > MAX_COORDINATE:
        raise ctx.error(f"{what} sends vertices beyond {MAX_COORDINATE:g} or to "
                        "infinite/NaN positions (entries too large)")


def check_reach(ctx: Context, rest: np.ndarray, moved: np.ndarray, diagonal: float,
                what: str = "its targets") -> None:
    """Warn when a group's targets ``moved`` (k, 3) lie farther from its rest positions
    ``rest`` than the mesh's bounding-box ``diagonal``: a translation in other units, or a
    target meant for another mesh, deforms "successfully" into a stretched shape."""
    if not len(rest) or not diagonal > 0:
        return
    reach = float(np.sqrt(np.max(np.einsum("ij,ij->i", moved - rest, moved - rest))))
    if reach > diagonal:
        ctx.warn("units", f"{what} move vertices by up to {reach:.4g}, {reach / diagonal:.3g} times "
                 f"the mesh's bounding-box diagonal ({diagonal:.4g}): check the units")


def _moved(ctx, spec, rest, base):
    keys = [k for k in ACTION_KEYS if k in spec]
    fixed = spec.get("fixed", False)
    if not isinstance(fixed, bool):
        raise ctx.error("fixed must be true or false")
    moving = [k for k in keys if k != "fixed"]
    if fixed and moving:
        raise ctx.error(f"fixed: true cannot be combined with {moving[0]}")
    if fixed:
        return rest.copy()
    if not moving:
        raise ctx.error("no action (use fixed: true, translate, rotate or matrix)")
    if "matrix" in spec:
        if len(moving) > 1:
            raise ctx.error("matrix cannot be combined with translate, rotate or pivot")
        M = _matrix(ctx, spec["matrix"], base)
        why = not_rigid(M[:3, :3])
        if why:
            ctx.warn("not-rigid", f"matrix {why}: no rigid motion reaches its targets, so the surface "
                     "around the group is stretched or turned inside out")
        return rest @ M[:3, :3].T + M[:3, 3]
    if "pivot" in spec and "rotate" not in spec:
        raise ctx.error("pivot only applies together with rotate")
    out = rest.copy()
    if "rotate" in spec:
        _check_turn(ctx, spec["rotate"])
        pivot = (ctx.vector(spec["pivot"], "pivot", 3) if "pivot" in spec
                 else rest.mean(axis=0))
        out = (rest - pivot) @ rotation_matrix(ctx, spec["rotate"]).T + pivot
    if "translate" in spec:
        out = out + ctx.vector(spec["translate"], "translate", 3)
    return out


def describe_action(spec: dict, rest: np.ndarray) -> str:
    """A group's static action as its handle file states it, in words (for ``srarap info``):
    the values as written, a default pivot as the centroid it is, no round-off.

    Examples
    --------
    >>> rest = np.array([[0., 0, 0], [2, 0, 0]])
    >>> describe_action({"rotate": {"axis": [0, 1, 0], "angle_deg": 90}}, rest)
    "rotate 90 degrees (angle_deg) about axis (0, 1, 0) through the group's centroid (1, 0, 0)"
    >>> describe_action({"translate": [0, 0, 2]}, rest)
    'translate (0, 0, 2)'
    """
    if spec.get("fixed"):
        return "fixed"
    if "matrix" in spec:
        M = spec["matrix"]
        return f"matrix from {M}" if isinstance(M, str) else "matrix " + "; ".join(
            vector_text(row) for row in np.asarray(M, float).reshape(4, 4)[:3])
    words = []
    if "rotate" in spec:
        rot = spec["rotate"]
        key = next(k for k in (*ANGLE_KEYS, *QUATERNION_KEYS) if k in rot)
        if key in QUATERNION_KEYS:
            q = _scaled(np.asarray(rot[key], float)[QUATERNION_KEYS[key]])
            q = q / np.linalg.norm(q) * (1 if q[0] >= 0 else -1)
            angle = float(np.degrees(2 * np.arctan2(np.linalg.norm(q[1:]), q[0])))
            turn = (f"rotate {_num(angle)} degrees about {vector_text(q[1:] / np.linalg.norm(q[1:]))} "
                    f"({key} {vector_text(rot[key])})" if angle > 1e-9 else "")
        else:
            unit = {"angle_deg": "degrees", "angle_rad": "radians", "angle": "degrees"}[key]
            turn = f"rotate {_num(rot[key])} {unit} ({key}) about axis {vector_text(rot['axis'])}"
        pivot = (f"through {vector_text(spec['pivot'])}" if "pivot" in spec else
                 f"through the group's centroid {vector_text(rest.mean(axis=0), np.abs(rest).max())}")
        if turn:
            words.append(f"{turn} {pivot}")
    if "translate" in spec:
        words.append(f"translate {vector_text(spec['translate'])}")
    return ", then ".join(words) or "fixed"


def _num(x, scale=1.0):
    """``x`` in 6 digits; rounding noise (below 1e-12 of ``scale``) and -0 written 0."""
    x = float(x)
    return f"{(0.0 if abs(x) < 1e-12 * scale else x) + 0.0:.6g}"


def vector_text(v: np.ndarray, scale: float | None = None) -> str:
    """``(x, y, z)`` in 6 digits, rounding noise below 1e-12 of ``scale`` (default the
    largest component) written 0.

    Examples
    --------
    >>> vector_text(np.array([1.0, -1.6e-16, 2.5]))
    '(1, 0, 2.5)'
    """
    v = np.asarray(v, float).ravel()
    scale = float(np.abs(v).max(initial=0)) if scale is None else float(scale)
    return "(" + ", ".join(_num(x, scale) for x in v) + ")"
