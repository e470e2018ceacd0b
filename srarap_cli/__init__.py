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
import importlib

_WHERE = {"Comparison": "tasks.comparison", "CompareJob": "tasks.comparison",
          "Constraints": "io.handles", "DeformResult": "solver.result",
          "Deformer": "solver.deformer", "Mesh": "io.mesh", "MeshFormat": "io.mesh.formats",
          "MultiresPart": "solver.result", "Settings": "solver.settings",
          "Solver": "solver.interface", "StopReason": "solver.stop",
          "as_constraints": "io.handles", "compare_meshes": "tasks.comparison",
          "deform": "tasks.api", "deform_mesh": "tasks.pipeline", "load_handles": "io.handles",
          "make_deformer": "solver.oneshot", "read_mesh": "io.mesh",
          "register_format": "io.mesh.formats", "resolve": "solver.settings",
          "run_compare": "tasks.comparison", "write_mesh": "io.mesh",
          "RenderJob": "tasks.pictures", "run_render": "tasks.pictures",
          "PlotJob": "tasks.pictures", "run_plot": "tasks.pictures",
          "BenchJob": "tasks.bench", "run_bench": "tasks.bench"}

__all__ = sorted(_WHERE)


def __getattr__(name):
    if name == "__version__":  # one source, pyproject.toml; read on demand (importlib.metadata)
        from importlib.metadata import version
        return version("srarap-cli")
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)


def __dir__():
    return sorted(list(globals()) + __all__ + ["__version__"])
