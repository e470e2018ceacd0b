"""What one iterate of the local/global iteration is."""
from dataclasses import dataclass

import numpy as np


@dataclass
class State:
    """One iterate: positions, the rotors that go with them, and what the next step needs.

    Attributes
    ----------
    positions : (n, 3) float array
    rotors : (n, 4) float array, unit quaternions (w, x, y, z) of the vertex cells
    covariances : (n, 3, 3) float array, ``S_i`` of the positions (the next local step's input)
    stretch : (n,) float array or None, per-cell ``s_i`` (only for steps that use it)
    stretch_total : float, ``sum_i s_i``
    membrane, bending : float, the energy terms of (positions, rotors)
    iteration : int, 0 for a start
    """

    positions: np.ndarray
    rotors: np.ndarray
    covariances: np.ndarray
    stretch: np.ndarray | None
    stretch_total: float
    membrane: float
    bending: float
    iteration: int = 0

    @property
    def total(self) -> float:
        return self.membrane + self.bending
