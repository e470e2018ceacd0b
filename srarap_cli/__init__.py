"""srarap: as-rigid-as-possible surface deformation with smooth rotations (linear-time SR-ARAP).

Public API: :class:`Deformer` (precompute once, solve many times), :func:`deform` (one shot),
:func:`read_mesh` / :func:`write_mesh`, :func:`load_handles`, :func:`deform_mesh`; the
:class:`Settings` every solver reads, the :class:`Solver` interface both solvers satisfy, the
:class:`StopReason` every result carries.

The package is in layers, each importing only those below it: ``cli`` (the command line) ->
``tasks`` (what a command does) -> ``io`` (files) -> ``solver`` (the paper) -> ``runtime``
(errors, signals, threads, limits). Each layer's ``__init__`` states its rule.

Names are imported on first use, so that ``import srarap_cli`` and the command line's help
do not load the numerical stack.
"""
from .runtime.lazy_names import attach_stub

_getattr, _dir, __all__ = attach_stub(__name__, __file__)


def __getattr__(name):
    if name == "__version__":  # one source, pyproject.toml; read on demand (importlib.metadata)
        from importlib.metadata import version
        return version("srarap-cli")
    return _getattr(name)


def __dir__():
    return [*_dir(), "__version__"]
