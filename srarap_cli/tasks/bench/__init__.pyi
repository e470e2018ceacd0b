# The wing's names for type checkers: the package loads them lazily (__init__.py's
# __getattr__). Keep in step with _WHERE there (tests/test_layers.py checks it).
from .job import CHOICES as CHOICES
from .job import OWN_DEFAULTS as OWN_DEFAULTS
from .job import BenchJob as BenchJob
from .job import run_bench as run_bench
from .methods import ALL_METHODS as ALL_METHODS
from .methods import run_methods as run_methods
from .report import table as table

__all__: list[str]
