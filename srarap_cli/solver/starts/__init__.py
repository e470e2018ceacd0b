"""Starts: how the first iterate of a solve is made.

A start is ``start(step, initial) -> State`` with ``step`` the solve's
:class:`~srarap_cli.solver.step.LocalGlobalStep` and ``initial`` the caller's ``(positions, rotors)``
or None. :data:`STARTS` maps names to starts; :func:`register` adds one.
"""
from .registry import (
    STARTS,
    WARM_STARTS,
    register,
)

__all__ = ["STARTS", "WARM_STARTS", "register"]
