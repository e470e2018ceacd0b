"""numpy submodules a run never uses are registered lazily: not executed, still usable."""
import subprocess
import sys

from helpers import ROOT

# a module's own __dict__, read without the lazy module's hook (which would load it)
EXECUTED = ("[m for m in UNUSED if len(object.__getattribute__(sys.modules[m], '__dict__')) "
            "> 12]")


def _run(code):
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout
    return out.strip().splitlines()[-1]


def test_a_deform_run_executes_none_of_them_and_keeps_one_blas_thread(tmp_path):
    code = (
        "import sys\n"
        "from srarap_cli.cli import main\n"
        "from srarap_cli.runtime.lazy_modules import UNUSED\n"
        "try:\n"
        f"    main(['deform', 'sample_meshes/bar.obj', 'configs/bar-twist.yaml', '-o', "
        f"{str(tmp_path / 'bar.obj')!r}, '-q'])\n"
        "except SystemExit as exc:\n"
        "    assert exc.code == 0, exc.code\n"
        "from threadpoolctl import threadpool_info\n"
        "blas = sorted({p['num_threads'] for p in threadpool_info()})\n"
        f"print({EXECUTED}, blas)\n")
    assert _run(code) == "[] [1]"
    assert (tmp_path / "bar.obj").stat().st_size > 0


def test_deferred_modules_load_on_first_use():
    code = (
        "import sys\n"
        "from srarap_cli.runtime.lazy_modules import UNUSED, defer_unused_numpy_modules\n"
        "defer_unused_numpy_modules()\n"
        "import scipy.sparse, numpy\n"  # scipy's clone of numpy reads every name
        f"before = {EXECUTED}\n"
        "numpy.testing.assert_allclose([1.0], [1.0])\n"
        "from numpy.polynomial import Polynomial\n"
        "value = Polynomial([1.0, 2.0])(3.0)\n"
        "import numpy.f2py\n"
        "has = callable(numpy.f2py.run_main)\n"
        f"print(before, value, has, {EXECUTED} == list(UNUSED))\n")
    assert _run(code) == "[] 7.0 True True"
