"""Anderson acceleration of the local/global iteration (Peng, Deng, Zhang, Liu 2018).

The plain iteration is a fixed-point map ``x -> G(x)`` on the joint state ``x`` = (positions,
rotors): the local step gives rotors from positions (and the previous rotors, through feedback
and the constrained rotors of section 6.2), the global step positions from rotors. Anderson's
type-II update mixes the last ``m`` values of ``G`` with the weights that best cancel the
residuals ``f = G(x) - x`` (a small least-squares problem), which extrapolates along the
slowly converging directions that make the plain iteration need thousands of steps.

The weights minimize the *rotor* part of ``f`` alone. The positions of ``G(x)`` are an affine
function of its rotors (one Poisson solve), so the rotor residual holds all the information,
while counting the position residual too weighted most what the Poisson solve amplifies (the
smooth components). Measured against the joint residual (positions scaled to the mean rest
edge): iterations to 0.1% of the minimum on the cylinder 20 -> 14, bust 17 -> 16, Spot 36 ->
30, bar twisted 135 degrees 8 -> 6, 100k bar (coarse-to-fine) 36 -> 21; one loss, the 46k Spot
(coarse-to-fine) 18 -> 22, whose stop came later (42 -> 75 iterations) but 15 times closer to
the minimum (3e-4 -> 2e-5 above it).

Only rotors are mixed: a candidate's positions are the Poisson solve of its normalized mixed
rotors, one solve per candidate, as many as mixing the values of ``G``'s positions needed
(those came from a solve each). A coarse-grid correction adds to the mixed rotors before that
solve, so a corrected candidate costs no second one, and the history holds 8n floats per
difference instead of 11n. Iterations to 0.1% and to the stop on the benchmark cases were the
same within one either way (cylinder stop 24 -> 23, Spot 61 -> 58).

Energy safeguard: an accelerated iterate is kept only if its energy, with the rotors the
local step gives it, is not above the last accepted one (up to the rounding of the energy
evaluation); otherwise the plain step ``G(x)`` is taken. The local step that tests a
candidate is the one the next iteration needs anyway, so an accepted acceleration costs a
few vector operations; a rejected one costs a wasted local step and Poisson solve.

The history is kept on a rejection (Peng et al. restart it). Every stored pair is a true
``(x, G(x))``, the plain step included, so nothing in it is invalid; restarting left a
one-difference history whose secant step overshot again, and runs fell into long
reject/plain alternations (Spot: 90 iterations at 0.4-0.2% above the minimum, 137
iterations to 0.1% instead of 36 when the history is kept).

Near the end of a run, when the energy is within about 1e-8 of its minimum, most candidates
are rejected: there the energy differences are at the level of the evaluation's rounding and
of the gap between the fixed point of ``G`` and the energy's minimum (the normalized linear
local step is not an exact minimization; plain steps from a lower iterate even raise the
energy by ~1e-11 relative). The stopping test ends runs well before that.

The same gap can show earlier: the fixed point of ``G`` lies slightly above the energy's
minimum (2e-5 relative on a tube twisted by 150 degrees), and an accelerated iterate may land
below it. From there every candidate heading to the fixed point raises the energy and is
rejected, and the plain steps taken instead climb to the fixed point's energy (logged as
``fallback`` rows whose energy rises). The result is still the plain iteration's fixed point
(2.9e-8 of the diagonal from it there), but those steps cost two local steps each.
"""
from functools import partial
from typing import Any

import numpy as np

from ...runtime.parallel import blocks, fill, map_blocks, ordered_sum
from ..quaternion import align_hemisphere, normalize
from ..state import State
from ..step import LocalGlobalStep
from .monitor import Monitor

# history length: on the benchmark cases 10 reached 0.1% of the minimum in as few or fewer
# iterations than 3, 6 or 15 (Spot: 36 against 71, 44 and 34)
DEFAULT_DEPTH = 10
# Relative slack of the energy comparison: the membrane energy from covariances cancels,
# with rounding near 1e-16 of the total stretch; a candidate whose energy rises by less
# than that is not worse, and rejecting it would restart the history for nothing.
ROUNDING = 1e-13
HISTORY_DTYPE = np.float32


class AndersonMixer:
    """Type-II Anderson mixing with a bounded history (``depth`` differences).

    Differences are kept normalized in ring buffers with their Gram matrix updated one row
    at a time, so a mix costs ``O(depth * len(x))``. The buffers hold single precision
    (half the memory: 0.24 GB at 738k vertices), every product with them sums in double: the
    mixing then works with differences rounded to 6e-8 of their size, and its Gram matrix
    and weights are those of the rounded differences to double precision.

    Parameters
    ----------
    depth : int >= 1

    Examples
    --------
    >>> A = np.array([[0.5, 0.2], [0.1, 0.3]])  # a linear contraction, fixed point 0
    >>> mixer, x = AndersonMixer(2), np.array([1.0, 1.0])
    >>> for _ in range(5):  # plain iteration would still be at |x| ~ 0.4 ** 5
    ...     g = A @ x
    ...     x = mixer.mix(g, g - x)
    >>> bool(np.abs(x).max() < 1e-15)
    True
    """

    def __init__(self, depth: int = DEFAULT_DEPTH) -> None:
        self.depth = depth
        self.reset()

    def reset(self) -> None:
        self._dF: np.ndarray | None = None
        self._dG: np.ndarray | None = None
        self._gram: np.ndarray | None = None
        self._f: np.ndarray | None = None
        self._g: np.ndarray | None = None
        self._count = self._next = 0

    def mix(self, g: np.ndarray, f: np.ndarray) -> np.ndarray:
        """The next iterate from ``g = G(x)`` and the residual ``f`` (1-D arrays); ``g``
        itself (the same object) when there is no history yet.

        ``f`` is ``G(x) - x`` or any fixed linear function of it (a part of it, a weighting):
        the mixing weights minimize its norm, and ``g`` is mixed with them."""
        if self._f is not None:
            self._push(f - self._f, g - self._g)
        self._f, self._g = f, g
        k = self._count
        if k == 0:
            return g
        assert self._gram is not None and self._dF is not None and self._dG is not None
        gram = self._gram[:k, :k].copy()
        # the columns are unit vectors: a relative ridge keeps near-dependent ones solvable
        gram[np.diag_indices(k)] += 1e-10
        theta = np.linalg.solve(gram, _products(self._dF[:k], f))
        out = np.empty_like(g)
        map_blocks(partial(_mixed_block, g, theta, self._dG[:k], out), blocks(g.size, "values"))
        return out

    def _push(self, df, dg):
        scale = np.linalg.norm(df)
        if not scale > 0:
            return
        if self._dF is None:
            self._dF = np.empty((self.depth, df.size), dtype=HISTORY_DTYPE)
            self._dG = np.empty((self.depth, dg.size), dtype=HISTORY_DTYPE)
            self._gram = np.empty((self.depth, self.depth))
        assert self._dG is not None and self._gram is not None  # allocated with _dF
        i = self._next
        fill(lambda part: part / scale, self._dF[i], df, kind="values")
        fill(lambda part: part / scale, self._dG[i], dg, kind="values")
        self._count = min(self._count + 1, self.depth)
        row = _products(self._dF[:self._count], self._dF[i])
        self._gram[i, :self._count] = row
        self._gram[:self._count, i] = row
        self._next = (i + 1) % self.depth


def _products(rows, v):
    """``rows @ v`` summed in double precision, whatever the storage of ``rows``: by blocks
    of columns, their partial sums added in block order (the same at any thread count)."""
    return ordered_sum(partial(_columns_product, rows, v), blocks(v.size, "values"),
                       np.zeros(rows.shape[0]))


def _mixed_block(g, theta, dG, out, cols):
    """``out[cols] = g[cols] - theta . dG[:, cols]`` (einsum sums in double without a
    double copy of the history)."""
    out[cols] = g[cols] - np.einsum("i,ij->j", theta, dG[:, cols], dtype=float)


def _columns_product(rows, v, cols):
    """``rows[:, cols] @ v[cols]`` in double precision."""
    return np.einsum("ij,j->i", rows[:, cols], v[cols], dtype=float)


def anderson_iteration(step: LocalGlobalStep, state: State, monitor: Monitor,
                       depth: int | None = None, correction: Any = None) -> State:
    """Accelerated iteration with an energy safeguard.

    Logs one row per accepted iterate: its positions with the rotors the local step gives
    them (the pair returned). The row's ``step`` says where the iterate came from:
    ``anderson`` (mixed and accepted), ``corrected`` (mixed, or the plain step where there
    is no history yet, plus ``correction``; accepted), ``plain`` (no history yet) or
    ``fallback`` (the candidate raised the energy: plain step taken instead).

    Parameters
    ----------
    step : LocalGlobalStep
    state : State, the start (released once it is left behind: :meth:`State.release`)
    monitor : Monitor
    depth : int, Anderson history length (default DEFAULT_DEPTH)
    correction : optional, adds to the rotors of the iterates it is ``due`` for (numbered
        from 1): ``correction(state, residual)`` gives (n, 4) or None from an iterate and
        its step's rotor residual (a
        :class:`~srarap_cli.solver.multires.correction.CoarseCorrection`)

    Returns
    -------
    State, settled (:meth:`State.settled`: positions, rotors and energy)
    """
    mixer = AndersonMixer(depth or DEFAULT_DEPTH)
    x = state
    current = step.with_rotors(x, step.local(x)).settled()
    stop = monitor.record(current, kind="start")
    while not stop:
        R = current.rotors
        # mixing needs one sign per rotor across the history: compare on x's hemispheres
        g = align_hemisphere(R, x.rotors)
        residual = g - x.rotors
        flat = g.ravel()
        mixed = mixer.mix(flat, residual.ravel())
        kind = "anderson" if mixed is not flat else None
        mixed = mixed.reshape(g.shape)
        delta = None
        if correction is not None and correction.due(x.iteration + 1):
            delta = correction(x, residual)
        if delta is not None:
            kind, mixed = "corrected", mixed + delta
        if kind:
            R_new = align_hemisphere(normalize(mixed, R), R)
            candidate, tried = _local(step, step.positions(R_new), R_new, x.iteration + 1)
            if tried.total > current.total + ROUNDING * abs(tried.stretch_total):
                kind = "fallback"
        if kind in (None, "fallback"):
            candidate, tried = _local(step, step.positions(R), R, x.iteration + 1)
        stop = monitor.record(tried, current, kind=kind or "plain")
        x.release()
        x, current = candidate, tried
    return current


def _local(step, P, R, iteration):
    """The iterate (P, R) and the same positions with the rotors its local step gives, both
    settled (:meth:`State.settled`): nothing reads their covariances after that local step,
    which the next candidate's would otherwise run beside (1.2M-vertex cylinder: peak 5.10-5.13
    -> 5.02-5.05 GB, three runs or more each)."""
    candidate = step.state(P, R, iteration=iteration, energy=False)
    tried = step.with_rotors(candidate, step.local(candidate))
    return candidate.settled(), tried.settled()
