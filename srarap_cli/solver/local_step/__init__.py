"""Local steps: given deformed positions, find the cell rotors.

Every method is a class built once per mesh and constraint set and follows :class:`LocalStep`.
The paper's units have their own modules: section 6.2 (rotors of constrained vertices from
their own 4x4 systems) in ``constrained_rotors``, section 6.3 (feedback) in ``feedback``, the
cells' 4x4 matrices (section 8) in ``membrane``, the one sparse solve in ``rotor_system``.
"""
from .methods import (
    METHODS,
    LocalStep,
)

__all__ = ["LocalStep", "METHODS"]
