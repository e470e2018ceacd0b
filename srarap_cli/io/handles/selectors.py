"""Selectors: which vertices a handle group (or the region of interest) covers."""
import os

import numpy as np

from .fields import Context
from .formats import SEL_STATUS, read_dmat, read_sel

SELECTOR_KEYS = ("indices", "sphere", "box", "dmat", "sel")


def _file(ctx, base, value, name):
    if not isinstance(value, str) or not value:
        raise ctx.error(f"{name} must be a file path")
    return os.path.join(base, value)


def _indices(ctx, spec, V, base):
    if isinstance(spec, (str, bool)) or not isinstance(spec, (list, tuple)):
        raise ctx.error("indices must be a list of vertex indices")
    idx = np.array([ctx.integer(i, "indices") for i in spec], dtype=np.int64)
    bad = idx[(idx < 0) | (idx >= len(V))]
    if bad.size:
        more = f" (and {bad.size - 1} more)" if bad.size > 1 else ""
        raise ctx.error(f"indices: vertex {bad[0]}{more} out of range: the mesh has {len(V)} "
                        f"vertices, ids 0..{len(V) - 1} (0-based)")
    return idx


def _shapes(select_one):
    """A selector of one shape that also takes a list of them (the union of their vertices)."""
    def select_any(ctx, spec, V, base):
        if isinstance(spec, list):
            if not spec:
                raise ctx.error(f"{select_one.__name__[1:]}: an empty list selects nothing")
            return np.unique(np.concatenate([
                select_one(ctx.at(f"{ctx.where}, {select_one.__name__[1:]} {k}".lstrip(", ")),
                           one, V)
                for k, one in enumerate(spec)]))
        return select_one(ctx, spec, V)
    return select_any


def _sphere(ctx, spec, V):
    spec = ctx.record(spec, "sphere", ("center", "radius"))
    center = ctx.vector(spec["center"], "center", 3)
    radius = ctx.number(spec["radius"], "radius", 0, strict=True)
    return np.flatnonzero(np.sum((V - center) ** 2, axis=1) <= radius * radius)


def _box(ctx, spec, V):
    spec = ctx.record(spec, "box", ("min", "max"))
    lo, hi = ctx.vector(spec["min"], "min", 3), ctx.vector(spec["max"], "max", 3)
    if (lo > hi).any():
        raise ctx.error("box: min must not exceed max in any coordinate")
    return np.flatnonzero(np.all((V >= lo) & (V <= hi), axis=1))


def _checked_length(ctx, values, V, path):
    if values.size != len(V):
        raise ctx.error(f"{path} has {values.size} entries but the mesh has {len(V)} vertices")
    return values


def _dmat(ctx, spec, V, base):
    spec = ctx.record(spec, "dmat", ("file", "group"))
    path = _file(ctx, base, spec["file"], "dmat file")
    group = ctx.integer(spec["group"], "dmat group", 0)
    return np.flatnonzero(_checked_length(ctx, read_dmat(path), V, path) == group)


def _sel(ctx, spec, V, base):
    spec = ctx.record(spec, "sel", ("file", "status"))
    if not isinstance(spec["status"], str) or spec["status"] not in SEL_STATUS:
        raise ctx.error("sel status must be one of fixed, free, handle")
    path = _file(ctx, base, spec["file"], "sel file")
    return np.flatnonzero(_checked_length(ctx, read_sel(path), V, path)
                          == SEL_STATUS[spec["status"]])


_SELECTORS = {"indices": _indices, "sphere": _shapes(_sphere), "box": _shapes(_box),
              "dmat": _dmat, "sel": _sel}


def select(ctx: Context, spec: dict, V: np.ndarray, base: str) -> np.ndarray:
    """Union of the vertices picked by every selector key present in ``spec``.

    Parameters
    ----------
    ctx : fields.Context
    spec : dict, a group or region entry of the handle file
    V : (n, 3) float array, rest positions
    base : str, folder that relative file paths start from

    Returns
    -------
    (k,) int array of sorted vertex ids
    """
    keys = [k for k in SELECTOR_KEYS if k in spec]
    if not keys:
        raise ctx.error(f"no selector (use one or more of {', '.join(SELECTOR_KEYS)})")
    picked = [_SELECTORS[k](ctx, spec[k], V, base) for k in keys]
    ids = np.unique(np.concatenate(picked))
    if ids.size == 0:
        shapes = [_shown(k, one) for k in ("box", "sphere") if k in spec
                  for one in (spec[k] if isinstance(spec[k], list) else [spec[k]])]
        if not len(V):
            raise ctx.error(f"selects no vertex ({', '.join(keys)}): the mesh has none")
        lo, hi = V.min(axis=0), V.max(axis=0)
        extent = ", ".join(f"{a} {lo[i]:.4g}..{hi[i]:.4g}" for i, a in enumerate("xyz"))
        raise ctx.error(f"selects no vertex ({'; '.join(shapes) or ', '.join(keys)}); the "
                        f"mesh spans {extent}")
    return ids


def _shown(kind, spec):
    """A box or sphere as the error beside the mesh's extent shows it."""
    def vec(v):
        return "[" + ", ".join(f"{float(x):.4g}" for x in v) + "]"
    if kind == "box":
        return f"box {vec(spec['min'])}..{vec(spec['max'])}"
    return f"sphere at {vec(spec['center'])} radius {float(spec['radius']):.4g}"
