"""``srarap animate``: keyframed handles -> one deformed mesh per frame."""
import math
import os
import re
import string
import sys
import time
from typing import Any

import click

from ..io.handles import load_handles, referenced_files
from ..io.mesh import format_mesh, frame_formatter, read_mesh
from ..io.mesh.formats import extensions
from ..io.solve_log import LOG_FORMATS, format_log
from ..runtime import exit_codes
from ..runtime.commit import commit_files
from ..runtime.encoding import utf8
from ..runtime.errors import InputError, OutputError
from ..runtime.limits import check_solve
from ..solver.settings import resolve
from ..solver.stop import StopReason
from ..tasks.animation import FRAME_FIELDS, Animator, FrameState, fingerprint, unreached_keys
from ..tasks.pipeline import refuse_warnings
from ..tasks.preflight import check_output_path, refuse_overwrite
from .common import FiniteFloat, cache_option, guarded, report, with_verbosity
from .options import settings_options

STATE_NAME = ".srarap-animate-state.npz"
MAX_FRAMES = 100_000


@click.command("animate")
@click.argument("mesh")
@click.argument("handles")
@click.option("-o", "--output", "pattern", required=True,
              help="Frame file pattern with a format field, e.g. 'out/frame_{:04d}.obj'.")
@click.option("--frames", type=click.IntRange(min=1),
              help="Number of frames. [default: up to the last keyframe]")
@click.option("--fps", type=FiniteFloat(min=0, min_open=True),
              help="Frames per second, for keyframes given by time.")
@click.option("--max-frames", type=click.IntRange(min=1), default=MAX_FRAMES, show_default=True,
              help="Refuse an animation of more frames than this (a typo in --fps or a "
                   "keyframe time would otherwise fill the disk); raise it on purpose.")
@click.option("--iters-per-frame", type=click.IntRange(min=1),
              help="Fixed budget (real-time mode): at most N iterations per frame, and a "
                   "frame that stops short of --tol is written all the same (exit code 0). "
                   "[default: every frame iterates to --tol, at most --max-iter]")
@click.option("--keep-unconverged", is_flag=True,
              help="Write a frame that did not converge and go on (exit code still 3).")
@click.option("--log", "log", help="Per-frame log: .csv or .jsonl.")
@click.option("--resume", is_flag=True, help="Continue after the last complete frame.")
@settings_options()
@cache_option
@with_verbosity
@guarded
def animate(mesh: str, handles: str, pattern: str, frames: int | None, fps: float | None,
            max_frames: int, iters_per_frame: int | None, keep_unconverged: bool,
            log: str | None, resume: bool, overrides: dict[str, Any], cache: str | None,
            verbosity: int | None) -> None:
    """Deform MESH through the keyframes of HANDLES, writing one mesh per frame.

    Each frame starts from the frames before it and iterates to --tol (at most --max-iter
    iterations and --time-limit seconds a frame). Frames are written atomically; --resume
    continues an interrupted run and gives the same files as an uninterrupted one. Exit
    codes: 0 every frame converged and was written; 3 a frame did not converge: the sequence
    stops before it (frames so far and the log are written; --keep-unconverged writes it and
    goes on; later frames an earlier run left under the pattern are removed, so that the
    sequence on disk is this run's). With --iters-per-frame N (fixed budget) every frame is
    written and the exit code is 0.
    """
    folder = _check_pattern(pattern)
    if log is not None:
        check_output_path(log, LOG_FORMATS, "log")
    source = read_mesh(mesh)
    check_solve(mesh, len(source.vertices))
    constraints = load_handles(handles, source.vertices, fps=fps)
    n_frames = _frame_count(frames, constraints.last_key_frame, max_frames, handles, fps)
    state_path = os.path.join(folder, STATE_NAME)
    # only existing files can be inputs: the folder is listed, the frames never enumerated
    on_disk = _frames_on_disk(pattern)
    refuse_overwrite([p for k, p in on_disk.items() if k < n_frames] + [log], mesh=mesh,
                     handles=handles, others=[("resume state", state_path)])
    opts = resolve(constraints.solver, overrides)
    run_id = fingerprint((mesh, handles, *referenced_files(handles)), opts, n_frames, fps,
                         iters_per_frame, pattern)
    state = _resume_state(state_path, run_id) if resume else None
    animator = Animator(source, constraints, opts, cache=cache, name=mesh)
    progress = _Progress(n_frames, enabled=verbosity != 0 and sys.stderr.isatty())

    frame_bytes = frame_formatter(source, _suffix(pattern))
    # what every frame's file loses, and keys no frame shows: said once, errors under strict
    lost = format_mesh(source, _suffix(pattern))[1] + unreached_keys(constraints, n_frames, fps,
                                                                      handles)
    refuse_warnings(opts, lost)

    def write_frame(f, positions, st):
        commit_files([(pattern.format(f), frame_bytes(positions)), (state_path, st.to_bytes())])
        progress.update(f + 1)

    budget = iters_per_frame is not None
    final = animator.run(n_frames, max_iter=iters_per_frame,
                         stop_unconverged=not (budget or keep_unconverged),
                         state=state, on_frame=write_frame, fingerprint=run_id)
    progress.close()
    rows = final.rows if final is not None else []
    if animator.stopped_at is not None:
        rows = rows + [animator.stopped_row]
    if log is not None:
        text = format_log(rows, os.path.splitext(log)[1].lower(), FRAME_FIELDS)
        commit_files([(log, utf8(text))])
    stopped = animator.stopped_at
    if stopped is None and os.path.exists(state_path):
        os.unlink(state_path)
    notes = animator.warnings + lost
    if stopped is not None:
        removed = _remove_stale(pattern, stopped)
        if removed:
            notes.append(f"removed {removed} later frame(s) of an earlier run under {pattern!r} "
                         f"(frame {stopped} on), so that the frames on disk are this run's")
    report(verbosity, warnings=notes,
           details=animator.last_result.report_lines() if animator.last_result else [],
           summary=_summary(rows, state, n_frames, pattern, stopped, iters_per_frame,
                            animator.last_result))
    unconverged = sum(not r["converged"] for r in rows)
    if unconverged and not budget:
        raise SystemExit(exit_codes.NOT_CONVERGED)


def _summary(rows, state, n_frames, pattern, stopped, budget, result):
    first = 0 if state is None else state.frame + 1
    last = n_frames - 1 if stopped is None else stopped - 1
    wrote = (f"wrote {pattern.format(first)} .. {pattern.format(last)}" if first <= last
             else "nothing left to write" if stopped is None else "no frame written")
    if first:
        wrote += f" (frames 0-{first - 1} were kept from the interrupted run)"
    converged = sum(r["converged"] for r in rows)
    seconds = sum(r["seconds"] for r in rows)
    its = sorted(r["iterations"] for r in rows)
    head = (f"srarap animate: {converged} of {len(rows)} frames converged"
            + (f" (fixed budget of {budget} iterations a frame)" if budget else "")
            + (f", median {its[len(its) // 2]} iterations" if its else "")
            + f"; {len(rows) / max(seconds, 1e-9):.2f} frames/s; {wrote}")
    if stopped is not None:
        reason = result.stop_reason
        limit = "--time-limit" if reason is StopReason.TIME_LIMIT else "--max-iter"
        head += (f"; STOPPED at frame {stopped}: not converged in {result.iterations} "
                 f"iterations ({reason}: {result.stop_detail}; raise {limit}, or "
                 "--keep-unconverged writes it and goes on)")
    return head


def _frame_count(frames, last_key_frame, max_frames, handles, fps):
    n = frames if frames is not None else (
        math.floor(last_key_frame) + 1 if math.isfinite(last_key_frame) else math.inf)
    if n > max_frames:
        why = "--frames" if frames is not None else (
            f"the last keyframe of {handles}" + (f" (at --fps {fps:g})" if fps else ""))
        shown = f"{n:.3g}" if isinstance(n, float) else str(n)
        raise InputError(f"{why} makes {shown} frames, more than --max-frames {max_frames}; "
                         "raise --max-frames to render them")
    return int(n)


def _frames_on_disk(pattern):
    """frame number -> path of the files in the pattern's folder that the pattern names."""
    literal = [(text, field) for text, field, _, _ in string.Formatter().parse(pattern)]
    head, tail = literal[0][0], "".join(text for text, _ in literal[1:])
    folder, head = os.path.split(head)
    name = re.compile(re.escape(head) + r" *(\d+)" + re.escape(tail))
    found = {}
    for entry in os.listdir(folder or "."):
        match = name.fullmatch(entry)
        if match and os.path.basename(pattern.format(int(match.group(1)))) == entry:
            found[int(match.group(1))] = os.path.join(folder, entry)
    return found


def _remove_stale(pattern, first):
    """Remove the frames from ``first`` on that an earlier run left under ``pattern``;
    returns how many."""
    stale = [path for k, path in _frames_on_disk(pattern).items() if k >= first]
    for path in stale:
        try:
            os.unlink(path)
        except FileNotFoundError:
            pass
        except OSError as exc:
            raise OutputError(f"{path}: cannot remove a frame of an earlier run: "
                              f"{exc.strerror}") from None
    return len(stale)


def _fields(pattern):
    """(name, spec, conversion) of each replacement field; a malformed pattern has none."""
    try:
        return [(name, spec, conv) for _, name, spec, conv in string.Formatter().parse(pattern)
                if name is not None]
    except ValueError:
        return []


def _suffix(pattern):
    return os.path.splitext(pattern.format(0))[1].lower()


def _check_pattern(pattern):
    fields = _fields(pattern)
    if len(fields) != 1 or fields[0][0] not in ("", "0") or fields[0][2] is not None \
            or not re.fullmatch(r"0?[1-9]?[0-9]?d?", fields[0][1] or ""):
        raise click.UsageError(f"-o {pattern!r}: needs exactly one frame-number field such as "
                               "'{}' or '{:04d}' (width at most 99)")
    try:
        a, b = pattern.format(0), pattern.format(1)
    except (IndexError, KeyError, ValueError):
        raise click.UsageError(f"-o {pattern!r}: needs one format field for the frame number, "
                               "e.g. 'out/frame_{:04d}.obj'") from None
    if a == b:
        raise click.UsageError(f"-o {pattern!r}: has no field for the frame number")
    if os.path.dirname(a) != os.path.dirname(b):
        raise click.UsageError(f"-o {pattern!r}: the frame number must be in the file name, "
                               "not in a folder")
    if _suffix(pattern) not in extensions():
        raise click.UsageError(f"-o {pattern!r}: extension must be one of "
                               f"{', '.join(extensions())}")
    folder = os.path.dirname(os.path.abspath(a))
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{folder}: cannot create folder: {exc.strerror}") from None
    return folder


def _resume_state(path, fingerprint):
    if not os.path.exists(path):
        return None
    state = FrameState.from_file(path)
    if state.fingerprint != fingerprint:
        raise InputError(f"{path}: resume state of another run (different inputs or options); "
                         "delete it or run without --resume")
    return state


class _Progress:
    """A one-line progress display on stderr (only on a terminal)."""

    def __init__(self, total, enabled):
        self.total, self.enabled, self.start = total, enabled, time.perf_counter()

    def update(self, done):
        if not self.enabled:
            return
        elapsed = time.perf_counter() - self.start
        rate = done / max(elapsed, 1e-9)
        eta = (self.total - done) / max(rate, 1e-9)
        sys.stderr.write(f"\rframe {done}/{self.total}  {rate:.2f} frames/s  ETA {eta:.0f} s ")
        sys.stderr.flush()

    def close(self):
        if self.enabled:
            sys.stderr.write("\n")
