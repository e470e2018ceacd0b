# The wing's names for type checkers: the package loads them lazily (__init__.py's
# __getattr__). Keep in step with _WHERE there (tests/test_layers.py checks it).
from .frame_files import MAX_FRAMES as MAX_FRAMES
from .frame_files import frame_paths as frame_paths
from .job import AnimateJob as AnimateJob
from .job import AnimationOutcome as AnimationOutcome
from .job import run_animation as run_animation
from .sequence import Animator as Animator

__all__: list[str]
