"""What one iterate of the local/global iteration is."""
from dataclasses import dataclass, field, replace

import numpy as np


@dataclass
class State:
    """One iterate: positions, the rotors that go with them, and what the next step needs.

    Attributes
    ----------
    positions : (n, 3) float array
    rotors : (n, 4) float array, unit quaternions (w, x, y, z) of the vertex cells
    covariances : (n, 3, 3) float array, ``S_i`` of the positions (the next local step's
        input); (0, 3, 3) in a settled state (:meth:`settled`)
    stretch : (n,) float array or None, per-cell ``s_i`` (only for steps that use it; None in
        a settled state)
    stretch_total : float, ``sum_i s_i``
    membrane, bending : float, the energy terms of (positions, rotors)
    iteration : int, 0 for a start
    handed_over : bool, the start a solver built for its driver, which may drop its arrays
        once it has moved past it (:meth:`release`)
    """

    positions: np.ndarray
    rotors: np.ndarray
    covariances: np.ndarray
    stretch: np.ndarray | None
    stretch_total: float
    membrane: float
    bending: float
    iteration: int = 0
    handed_over: bool = field(default=False, repr=False, compare=False)

    def release(self) -> None:
        """Drop a handed-over start's arrays; any other state is left as it is.

        The solver that built the start and the call that passes it to the driver both hold
        it until the solve ends, so without this its arrays outlive their use (1.2M-vertex
        cylinder: 0.17 GB through the whole solve, 0.15 GB of its peak)."""
        if self.handed_over:
            self.positions, self.rotors, self.covariances, self.stretch = _EMPTY

    def settled(self) -> "State":
        """This state without its covariances and per-cell stretch: an iterate past its local
        step, kept for its positions, rotors and energy (0.1 GB less at 1.2M vertices)."""
        return replace(self, covariances=_EMPTY[2], stretch=None)

    @property
    def total(self) -> float:
        return self.membrane + self.bending


_EMPTY = (np.empty((0, 3)), np.empty((0, 4)), np.empty((0, 3, 3)), None)
