"""The ``keyframes`` of a handle group: parsed into a :class:`~srarap_cli.io.handles.keyframes.Track`."""
import numpy as np

from ...solver.quaternion import IDENTITY, from_matrix
from .fields import Context
from .keyframes import EASINGS, Track
from .transforms import STATIC_ACTIONS, rotation_matrix

KEY_KEYS = ("frame", "time", "translate", "rotate")


def parse_track(ctx: Context, spec: dict, rest: np.ndarray, fps: float | None,
                any_rate: bool = False) -> Track:
    """Track of a group with ``keyframes`` (rest: (m, 3) rest positions of the group).

    ``any_rate``: only the pose at frame 0 is wanted, so ``time`` keys need no ``fps``: that
    pose is the first key's at every frame rate (keys are in increasing order and none comes
    before frame 0), and without a rate the track keeps that key alone."""
    clash = [k for k in STATIC_ACTIONS if k in spec]
    if clash:
        raise ctx.error(f"keyframes cannot be combined with {clash[0]} (put it in the keys)")
    keys = spec["keyframes"]
    if not isinstance(keys, list) or not keys:
        raise ctx.error("keyframes must be a non-empty list of keys")
    frames, moves, turns = [], [], []
    for k, key in enumerate(keys):
        kctx = ctx.at(f"{ctx.where}: keyframe {k}")
        key = kctx.mapping(key, "the keyframe", KEY_KEYS)
        frames.append(_frame(kctx, key, fps, any_rate))
        moves.append(kctx.vector(key["translate"], "translate", 3) if "translate" in key
                     else np.zeros(3))
        turns.append(from_matrix(rotation_matrix(kctx, key["rotate"])[None])[0]
                     if "rotate" in key else IDENTITY)
    first_only = None in frames
    if first_only:  # time keys without a rate: the pose at frame 0 only
        frames, moves, turns = [frames[0] or 0.0], moves[:1], turns[:1]
    frames = np.array(frames)
    if (np.diff(frames) <= 0).any():
        raise ctx.error("keyframes must be in strictly increasing frame order")
    easing = spec.get("easing", "linear")
    if easing not in EASINGS:
        raise ctx.error(f"easing must be one of {', '.join(EASINGS)}")
    pivot = ctx.vector(spec["pivot"], "pivot", 3) if "pivot" in spec else rest.mean(axis=0)
    return Track(frames, np.array(moves), np.array(turns), pivot, easing, first_only)


def _frame(ctx, key, fps, any_rate=False):
    if ("frame" in key) == ("time" in key):
        raise ctx.error("give exactly one of frame or time")
    if "frame" in key:
        return float(ctx.integer(key["frame"], "frame", 0))
    if fps is None and any_rate:
        ctx.number(key["time"], "time", 0)
        return None
    if fps is None:
        raise ctx.error("time needs a frame rate: give --fps (animate, deform and info take "
                        "it), or give the key's frame instead")
    return ctx.number(key["time"], "time", 0) * fps
