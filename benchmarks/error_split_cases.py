"""The meshes the multiresolution error benchmarks run on (``multires_error_split.py``,
``galerkin_correction.py``): Spot at 46k and 184k vertices and ``multires_large.py``'s cases."""
import os

from multires_large import CASES as LARGE
from multires_large import _mesh
from run_bench import OUT, ROOT

NOD = os.path.join(ROOT, "configs", "spot-nod.yaml")
CASES = {"spot46k": (os.path.join(OUT, "spot-46k.obj"), NOD),
         "spot184k": (os.path.join(OUT, "spot-184k.obj"), NOD)}


def case(name):
    """(mesh path, handle file) of a case by name."""
    if name in LARGE:
        return _mesh(name)
    return CASES[name]
