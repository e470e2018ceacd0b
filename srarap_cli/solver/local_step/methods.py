"""The local steps by name (loaded on first use) and the protocol they follow."""
from __future__ import annotations

import importlib
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, ClassVar, Protocol

if TYPE_CHECKING:
    import numpy as np


class LocalStep(Protocol):
    """What a local step is.

    Built as ``Step(rest_edges, constrained_mask, alpha * A, feedback, **options)``.

    Attributes
    ----------
    bending : bool, the method's energy has the bending term (classic ARAP's has not)
    needs_stretch : bool, ``step`` uses the per-cell ``s`` (otherwise it gets None)
    near_minimum : bool, the local/global iteration's fixed point is the energy's minimum or
        close to it, so the energy's derivatives say how it moves (warm starts add their
        first-order response to a move of the handles only then)
    """

    bending: ClassVar[bool]
    needs_stretch: ClassVar[bool]
    near_minimum: ClassVar[bool]

    def __init__(self, edges: Any, constrained: np.ndarray, alpha_area: float,
                 feedback: float, **options: Any) -> None: ...

    def step(self, S: np.ndarray, s: np.ndarray | None, R_prev: np.ndarray,
             forcing: float = 0.0) -> np.ndarray:
        """New unit rotors (n, 4) from the cells' covariances ``S`` (n, 3, 3), stretch ``s``
        (n,) and the previous rotors ``R_prev`` (n, 4). A step that solves a linear system
        iteratively may stop once its residual is ``forcing`` times that of ``R_prev``
        (0: to rounding level); closed-form steps ignore it."""


class _Methods(Mapping):
    """Method name -> local step class, each module imported on first use (the names are
    needed by the command line's options long before any solve)."""

    def __init__(self, where):
        self._where = where

    def __getitem__(self, name):
        module, cls = self._where[name]
        return getattr(importlib.import_module(module, __package__), cls)

    def __contains__(self, name):
        return name in self._where

    def __iter__(self):
        return iter(self._where)

    def __len__(self):
        return len(self._where)


METHODS: Mapping[str, type[LocalStep]] = _Methods({
    "sr-linear": (".linear", "LinearRotorStep"),
    "sr-linear-sym": (".linear_sym", "SymmetricRotorStep"),
    "sr-relax": (".relax", "RelaxRotorStep"),
    "arap": (".arap", "ArapRotorStep"),
})
