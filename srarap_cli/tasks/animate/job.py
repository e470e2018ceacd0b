"""One animation, files in and files out: the path ``srarap animate`` takes, beside the job
runner of ``deform`` and ``batch`` (:mod:`.job`), with the same checks, warnings, ``strict``
and failures (the command line maps them to exit codes alike).

Each frame is committed with the resume state after it, so that ``resume`` continues an
interrupted run and gives the same files as an uninterrupted one.
"""
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ...io.handles import load_handles, referenced_files
from ...io.mesh import format_mesh, frame_formatter
from ...io.solve_log import LOG_FORMATS, format_log
from ...runtime import exit_codes
from ...runtime.commit import commit_files
from ...runtime.encoding import utf8
from ...runtime.errors import InputError
from ...runtime.limits import check_solve
from ...runtime.warning_codes import note
from ...solver.result import DeformResult
from ...solver.settings import resolve
from ...solver.stop import StopReason
from ..fingerprint import fingerprint
from ..preflight import check_output_path, read_any_mesh, refuse_overwrite
from .frame_files import MAX_FRAMES, check_pattern, frame_count, frames_on_disk, remove_stale, suffix
from .sequence import FRAME_FIELDS, Animator, FrameState, run_inputs, unreached_keys

#: the resume state, in the frames' folder
STATE_NAME = ".srarap-animate-state.npz"


@dataclass(frozen=True)
class AnimateJob:
    """What one animation reads and writes.

    Attributes
    ----------
    mesh, handles : str, input paths (the handle file with keyframes)
    pattern : str, the frames' file pattern with one frame-number field (``f_{:04d}.obj``)
    settings : mapping, solver settings over the handle file's
    frames : int, optional, the number of frames (default: up to the last key)
    fps : float, optional, frames per second for keys given by time
    max_frames : int, the most frames allowed
    iters_per_frame : int, optional, a fixed budget: every frame written, converged or not
    keep_unconverged : bool, write a frame that did not converge and go on
    log : str, optional, the per-frame log (.csv/.jsonl)
    resume : bool, continue after the last frame an interrupted run wrote
    cache : str, optional, folder of simplified meshes (multiresolution)
    """

    mesh: str
    handles: str
    pattern: str
    settings: Mapping[str, Any] = field(default_factory=dict)
    frames: int | None = None
    fps: float | None = None
    max_frames: int = MAX_FRAMES
    iters_per_frame: int | None = None
    keep_unconverged: bool = False
    log: str | None = None
    resume: bool = False
    cache: str | None = None


@dataclass
class AnimationOutcome:
    """How an animation ended.

    Attributes
    ----------
    rows : list of dict, one per frame solved (FRAME_FIELDS), the one it stopped at last
    n_frames : int, frames asked
    first : int, the first frame this run solved (after those a resumed run kept)
    stopped : int or None, the frame that did not converge and stopped the sequence
    warnings : list of str
    last : DeformResult or None, the last frame's solve
    """

    rows: list[dict]
    n_frames: int
    first: int
    stopped: int | None
    warnings: list[str]
    last: DeformResult | None

    @property
    def unconverged(self) -> int:
        return sum(not r["converged"] for r in self.rows)

    def exit_code(self, budget: int | None) -> int:
        """3 when a frame did not converge, unless every frame had a fixed ``budget`` of
        iterations (``--iters-per-frame``); else 0."""
        return exit_codes.NOT_CONVERGED if self.unconverged and budget is None else exit_codes.OK

    def summary(self, pattern: str, budget: int | None) -> str:
        """``srarap animate``'s one summary line: frames converged, the median iterations,
        the rate, what was written, and where and why the sequence stopped."""
        rows, first, stopped, result = self.rows, self.first, self.stopped, self.last
        last = self.n_frames - 1 if stopped is None else stopped - 1
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
        if stopped is not None and result is not None:
            reason = result.stop_reason
            limit = "--time-limit" if reason is StopReason.TIME_LIMIT else "--max-iter"
            head += (f"; STOPPED at frame {stopped}: not converged in {result.iterations} "
                     f"iterations ({reason}: {result.stop_detail}; raise {limit}, or "
                     "--keep-unconverged writes it and goes on)")
        return head


def run_animation(job: AnimateJob, on_frame: Callable[[int, int], None] | None = None,
                  on_warnings: Callable[[list[str]], None] | None = None) -> AnimationOutcome:
    """Run ``job``; raise on failure (InputError, OutputError, UsageProblem, ...).
    ``on_frame(done, total)`` is called after each frame is committed (a progress display);
    ``on_warnings`` hears the warnings as they are known, before the setup and the frames."""
    folder = check_pattern(job.pattern)
    if job.log is not None:
        check_output_path(job.log, LOG_FORMATS, "log")
    source, _ = read_any_mesh(job.mesh)
    check_solve(job.mesh, len(source.vertices))
    constraints = load_handles(job.handles, source.vertices, fps=job.fps)
    n_frames = frame_count(job.frames, constraints.last_key_frame, job.max_frames, job.handles,
                           job.fps)
    state_path = os.path.join(folder, STATE_NAME)
    # only existing files can be inputs: the folder is listed, the frames never enumerated
    refuse_overwrite([p for k, p in frames_on_disk(job.pattern).items() if k < n_frames]
                     + [job.log], mesh=job.mesh, handles=job.handles,
                     others=[("resume state", state_path)])
    opts = resolve(constraints.solver, dict(job.settings))
    run_id = fingerprint(run_inputs(source, (job.handles, *referenced_files(job.handles))),
                         opts, {"frames": n_frames, "fps": job.fps, "pattern": job.pattern,
                                "iters_per_frame": job.iters_per_frame})
    state = _resume_state(state_path, run_id) if job.resume else None
    # what every frame's file loses, and keys no frame shows: said once, errors under strict
    lost = format_mesh(source, suffix(job.pattern))[1] + unreached_keys(
        constraints, n_frames, job.fps, job.handles)
    animator = Animator(source, constraints, opts, cache=job.cache, name=job.mesh,
                        known=lost, on_warnings=on_warnings)
    frame_bytes = frame_formatter(source, suffix(job.pattern))

    def write_frame(f, positions, st):
        commit_files([(job.pattern.format(f), frame_bytes(positions)),
                      (state_path, st.to_bytes())])
        if on_frame is not None:
            on_frame(f + 1, n_frames)

    budget = job.iters_per_frame is not None
    final = animator.run(n_frames, max_iter=job.iters_per_frame,
                         stop_unconverged=not (budget or job.keep_unconverged),
                         state=state, on_frame=write_frame, fingerprint=run_id)
    rows = (final.rows if final is not None else []) + (
        [animator.stopped_row] if animator.stopped_at is not None else [])
    notes = animator.warnings + _finish(job, rows, animator.stopped_at, state_path,
                                               n_frames)
    return AnimationOutcome(rows, n_frames, 0 if state is None else state.frame + 1,
                            animator.stopped_at, notes, animator.last_result)


def _finish(job, rows, stopped, state_path, n_frames):
    """Write the log; drop the resume state of a finished run; remove the frames an earlier
    run left from the frame this one stopped at, or past its last frame (an earlier run of
    more frames: ``render 'f_{}.obj'`` would draw both runs' frames as one animation).
    Returns the warnings to say."""
    if job.log is not None:
        text = format_log(rows, os.path.splitext(job.log)[1].lower(), FRAME_FIELDS)
        commit_files([(job.log, utf8(text))])
    if stopped is None and os.path.exists(state_path):
        os.unlink(state_path)
    first = n_frames if stopped is None else stopped
    removed = remove_stale(job.pattern, first)
    return [note("stale-frames", f"removed {removed} later frame(s) of an earlier run under "
                 f"{job.pattern!r} (frame {first} on), so that the frames on disk are this "
                 "run's")] if removed else []


def _resume_state(path, key):
    if not os.path.exists(path):
        return None
    state = FrameState.from_file(path)
    if state.fingerprint != key:
        raise InputError(f"{path}: resume state of another run (different inputs or options); "
                         "delete it or run without --resume")
    return state
