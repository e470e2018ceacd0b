"""What a local/global step needs of the solver it belongs to: the precomputed operators.

:class:`~srarap_cli.solver.deformer.Deformer` satisfies :class:`Precomputed`; the step and
the linear response program against this, not against the Deformer that builds them, so
the solver's modules import one way only (the Deformer imports them, never the reverse).
"""
from typing import Any, Protocol

import numpy as np

from .operators import CellGraph
from .rest_edges import RestEdges


class Precomputed(Protocol):
    """The per-mesh, per-constraint-set setup of a solver.

    Attributes
    ----------
    V : (n, 3) float array, rest positions
    graph : CellGraph, the cells, edges and weights
    edges : RestEdges, the rest edges and their products
    constrained : (k,) int array, constrained vertex ids
    constrained_slots : (k,) int array, where each constrained vertex sits in ``fixed``
    labels : (k,) int array, handle group of each constrained vertex
    fixed : (j,) int array, every vertex whose position is held
    poisson : the factored Poisson matrix: ``poisson.bind(targets)`` gives the global step
    local_step : the method's local step (see :mod:`srarap_cli.solver.local_step`)
    bending_weight : float, ``alpha * A`` (0 for classic ARAP)
    linear_response : the first-order response to a move of the held vertices (warm starts;
        a :class:`~srarap_cli.solver.linear_response.LinearResponse`, which is built on this)
    """

    V: np.ndarray
    graph: CellGraph
    edges: RestEdges
    constrained: np.ndarray
    constrained_slots: np.ndarray
    labels: np.ndarray
    fixed: np.ndarray

    @property
    def poisson(self) -> Any: ...

    @property
    def local_step(self) -> Any: ...

    @property
    def bending_weight(self) -> float: ...

    @property
    def linear_response(self) -> Any: ...

    def fixed_targets(self, targets: np.ndarray) -> np.ndarray:
        """Positions (j, 3) of every held vertex for the constrained ones' ``targets``."""
        ...

    def bending(self, R: np.ndarray) -> float:
        """The bending energy of rotors ``R`` (n, 4)."""
        ...
