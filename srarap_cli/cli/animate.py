"""``srarap animate``: keyframed handles -> one deformed mesh per frame."""
from typing import Any

import click

from ..runtime.stages import heard_by
from ..tasks.animate import MAX_FRAMES, AnimateJob, run_animation
from .common import EarlyWarnings, FiniteFloat, cache_option, guarded, report, with_verbosity
from .options import StrictCommand, settings_options
from .progress import FrameProgress


@click.command("animate", cls=StrictCommand)
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
    job = AnimateJob(mesh, handles, pattern, overrides, frames=frames, fps=fps,
                     max_frames=max_frames, iters_per_frame=iters_per_frame,
                     keep_unconverged=keep_unconverged, log=log, resume=resume, cache=cache)
    progress, early = FrameProgress(enabled=verbosity != 0), EarlyWarnings()
    try:
        with heard_by(progress.stage if (verbosity or 0) >= 2 else None):
            done = run_animation(job, on_frame=progress.frame, on_warnings=early)
    finally:
        progress.close()
    report(verbosity, warnings=early.rest(done.warnings),
           details=done.last.report_lines() if done.last else [],
           summary=done.summary(pattern, iters_per_frame))
    if done.exit_code(iters_per_frame):
        raise SystemExit(done.exit_code(iters_per_frame))
