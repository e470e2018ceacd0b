"""Multiresolution deformation (paper section 7): subset simplification, coarse solve,
harmonic rotor transfer, one fine Poisson solve.

Names are imported on first use, so that reading the settings (``size``) does not load the
simplifier or the solver.
"""
import importlib
from typing import Any

_WHERE = {"MultiresDeformer": "deformer",
          "CoarseMesh": "simplify", "simplify_to_subset": "simplify",
          "coarse_size": "size", "parse_size": "size"}

__all__ = ["CoarseMesh", "MultiresDeformer", "coarse_size", "parse_size",
           "simplify_to_subset"]


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
