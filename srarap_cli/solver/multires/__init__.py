"""Multiresolution deformation (paper section 7): subset simplification, coarse solve,
harmonic rotor transfer, one fine Poisson solve.

Names are imported on first use, so that reading the settings (``size``) does not load the
simplifier or the solver.
"""
from ...runtime.lazy_names import attach_stub

__getattr__, __dir__, __all__ = attach_stub(__name__, __file__)
