# The wing's names, the only list of them: type checkers read it, and the package's
# __init__.py loads each name from the module named here on first use (attach_stub).
from .job_pictures import difference_picture as difference_picture
from .job_pictures import energy_picture as energy_picture
from .job_pictures import shape_picture as shape_picture
from .jobs import PlotJob as PlotJob
from .jobs import RenderJob as RenderJob
from .jobs import run_plot as run_plot
from .jobs import run_render as run_render
from .preview import preview_png as preview_png
from .render import VIEWS as VIEWS
from .render import render_png as render_png

__all__: list[str]
