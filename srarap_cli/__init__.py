"""srarap: as-rigid-as-possible surface deformation with smooth rotations (linear-time SR-ARAP).

Public API: :class:`Deformer` (precompute once, solve many times), :func:`deform` (one shot),
:func:`read_mesh` / :func:`write_mesh`, :func:`load_handles`, :func:`deform_mesh`.

Names are imported on first use, so that ``import srarap_cli`` and the command line's help
do not load the numerical stack.
"""
import importlib

_WHERE = {"Constraints": "handles", "DeformResult": "deformer", "Deformer": "deformer",
          "Mesh": "mesh_io", "deform": "oneshot", "deform_mesh": "pipeline",
          "load_handles": "handles", "read_mesh": "mesh_io", "write_mesh": "mesh_io"}

__all__ = sorted(_WHERE)


def __getattr__(name):
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)


def __dir__():
    return sorted(list(globals()) + __all__)
