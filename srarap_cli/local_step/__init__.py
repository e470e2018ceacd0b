"""Local steps: given deformed positions, find the cell rotors.

Every method is a class built once per mesh and constraint set and follows :class:`LocalStep`.
The paper's units have their own modules: section 6.2 (rotors of constrained vertices from
their own 4x4 systems) in ``constrained_rotors``, section 6.3 (feedback) in ``feedback``, the
cells' 4x4 matrices (section 8) in ``membrane``, the one sparse solve in ``rotor_system``.
"""
from typing import ClassVar, Protocol

import numpy as np

from .arap import ArapRotorStep
from .linear import LinearRotorStep
from .linear_sym import SymmetricRotorStep
from .relax import RelaxRotorStep


class LocalStep(Protocol):
    """What a local step is.

    Built as ``Step(rest_edges, constrained_mask, alpha * A, feedback, **options)``.

    Attributes
    ----------
    bending : bool, the method's energy has the bending term (classic ARAP's has not)
    needs_stretch : bool, ``step`` uses the per-cell ``s`` (otherwise it gets None)
    """

    bending: ClassVar[bool]
    needs_stretch: ClassVar[bool]

    def step(self, S: np.ndarray, s: np.ndarray | None, R_prev: np.ndarray) -> np.ndarray:
        """New unit rotors (n, 4) from the cells' covariances ``S`` (n, 3, 3), stretch ``s``
        (n,) and the previous rotors ``R_prev`` (n, 4)."""


METHODS: dict[str, type[LocalStep]] = {
    "sr-linear": LinearRotorStep,
    "sr-linear-sym": SymmetricRotorStep,
    "sr-relax": RelaxRotorStep,
    "arap": ArapRotorStep,
}
