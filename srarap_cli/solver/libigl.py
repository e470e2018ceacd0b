"""libigl's Python bindings, imported with SIGINT/SIGTERM held back.

A signal during the initialization of a pybind11 module surfaces as ``ImportError:
std::bad_cast`` (and may then be swallowed); held back, it is raised right after the import,
as at any other moment. Import ``igl`` from here, never directly.
"""
from ..runtime.signals import deferred

with deferred():
    import igl

__all__ = ["igl"]
