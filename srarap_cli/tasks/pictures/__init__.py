"""Pictures: meshes drawn headless (``render``), ``deform --preview`` (``preview``), an
animation's frames as a GIF or a contact sheet (``frames``), the batch report's pictures of a
job (``job_pictures``), log axes (``log_axis``), and the jobs of ``srarap render`` and ``srarap
plot`` (``jobs``: :class:`~.jobs.RenderJob`, :func:`~.jobs.run_render`, :class:`~.jobs.PlotJob`,
:func:`~.jobs.run_plot`). Names are imported on first use.
"""
from ...runtime.lazy_names import lazy_getattr

_WHERE = {"RenderJob": "jobs", "run_render": "jobs", "PlotJob": "jobs", "run_plot": "jobs",
          "VIEWS": "render", "render_png": "render", "preview_png": "preview",
          "difference_picture": "job_pictures",
          "energy_picture": "job_pictures", "shape_picture": "job_pictures"}

__all__ = sorted(_WHERE)


__getattr__ = lazy_getattr(__name__, _WHERE)
