# The wing's names for type checkers: the package loads them lazily (__init__.py's
# __getattr__). Keep in step with _WHERE there (tests/test_layers.py checks it).
from .compare import Comparison as Comparison
from .compare import Verdict as Verdict
from .compare import compare_meshes as compare_meshes
from .job import CompareJob as CompareJob
from .job import CompareOutcome as CompareOutcome
from .job import run_compare as run_compare

__all__: list[str]
