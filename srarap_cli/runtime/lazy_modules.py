"""Defer numpy's submodules that a run never uses.

SciPy's vendored array-API layer (imported by ``scipy.sparse``) clones numpy by reading every
name ``dir(numpy)`` lists, and numpy imports a submodule on first read of its name: so every
process that touches ``scipy.sparse`` pays for ``numpy.f2py``, ``numpy.testing`` and
``numpy.polynomial`` (about 45 ms, a sixth of deforming the sample bar), though srarap calls
none of them (``numpy.ma`` stays: ``np.unique`` calls it). Registered as lazy modules (the
standard library's ``LazyLoader``), they are still there for whoever reads them, and their
code runs on first attribute access.
"""
import importlib.util
import sys

#: numpy submodules nothing in srarap's runs uses
UNUSED = ("numpy.f2py", "numpy.testing", "numpy.polynomial")


def defer_unused_numpy_modules() -> None:
    """Register each of :data:`UNUSED` not imported yet as a lazy module (imports numpy)."""
    for name in UNUSED:
        if name in sys.modules:
            continue
        spec = importlib.util.find_spec(name)
        if spec is None or spec.loader is None:
            continue
        spec.loader = importlib.util.LazyLoader(spec.loader)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
        # what the import system does once a submodule is loaded: numpy's own lazy
        # attribute hook would otherwise import it again by name, and find this module
        parent, _, child = name.rpartition(".")
        setattr(sys.modules[parent], child, module)
