"""Local steps: given deformed positions, find the cell rotors.

Every method is a class built once per mesh and constraint set,
``Step(rest_edges, constrained_mask, alpha * A, feedback, **options)``, whose ``step(S, s, R_prev)``
returns new unit rotors from the cells' covariances (see ``membrane``). ``bending`` says
whether the method's energy has the bending term, ``needs_stretch`` whether ``step`` uses the
per-cell ``s`` (otherwise it gets None).
"""
from .arap import ArapRotorStep
from .linear import LinearRotorStep
from .linear_sym import SymmetricRotorStep
from .relax import RelaxRotorStep

METHODS = {
    "sr-linear": LinearRotorStep,
    "sr-linear-sym": SymmetricRotorStep,
    "sr-relax": RelaxRotorStep,
    "arap": ArapRotorStep,
}
