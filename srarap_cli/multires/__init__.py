"""Multiresolution deformation (paper section 7): subset simplification, coarse solve,
harmonic rotor transfer, one fine Poisson solve."""
from .deformer import MultiresDeformer
from .simplify import CoarseMesh, simplify_to_subset
from .size import coarse_size, parse_size

__all__ = ["CoarseMesh", "MultiresDeformer", "coarse_size", "parse_size", "simplify_to_subset"]
