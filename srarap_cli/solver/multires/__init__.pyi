# The package's names, the only list of them: type checkers read it, and __init__.py loads
# each name from the module named here on first use (attach_stub).
from .deformer import MultiresDeformer as MultiresDeformer
from .simplify import CoarseMesh as CoarseMesh
from .simplify import simplify_to_subset as simplify_to_subset
from .size import coarse_size as coarse_size
from .size import parse_size as parse_size

__all__: list[str]
