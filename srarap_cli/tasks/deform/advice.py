"""What ``srarap deform`` says of a finished solve: its one summary line, what to try when it
did not converge, and ``-v``'s pointer to ``--cache``."""
import math

from ...runtime import signals
from ...runtime.clock import elapsed
from ...solver.multires.size import AUTO_THRESHOLD
from ...solver.result import DeformResult
from ...solver.settings import Settings
from ...solver.stop import StopReason


def wall_seconds(result: DeformResult) -> float:
    """The process's wall seconds for a summary (the solve's own when srarap runs inside
    another program, whose clock did not start with srarap)."""
    return elapsed() if signals.OWNED else result.seconds


#: seconds of simplification from which ``-v`` says that ``--cache`` would skip it
SLOW_SIMPLIFY = 10.0


def cache_hint(result: DeformResult, cache: str | None) -> list[str]:
    """The ``-v`` line that points a user of a large mesh at ``--cache`` (the simplification
    is the longest stage that runs on one core)."""
    part = result.multires
    seconds = part.stages.get("simplify", 0.0) if part is not None else 0.0
    if cache is not None or part is None or part.cache_hit or seconds < SLOW_SIMPLIFY:
        return []
    return [f"srarap: multires: the simplification took {seconds:.1f} s; --cache DIR keeps "
            "the coarse mesh, and a rerun of this mesh skips it"]


def summary_line(result: DeformResult, opts: Settings, out: str | None) -> str:
    """``srarap deform``'s one summary line (``out``: what was written, else None): why the
    solve stopped (at full resolution), the full-resolution and coarse iterations apart, the
    energy, the process's wall seconds."""
    coarse = f" (+ {result.coarse_iterations} coarse)" if result.coarse_iterations else ""
    e = result.energies()
    energy = (f"energy {e['total']:.6g} (membrane {e['membrane']:.6g}, bending "
              f"{e['bending']:.6g})")
    reason = result.stop_reason
    part = result.multires
    if result.approximate and part is not None:
        state = (f"approximate (multires transfer: coarse solve "
                 f"{'converged' if part.converged else 'NOT converged'} in "
                 f"{part.iterations} iterations, none at full resolution)")
        energy = f"full-resolution {energy}, {part.start_energy['total']:.6g} at the start"
    elif reason is StopReason.CONVERGED:
        state = f"converged in {result.iterations} full-resolution iterations{coarse}"
    elif reason is StopReason.ITERATIONS_RUN:
        state = f"ran the {result.iterations} iterations asked (tol 0){coarse}"
    else:
        state = (f"NOT converged after {result.iterations} full-resolution iterations{coarse} "
                 f"({reason}: {result.stop_detail}; {_advice(result, opts)})")
    return (f"srarap deform: {state}; {energy}; {wall_seconds(result):.2f} s; "
            + (f"wrote {out}" if out else "no mesh written (--keep-unconverged writes it)"))


def _advice(result, opts):
    """What to try after a run that stopped unconverged, from why it stopped."""
    if result.stop_reason is StopReason.TIME_LIMIT:
        return f"stopped by --time-limit {opts.time_limit:g}: allow more time"
    tips = [f"raise --max-iter (was {opts.max_iter})"]
    n = len(result.positions)
    if opts.multires == "off" and n >= AUTO_THRESHOLD:
        tips.append(f"--multires auto (a coarse solve starts the {n} vertices closer)")
    if opts.accel == "none":
        tips.append("use --accel anderson")
    if opts.start == "laplacian":
        tips.append("--start harmonic")
    last = result.log[-1]["rel_change"]
    if not math.isnan(last):
        tips.append(f"or loosen --tol (the last change was {last:.2g})")
    return "try: " + ", ".join(tips)
