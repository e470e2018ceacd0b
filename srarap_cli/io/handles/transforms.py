"""Actions: where a handle group's vertices go."""
import os

import numpy as np

from ...runtime.limits import MAX_COORDINATE
from ...solver.quaternion import from_axis_angle, to_matrix
from .formats import read_def

ACTION_KEYS = ("fixed", "translate", "rotate", "pivot", "matrix")


def rotation_matrix(ctx, spec):
    """3x3 matrix of a ``rotate`` entry (axis and angle in degrees, or a quaternion)."""
    spec = ctx.mapping(spec, "rotate", ("axis", "angle", "quaternion"))
    if "quaternion" in spec:
        if "axis" in spec or "angle" in spec:
            raise ctx.error("rotate takes either 'quaternion' or 'axis' and 'angle'")
        q = ctx.vector(spec["quaternion"], "quaternion [w, x, y, z]", 4)
        if np.linalg.norm(q) < 1e-12:
            raise ctx.error("quaternion must not be zero")
        return to_matrix(q / np.linalg.norm(q))
    if "axis" not in spec or "angle" not in spec:
        raise ctx.error("rotate needs 'axis' and 'angle' (degrees), or 'quaternion'")
    axis = ctx.vector(spec["axis"], "axis", 3)
    if np.linalg.norm(axis) < 1e-12:
        raise ctx.error("axis must not be zero")
    return to_matrix(from_axis_angle(axis, ctx.number(spec["angle"], "angle")))


def _matrix(ctx, value, base):
    if isinstance(value, str):
        return read_def(os.path.join(base, value))
    M = ctx.matrix4(value, "matrix")
    if not np.allclose(M[3], [0, 0, 0, 1]):
        raise ctx.error("matrix: last row must be [0, 0, 0, 1]")
    return M


def targets(ctx, spec, rest, base):
    """Target positions (k, 3) of a group whose rest positions are ``rest`` (k, 3).

    ``fixed: true`` keeps rest positions; otherwise ``x' = Rot (x - pivot) + pivot +
    translate`` (pivot defaults to the group's centroid), or ``x' = matrix @ [x, 1]`` with a
    4x4 matrix given inline or as the path of a ``.def`` file.
    """
    out = _moved(ctx, spec, rest, base)
    if not np.isfinite(out).all() or np.abs(out).max(initial=0) > MAX_COORDINATE:
        where = f" ({spec['matrix']})" if isinstance(spec.get("matrix"), str) else ""
        raise ctx.error(f"the action{where} sends vertices beyond {MAX_COORDINATE:g} or to "
                        "infinite/NaN positions (entries too large)")
    return out


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
        return rest @ M[:3, :3].T + M[:3, 3]
    if "pivot" in spec and "rotate" not in spec:
        raise ctx.error("pivot only applies together with rotate")
    out = rest.copy()
    if "rotate" in spec:
        pivot = (ctx.vector(spec["pivot"], "pivot", 3) if "pivot" in spec
                 else rest.mean(axis=0))
        out = (rest - pivot) @ rotation_matrix(ctx, spec["rotate"]).T + pivot
    if "translate" in spec:
        out = out + ctx.vector(spec["translate"], "translate", 3)
    return out
