# The wing's names, the only list of them: type checkers read it, and the package's
# __init__.py loads each name from the module named here on first use (attach_stub).
from .compare import Comparison as Comparison
from .compare import Verdict as Verdict
from .compare import compare_meshes as compare_meshes
from .gates import EXPECT_KEYS as EXPECT_KEYS
from .gates import GATE_KEYS as GATE_KEYS
from .gates import Expect as Expect
from .gates import Observed as Observed
from .gates import judge as judge
from .gates import parse_expect as parse_expect
from .gates import verdict_line as verdict_line
from .goldens import GOLDEN_MODES as GOLDEN_MODES
from .goldens import read_golden_record as read_golden_record
from .goldens import record_path as record_path
from .goldens import refuse_leading_out as refuse_leading_out
from .goldens import write_golden as write_golden
from .job import CompareJob as CompareJob
from .job import CompareOutcome as CompareOutcome
from .job import run_compare as run_compare

__all__: list[str]
