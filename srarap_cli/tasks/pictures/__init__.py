"""Pictures: meshes drawn headless (``render``), ``deform --preview`` (``preview``), an
animation's frames as a GIF or a contact sheet (``frames``), the batch report's pictures of a
job (``job_pictures``), log axes (``log_axis``), and the jobs of ``srarap render`` and ``srarap
plot`` (``jobs``: :class:`~.jobs.RenderJob`, :func:`~.jobs.run_render`, :class:`~.jobs.PlotJob`,
:func:`~.jobs.run_plot`). Names are imported on first use.
"""
from ...runtime.lazy_names import attach_stub

__getattr__, __dir__, __all__ = attach_stub(__name__, __file__)
