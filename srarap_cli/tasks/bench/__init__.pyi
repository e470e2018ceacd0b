# The wing's names, the only list of them: type checkers read it, and the package's
# __init__.py loads each name from the module named here on first use (attach_stub).
from .job import CHOICES as CHOICES
from .job import OWN_DEFAULTS as OWN_DEFAULTS
from .job import BenchJob as BenchJob
from .job import run_bench as run_bench
from .methods import ALL_METHODS as ALL_METHODS
from .methods import run_methods as run_methods
from .report import table as table

__all__: list[str]
