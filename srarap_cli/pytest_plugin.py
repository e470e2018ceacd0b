"""srarap's pytest plugin (installed with srarap, loaded by pytest through its ``pytest11``
entry point): the ``mesh_regression`` fixture and the ``--update-goldens`` and
``--accept-goldens`` options.

A test hands its mesh (or a solve's result) to ``mesh_regression.check(...)``, which compares
it with a golden kept beside the test module, in a folder named after the module and a file
named after the test::

    def test_twist(mesh_regression):
        result = srarap_cli.deform(V, F, handles)
        mesh_regression.check(result, tol=1e-6, relative=True, energy_rtol=1e-6)

    tests/test_bar.py  ->  tests/test_bar/test_twist.obj (+ test_twist.obj.srarap.json)

A missing golden is written and the test fails once (so that no new test passes before its
golden was looked at); a result beyond any gate fails with ``compare``'s one-line verdict
and leaves the obtained mesh beside the golden (``test_twist.obtained.obj``);
``--update-goldens`` rewrites the goldens of the tests that fail (the tests still fail:
review them), ``--accept-goldens`` rewrites them and passes.

Nothing heavy is imported until a test uses the fixture.
"""
import os
import re
from typing import Any

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("srarap", "srarap mesh regressions (the mesh_regression fixture)")
    group.addoption("--update-goldens", action="store_true",
                    help="mesh_regression: rewrite the golden of every check that fails (the "
                    "test still fails: review what was written)")
    group.addoption("--accept-goldens", action="store_true",
                    help="mesh_regression: as --update-goldens, and those checks pass")


@pytest.fixture
def mesh_regression(request: pytest.FixtureRequest) -> "MeshRegression":
    """Compare a mesh with the golden kept beside the test module (see
    :class:`MeshRegression`)."""
    option = request.config.getoption
    mode = ("accept" if option("accept_goldens") else "update" if option("update_goldens")
            else "check")
    return MeshRegression(request.node, mode)


class MeshRegression:
    """The ``mesh_regression`` fixture: :meth:`check` a mesh against its golden.

    Parameters
    ----------
    node : the pytest item of the test (its path and name give the golden's)
    mode : {"check", "update", "accept"}, what a failing check does to its golden
    """

    def __init__(self, node: Any, mode: str = "check") -> None:
        self.node, self.mode = node, mode
        self._calls = 0

    def golden_path(self, basename: str | None = None, extension: str = ".obj") -> str:
        """Where the golden of ``basename`` (default: the test's name, made a file name) is
        kept: ``<module folder>/<module name>/<basename><extension>``."""
        path = str(self.node.path)
        folder = os.path.join(os.path.dirname(path), os.path.splitext(os.path.basename(path))[0])
        return os.path.join(folder, (basename or self._test_name()) + extension)

    def _test_name(self) -> str:
        return re.sub(r"[^\w.-]", "_", self.node.name)

    def check(self, obtained: Any, basename: str | None = None, extension: str = ".obj",
              **gates: Any) -> None:
        """Compare ``obtained`` with its golden; fail the test with the verdict when a gate
        fails or the golden is missing (then written).

        Parameters
        ----------
        obtained : a :class:`~srarap_cli.DeformResult` (its positions and faces; its energy,
            iterations and seconds for those gates), a :class:`~srarap_cli.Mesh`, a
            ``(V, F)`` pair, a trimesh or meshio mesh
        basename : str, optional, the golden's file name without extension (default: the
            test's name; a second check in one test adds ``-2``, a third ``-3``)
        extension : str, the golden's format (``.obj``, ``.ply``, ``.off``, ...)
        **gates : a manifest's ``expect`` keys: ``tol``, ``relative``, ``beyond_tol``,
            ``p95``, ``p99``, ``energy_rtol``, ``max_iterations``, ``iterations_within``,
            ``max_seconds``, ``align``

        Examples
        --------
        ``mesh_regression.check(result, tol=1e-6, relative=True, max_iterations=50)``
        """
        from .tasks.regression_check import check_against_golden

        self._calls += 1
        if basename is None and self._calls > 1:
            basename = f"{self._test_name()}-{self._calls}"
        golden = self.golden_path(basename, extension)
        outcome = check_against_golden(obtained, golden, self.mode, gates)
        self.node.user_properties.extend(outcome.properties)
        if outcome.failure:
            pytest.fail(outcome.failure, pytrace=False)
