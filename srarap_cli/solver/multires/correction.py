"""Coarse-grid correction of the full-resolution iteration (a full approximation scheme).

Started from the coarse solution, the full-resolution iteration still converges slowly in
the smooth components of its error: the coarse mesh's minimum differs from the full mesh's
in exactly those, and the local/global step (accelerated or not) removes them a little per
step (0.98 per step at 738k vertices). The coarse mesh can solve for them cheaply, if its
problem is told where the full one stands: with ``y0`` the iterate's rotors at the coarse
vertices and ``r`` its full-resolution step residual averaged over each coarse vertex's cell,
the coarse fixed point of

    y = G_c(y) - tau,    tau = G_c(y0) - y0 - r

(``G_c`` the coarse local/global step) starts where the full iteration stands, its first step
is the averaged full step, and the rest is what the coarse mesh predicts the full iteration
would still do. That prediction beyond one step, carried back to every vertex of the cell,
is the correction. At a full-resolution fixed point ``r = 0`` and ``y0`` is already the coarse
fixed point: the correction vanishes, so it never moves the answer, only the way to it.

Measured on the 46k Spot (coarse 5,000 vertices), iterations to 1e-3 / 1e-4 / 1e-5 above
the minimum and to the stop: 22 / 63 / never / 75 without the correction, 5 / 11 / 16 / 19
with it every iteration, 7 / 12 / 20 / 25 every second iteration.
"""
import numpy as np

from ..drivers.anderson import AndersonMixer
from ..group_rotations import label_sum
from ..quaternion import align_hemisphere, normalize
from ..state import State
from ..step import LocalGlobalStep

#: coarse steps per correction (Anderson-mixed); 10 took the 46k Spot to 1e-4 in 24
#: iterations instead of 16 (a correction every third iteration)
COARSE_STEPS = 20
#: ... or, when a coarser mesh corrects the coarse iteration in turn, this many: each step
#: then does more and costs more. Full-resolution iterations and their seconds to the stop,
#: 10 steps against 6 (default settings, same process): 184k Spot 15, 14.1 s -> 15, 11.7 s;
#: 500k bar twisted 90 degrees 23, 52.8 s -> 23, 40.0 s; 738k Spot 17, 47.0-53.9 s -> 17,
#: 39.7-40.4 s; 1.2M cylinder 22, 130 s -> 23, 108 s. Fewer (3, 4) or a correction every
#: iteration won on some meshes and lost on others (500k bar, 4 every iteration: 26, 57.7 s)
NESTED_STEPS = 6
#: the coarse iteration stops early once no rotor component changes by more than this
COARSE_SETTLED = 1e-9
#: a correction costs about COARSE_STEPS coarse steps, ``COARSE_STEPS * m / n`` full ones:
#: every iteration when the full mesh has at least this many times the coarse vertices (a
#: correction then costs under about two thirds of a full step), every second one below
#: (46k Spot, 9 times: 5.4 s to the stop against 6.6 s every iteration)
EVERY_STEP_RATIO = 30


class CoarseCorrection:
    """The coarse mesh's correction to a full-resolution iterate's rotors.

    Parameters
    ----------
    coarse_step : LocalGlobalStep of the coarse mesh, for the coarse targets
    coarse_vertices : (m,) int array, full-mesh ids of the coarse vertices
    nearest : (n,) int array, each vertex's coarse vertex (index into ``coarse_vertices``,
        -1 for none): the cells that average residuals and receive corrections
    inner : CoarseCorrection of the coarse mesh by a coarser one, optional: corrects the
        coarse iteration the same way (the levels of a multiresolution hierarchy)

    Attributes
    ----------
    every : int, a correction every ``every`` iterations
    """

    def __init__(self, coarse_step: LocalGlobalStep, coarse_vertices: np.ndarray,
                 nearest: np.ndarray, inner: "CoarseCorrection | None" = None) -> None:
        self.step, self.inner = coarse_step, inner
        self.vertices = np.asarray(coarse_vertices)
        self.nearest = np.asarray(nearest)
        self._in_cell = self.nearest >= 0
        self._cell = self.nearest[self._in_cell]
        size = np.bincount(self._cell, minlength=self.vertices.size)
        self._weight = 1.0 / np.maximum(size, 1)
        self.every = 1 if self.nearest.size >= EVERY_STEP_RATIO * self.vertices.size else 2

    def due(self, iteration: int) -> bool:
        """Whether the iterate numbered ``iteration`` gets a correction."""
        return iteration % self.every == 0

    def __call__(self, state: State, residual: np.ndarray) -> np.ndarray | None:
        """The correction (n, 4) to add to the rotors of the iterate after ``state``.

        Parameters
        ----------
        state : State, the iterate (its rotors are what the correction reads)
        residual : (n, 4) float array, its step's rotors minus its rotors (same hemispheres)

        Returns
        -------
        (n, 4) float array, zero outside the cells; None when the coarse iteration failed
        """
        return self.of_rotors(state.rotors, residual)

    def of_rotors(self, rotors: np.ndarray, residual: np.ndarray) -> np.ndarray | None:
        """The correction from an iterate's rotors (n, 4) alone (see :meth:`__call__`); a
        nested level's iterates have no positions."""
        y0 = rotors[self.vertices]
        r = self._average(residual)
        tau = self._map(y0) - y0 - r
        y = self._fixed_point(y0, tau, y0 + r)
        if not np.isfinite(y).all():
            return None
        out = np.zeros_like(rotors)
        out[self._in_cell] = (y - y0 - r)[self._cell]
        return out

    def _average(self, values):
        sums = label_sum(values[self._in_cell], self._cell, self.vertices.size)
        return sums * self._weight[:, None]

    def _map(self, y):
        """The coarse step's rotors from rotors ``y``, on the hemispheres of ``y``."""
        state = self.step.state(self.step.positions(y), y, energy=False)
        return align_hemisphere(self.step.local(state), y)

    def _fixed_point(self, y, tau, first):
        """Iterate ``y <- G_c(y) - tau`` from ``y`` whose first value ``first`` is known (the
        map at ``y`` is what ``tau`` was made from)."""
        mixer = AndersonMixer()
        for k in range(1, (COARSE_STEPS if self.inner is None else NESTED_STEPS) + 1):
            g = first if k == 1 else self._map(y) - tau
            f = g - y
            mixed = mixer.mix(g.ravel(), f.ravel()).reshape(y.shape)
            if self.inner is not None and self.inner.due(k):
                delta = self.inner.of_rotors(y, f)
                mixed = mixed if delta is None else mixed + delta
            new = normalize(mixed, y)
            settled = np.abs(new - y).max(initial=0.0) <= COARSE_SETTLED
            y = new
            if settled:
                break
        return y
