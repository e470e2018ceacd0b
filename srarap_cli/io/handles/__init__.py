"""The handle file: which vertices are constrained and where they go.

YAML or JSON (same schema), or a Botsch-Sorkine ``.sel`` file with its ``.def`` beside it.
The schema is documented in the README; :func:`load_handles` validates it and reports each
problem as one line naming the file, group and field.
"""
from .parse import (
    ANIMATION_KEYS,
    TOP_KEYS,
    Constraints,
    as_constraints,
    load_handles,
    parse_handles,
    referenced_files,
    solver_settings,
)

__all__ = ["ANIMATION_KEYS", "Constraints", "TOP_KEYS", "as_constraints", "load_handles", "parse_handles",
           "referenced_files", "solver_settings"]
