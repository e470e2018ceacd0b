# The wing's names, the only list of them: type checkers read it, and the package's
# __init__.py loads each name from the module named here on first use (attach_stub).
from .frame_files import MAX_FRAMES as MAX_FRAMES
from .frame_files import frame_paths as frame_paths
from .job import AnimateJob as AnimateJob
from .job import AnimationOutcome as AnimationOutcome
from .job import run_animation as run_animation
from .sequence import Animator as Animator

__all__: list[str]
