"""Starts: how the first iterate of a solve is made.

A start is ``start(step, initial) -> State`` with ``step`` the solve's
:class:`~srarap_cli.step.LocalGlobalStep` and ``initial`` the caller's ``(positions, rotors)``
or None. :data:`STARTS` maps names to starts; :func:`register` adds one.
"""
from .laplacian import laplacian
from .warm import warm

STARTS = {"laplacian": laplacian, "warm": warm}


def register(name, start):
    """Make ``start`` available as ``Deformer.solve(..., start=name)``."""
    STARTS[name] = start
