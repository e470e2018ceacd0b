"""Read and validate a handle file into :class:`Constraints`; see the package's docstring."""
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...runtime.errors import InputError
from ...runtime.limits import MAX_COORDINATE
from ...runtime.warning_codes import note
from ...solver.api_checks import targets as checked_targets
from ...solver.api_checks import vertex_ids
from ...solver.settings import parse_mapping
from ..documents import is_stream, load_document
from .fields import Context
from .formats import read_def, read_sel
from .keys import parse_track
from .selectors import SELECTOR_KEYS, select
from .transforms import (
    ACTION_KEYS,
    ROUNDING,
    check_bounds,
    check_reach,
    describe_action,
    not_rigid,
    targets,
)

TOP_KEYS = ("groups", "region", "solver")
ANIMATION_KEYS = ("keyframes", "easing")


@dataclass
class Constraints:
    """Constrained vertices and their targets, resolved against a mesh.

    Attributes
    ----------
    ids : (k,) int array, sorted constrained vertex ids
    targets : (k, 3) float array, target position of each id
    groups : dict of group name -> (j,) int array of its vertex ids
    region : (r,) int array or None, vertices allowed to move (region of interest);
        everything else stays at rest
    solver : dict, solver settings given in the file (see :mod:`srarap_cli.solver.settings`)
    tracks : list of (slots, rest, Track): keyframed groups, ``slots`` indexing ``ids``;
        ``targets`` holds their pose at frame 0
    actions : dict of group name -> str, each static group's action as the file states it
    warnings : list of str, what the file says that is valid but looks like a mistake (an
        angle's unit, a motion larger than the mesh), each naming file and group
    """

    ids: np.ndarray
    targets: np.ndarray
    groups: dict = field(default_factory=dict)
    region: np.ndarray | None = None
    solver: dict = field(default_factory=dict)
    tracks: list = field(default_factory=list)
    warnings: list = field(default_factory=list)
    actions: dict = field(default_factory=dict)

    @property
    def last_key_frame(self) -> float:
        """Frame of the latest keyframe (0 without keyframes)."""
        return max((float(t.frames[-1]) for _, _, t in self.tracks), default=0.0)

    def targets_at(self, frame: float) -> np.ndarray:
        """Targets (k, 3) at ``frame``: keyframed groups moved, the others as they are."""
        out = self.targets.copy()
        for slots, rest, track in self.tracks:
            out[slots] = track.apply(rest, frame)
        return out


def as_constraints(handles: Any, V: np.ndarray) -> "Constraints":
    """Constraints from what a Python caller has: a handle file's path, a dict in the handle
    file's schema, an ``(ids, targets)`` pair, or Constraints. Raises TypeError naming
    ``handles`` for anything else, ValueError for a wrong pair.

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> c = as_constraints(([2, 0], [[0, 2, 0], [0, 0, 0]]), V)
    >>> c.ids.tolist(), c.targets.tolist()
    ([0, 2], [[0.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    """
    if isinstance(handles, Constraints):
        return handles
    if isinstance(handles, (str, os.PathLike)):
        return load_handles(handles, V)
    if isinstance(handles, dict):
        try:
            return parse_handles(handles, V)
        except InputError as exc:
            raise ValueError(str(exc).replace("<handles>: ", "handles: ", 1)) from None
    if isinstance(handles, (tuple, list)) and len(handles) == 2:
        ids = vertex_ids(handles[0], len(V), "handles ids")
        tgt = checked_targets(handles[1], len(ids))
        order = np.argsort(ids, kind="stable")
        # no groups: the solver groups the ids by the connected patches they form
        return Constraints(ids=ids[order], targets=tgt[order])
    raise TypeError("handles must be a handle file's path, a dict in the handle-file schema, "
                    f"an (ids, targets) pair or Constraints, got {type(handles).__name__}")


def load_handles(path: str | os.PathLike, V: np.ndarray,
                 fps: float | None = None, any_rate: bool = False) -> "Constraints":
    """Read and validate a handle file against rest positions ``V`` (n, 3).

    Parameters
    ----------
    path : str, ``.yaml``/``.yml``, ``.json`` or ``.sel``
    V : (n, 3) float array
    fps : float, optional; frames per second, for keyframes given by ``time``
    any_rate : bool, only the pose at frame 0 is wanted: ``time`` keys need no ``fps``
        (keyframed groups then keep their first key alone)

    Returns
    -------
    Constraints
    """
    path = str(path)
    if os.path.isdir(path):
        raise InputError(f"{path}: is a folder, not a handle file")
    streamed = is_stream(path)
    if path.lower().endswith(".sel"):
        if streamed:
            raise InputError(f"{path}: a .sel file is read beside its .def; give it as a file")
        return _from_sel(path, V)
    return parse_handles(_load_document(path), V, _shown(path), _base(path), fps, any_rate)


def _load_document(path):
    ext = os.path.splitext(path)[1].lower()
    if is_stream(path):  # standard input, a pipe, a process substitution: by content
        return load_document(path, "json" if ext == ".json" else "content")
    if ext not in (".yaml", ".yml", ".json"):
        raise InputError(f"{path}: handle file must be .yaml, .yml, .json or .sel (or come "
                         "from a pipe or '-', read by its content)")
    return load_document(path, "json" if ext == ".json" else "yaml")


def _shown(path):
    return "<stdin>" if path == "-" else path


def _base(path):
    """The folder a handle file's relative paths start from: its own, or the working folder
    for one from a stream."""
    return os.getcwd() if is_stream(path) else os.path.dirname(os.path.abspath(path))


def _alike_names(groups):
    """Two group keys of different types that print alike (``1`` and ``"1"``): every report
    names groups as text, where one would hide the other. None when all differ."""
    seen: dict[str, Any] = {}
    for key in groups:
        if str(key) in seen:
            return seen[str(key)], key
        seen[str(key)] = key
    return None


def parse_handles(doc: Any, V: np.ndarray, path: str = "<handles>", base: str = ".",
                  fps: float | None = None, any_rate: bool = False) -> "Constraints":
    """Validate an already-loaded handle document (dict) against ``V``; see :func:`load_handles`."""
    ctx = Context(path)
    doc = ctx.mapping(doc, "the handle file", TOP_KEYS)
    groups = doc.get("groups")
    if not isinstance(groups, dict) or not groups:
        raise ctx.error("'groups' must map at least one group name to its selection and action")
    names, ids, tgts, tracks, actions = [], [], [], {}, {}
    diagonal = float(np.linalg.norm(np.ptp(V, axis=0))) if len(V) else 0.0
    alike = _alike_names(groups)
    if alike:
        raise ctx.error(f"group names {alike[0]!r} and {alike[1]!r} read as one name "
                        f"({str(alike[0])!r}): name them apart")
    for name, spec in groups.items():
        gctx = ctx.at(f"group {name!r}")
        spec = gctx.mapping(spec, "the group", SELECTOR_KEYS + ACTION_KEYS + ANIMATION_KEYS)
        sel = select(gctx, spec, V, base)
        names.append(str(name))
        ids.append(sel)
        if "keyframes" in spec:
            track = tracks[str(name)] = parse_track(gctx, spec, V[sel], fps, any_rate)
            tgts.append(track.apply(V[sel], 0.0))
            for k, frame in enumerate(track.frames):  # every key checked before frame 0
                moved = track.apply(V[sel], float(frame))
                check_bounds(gctx, moved, f"keyframe {k}")
                check_reach(gctx, V[sel], moved, diagonal, f"its keyframe {k}")
            if np.abs(track.pivot).max(initial=0) > MAX_COORDINATE:
                raise gctx.error(f"pivot beyond {MAX_COORDINATE:g}: its keyframes' rotations "
                                 "would send vertices to infinity between the keys")
        else:
            if "easing" in spec:
                raise gctx.error("easing only applies together with keyframes")
            tgts.append(targets(gctx, spec, V[sel], base))
            check_reach(gctx, V[sel], tgts[-1], diagonal)
            actions[str(name)] = describe_action(spec, V[sel])
    region = None
    if "region" in doc:
        rctx = ctx.at("region")
        region = select(rctx, rctx.mapping(doc["region"], "region", SELECTOR_KEYS), V, base)
    merged_ids, merged = _merge(ctx, names, ids, tgts, V)
    return Constraints(ids=merged_ids, targets=merged, groups=dict(zip(names, ids)),
                       region=region, solver=parse_mapping(doc.get("solver", {}), "solver",
                                            ctx.at("solver").error),
                       tracks=_tracks(ctx, tracks, dict(zip(names, ids)), merged_ids, V),
                       warnings=ctx.warnings, actions=actions)


def _tracks(ctx, tracks, groups, merged_ids, V):
    """(slots, rest, track) per keyframed group; its vertices may belong to no other group."""
    out = []
    for name, track in tracks.items():
        mine = groups[name]
        for other, theirs in groups.items():
            shared = np.intersect1d(mine, theirs) if other != name else np.zeros(0, int)
            if len(shared):
                raise ctx.error(f"vertex {shared[0]} is in keyframed group {name!r} and in "
                                f"group {other!r}")
        out.append((np.searchsorted(merged_ids, mine), V[mine], track))
    return out


def _merge(ctx, names, ids, tgts, V):
    """One target per vertex; a vertex two groups send to different places is an error."""
    all_ids = np.concatenate(ids)
    all_t = np.concatenate(tgts)
    owner = np.repeat(np.arange(len(names)), [len(i) for i in ids])
    order = np.argsort(all_ids, kind="stable")
    all_ids, all_t, owner = all_ids[order], all_t[order], owner[order]
    first = np.concatenate([[True], all_ids[1:] != all_ids[:-1]])
    lead = np.maximum.accumulate(np.where(first, np.arange(all_ids.size), 0))
    scale = max(float(np.ptp(V, axis=0).max()), 1e-300)
    # the same motion written twice (a rotate and its matrix with six decimals) agrees only
    # up to the decimals' rounding: the first group's target stands
    clash = np.flatnonzero(np.linalg.norm(all_t - all_t[lead], axis=1) > ROUNDING * scale)
    if clash.size:
        k = clash[0]
        raise ctx.error(f"vertex {all_ids[k]} is in groups {names[owner[lead[k]]]!r} and "
                        f"{names[owner[k]]!r} with different targets")
    return all_ids[first], all_t[first]


def _from_sel(path, V):
    """A ``.sel`` file alone: status 0 stays fixed, status 2 follows the ``.def`` beside it."""
    status = read_sel(path)
    if status.size != len(V):
        raise InputError(f"{path}: has {status.size} entries but the mesh has {len(V)} vertices")
    def_path = os.path.splitext(path)[0] + ".def"
    fixed, handle = np.flatnonzero(status == 0), np.flatnonzero(status == 2)
    if fixed.size + handle.size == 0:
        raise InputError(f"{path}: no vertex has status 0 (fixed) or 2 (handle)")
    t = V.copy()
    warnings = []
    if handle.size:
        if not os.path.isfile(def_path):
            raise InputError(f"{def_path}: no such file (the .def that goes with {path})")
        M = read_def(def_path)
        if why := not_rigid(M[:3, :3]):
            warnings.append(note("not-rigid", f"{def_path}: the matrix {why}: no rigid motion "
                                 "reaches its targets, so the surface around the handle is "
                                 "stretched or turned inside out"))
        t[handle] = V[handle] @ M[:3, :3].T + M[:3, 3]
        if not np.isfinite(t[handle]).all() or np.abs(t[handle]).max() > MAX_COORDINATE:
            raise InputError(f"{def_path}: sends handle vertices to infinite or NaN positions "
                             "(entries too large)")
    ids = np.flatnonzero(status != 1)
    return Constraints(ids=ids, targets=t[ids], groups={"fixed": fixed, "handle": handle},
                       warnings=warnings)


def solver_settings(handles: str | os.PathLike) -> dict[str, Any]:
    """The settings of a handle file's ``solver`` section, parsed; {} for a ``.sel`` file
    and for a file that cannot be read or parsed (loading it says why)."""
    handles = str(handles)
    if handles.lower().endswith(".sel"):
        return {}
    try:
        doc = load_document(handles, "yaml")  # JSON is YAML too
        spec = doc.get("solver", {}) if isinstance(doc, dict) else {}
        return parse_mapping(spec, "solver", InputError)
    except InputError:
        return {}


def referenced_files(handles: str | os.PathLike) -> list[str]:
    """Files a handle file names (``.dmat``, ``.sel``, ``.def``, ...): every string in it that
    is the path of an existing file, relative to the handle file; a ``.sel`` brings its ``.def``."""
    handles = str(handles)
    base = _base(handles)
    if handles.lower().endswith(".sel"):
        return [os.path.splitext(handles)[0] + ".def"]
    try:
        doc = load_document(handles, "yaml")  # JSON is YAML too
    except InputError:
        return []
    found, stack = [], [doc]
    while stack:
        item = stack.pop()
        if isinstance(item, dict):
            stack.extend(item.values())
        elif isinstance(item, list):
            stack.extend(item)
        elif isinstance(item, str) and os.path.isfile(os.path.join(base, item)):
            found.append(os.path.join(base, item))
    return sorted(set(found))
