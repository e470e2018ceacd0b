"""srarap: as-rigid-as-possible surface deformation with smooth rotations (linear-time SR-ARAP).

Public API: :class:`Deformer` (precompute once, solve many times), :func:`deform` (one shot),
:func:`read_mesh` / :func:`write_mesh`, :func:`load_handles`, :func:`deform_mesh`.
"""
from .deformer import Deformer, DeformResult
from .handles import Constraints, load_handles
from .mesh_io import Mesh, read_mesh, write_mesh
from .oneshot import deform
from .pipeline import deform_mesh

__all__ = [
           "Constraints",
           "DeformResult",
           "Deformer",
           "Mesh",
           "deform",
           "deform_mesh",
           "load_handles",
           "read_mesh",
           "write_mesh",
]
