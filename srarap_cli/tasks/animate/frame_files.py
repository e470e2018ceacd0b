"""An animation's frame files: the pattern that names them, the files an earlier run left
under it, how many frames the keys make."""
import math
import os
import re
import string

from ...io.mesh.formats import extensions, suffix_of
from ...runtime.errors import InputError, OutputError, UsageProblem
from ..preflight import check_output_path

#: frames an animation may have unless raised on purpose (a typo in --fps or a keyframe time
#: would otherwise fill the disk)
MAX_FRAMES = 100_000


def check_pattern(pattern: str) -> str:
    """The folder of the frames named by ``pattern`` (made if missing); UsageProblem for a
    pattern without exactly one frame-number field in the file name."""
    fields = _fields(pattern)
    if len(fields) != 1 or fields[0][0] not in ("", "0") or fields[0][2] is not None \
            or not re.fullmatch(r"0?[1-9]?[0-9]?d?", fields[0][1] or ""):
        raise UsageProblem(f"-o {pattern!r}: needs exactly one frame-number field such as "
                           "'{}' or '{:04d}' (width at most 99)")
    try:
        a, b = pattern.format(0), pattern.format(1)
    except (IndexError, KeyError, ValueError):
        raise UsageProblem(f"-o {pattern!r}: needs one format field for the frame number, "
                           "e.g. 'out/frame_{:04d}.obj'") from None
    if a == b:
        raise UsageProblem(f"-o {pattern!r}: has no field for the frame number")
    if os.path.dirname(a) != os.path.dirname(b):
        raise UsageProblem(f"-o {pattern!r}: the frame number must be in the file name, "
                           "not in a folder")
    if suffix(pattern) not in extensions():
        raise UsageProblem(f"-o {pattern!r}: extension must be one of "
                           f"{', '.join(extensions())}")
    # checked, not made: the frames' commit makes it (a run that fails first leaves none)
    check_output_path(a, None, "-o")
    return os.path.dirname(os.path.abspath(a))


def _fields(pattern):
    """(name, spec, conversion) of each replacement field; a malformed pattern has none."""
    try:
        return [(name, spec, conv) for _, name, spec, conv in string.Formatter().parse(pattern)
                if name is not None]
    except ValueError:
        return []


def suffix(pattern: str) -> str:
    """The frames' extension, lower-case (``.obj``)."""
    return suffix_of(pattern.format(0))


def frame_count(frames: int | None, last_key_frame: float, max_frames: int, handles: str,
                fps: float | None) -> int:
    """``frames``, or the frames up to the last key; InputError past ``max_frames``."""
    n = frames if frames is not None else (
        math.floor(last_key_frame) + 1 if math.isfinite(last_key_frame) else math.inf)
    if n > max_frames:
        why = "--frames" if frames is not None else (
            f"the last keyframe of {handles}" + (f" (at --fps {fps:g})" if fps else ""))
        shown = f"{n:.3g}" if isinstance(n, float) else str(n)
        raise InputError(f"{why} makes {shown} frames, more than --max-frames {max_frames}; "
                         "raise --max-frames to render them")
    return int(n)


def frames_on_disk(pattern: str) -> dict[int, str]:
    """frame number -> path of the files in the pattern's folder that the pattern names."""
    literal = [(text, field) for text, field, _, _ in string.Formatter().parse(pattern)]
    head, tail = literal[0][0], "".join(text for text, _ in literal[1:])
    folder, head = os.path.split(head)
    name = re.compile(re.escape(head) + r" *(\d+)" + re.escape(tail))
    found: dict[int, str] = {}
    if not os.path.isdir(folder or "."):  # not made yet: no frame there
        return found
    for entry in os.listdir(folder or "."):
        match = name.fullmatch(entry)
        if match and os.path.basename(pattern.format(int(match.group(1)))) == entry:
            found[int(match.group(1))] = os.path.join(folder, entry)
    return found


def frame_paths(pattern: str) -> list[str]:
    """The files of an animation's frame ``pattern`` (as ``animate`` writes them) from frame
    0 up to the first missing one, found by listing their folder (not by trying names: an
    animation may have :data:`MAX_FRAMES` and more). InputError without a frame 0,
    UsageProblem for a pattern without one frame-number field."""
    try:
        first = pattern.format(0)
        if first == pattern.format(1):
            raise ValueError("no field for the frame number")
    except (IndexError, KeyError, ValueError) as exc:
        raise UsageProblem(f"{pattern!r}: not a frame pattern with one field like "
                           f"'{{:04d}}' ({exc})") from None
    found = frames_on_disk(pattern)
    paths: list[str] = []
    while len(paths) in found:
        paths.append(found[len(paths)])
    if not paths:
        raise InputError(f"{pattern}: no frame 0 ({first} does not exist)")
    return paths


def remove_stale(pattern: str, first: int) -> int:
    """Remove the frames from ``first`` on that an earlier run left under ``pattern``;
    returns how many."""
    stale = [path for k, path in frames_on_disk(pattern).items() if k >= first]
    for path in stale:
        try:
            os.unlink(path)
        except FileNotFoundError:
            pass
        except OSError as exc:
            raise OutputError(f"{path}: cannot remove a frame of an earlier run: "
                              f"{exc.strerror}") from None
    return len(stale)
