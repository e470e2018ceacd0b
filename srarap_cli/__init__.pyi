# The public names, the only list of them: type checkers read it, and __init__.py loads
# each name from the module named here on first use (attach_stub).
from .io.handles.parse import Constraints as Constraints
from .io.handles.parse import as_constraints as as_constraints
from .io.handles.parse import load_handles as load_handles
from .io.mesh.files import read_mesh as read_mesh
from .io.mesh.files import write_mesh as write_mesh
from .io.mesh.formats import MeshFormat as MeshFormat
from .io.mesh.formats import register_format as register_format
from .io.mesh.mesh import Mesh as Mesh
from .solver.deformer import Deformer as Deformer
from .solver.interface import Solver as Solver
from .solver.oneshot import make_deformer as make_deformer
from .solver.result import DeformResult as DeformResult
from .solver.result import MultiresPart as MultiresPart
from .solver.settings import Settings as Settings
from .solver.settings import resolve as resolve
from .solver.stop import StopReason as StopReason
from .tasks.api import deform as deform
from .tasks.batch import BatchJob as BatchJob
from .tasks.batch import BatchOutcome as BatchOutcome
from .tasks.batch import run_batch as run_batch
from .tasks.bench import BenchJob as BenchJob
from .tasks.bench import run_bench as run_bench
from .tasks.comparison import CompareJob as CompareJob
from .tasks.comparison import Comparison as Comparison
from .tasks.comparison import compare_meshes as compare_meshes
from .tasks.comparison import run_compare as run_compare
from .tasks.pictures import PlotJob as PlotJob
from .tasks.pictures import RenderJob as RenderJob
from .tasks.pictures import run_plot as run_plot
from .tasks.pictures import run_render as run_render
from .tasks.pipeline import deform_mesh as deform_mesh

__version__: str
__all__: list[str]
