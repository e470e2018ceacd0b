"""A package whose names are imported on first use, listed once: in its ``__init__.pyi``
stub, which type checkers read (``from .job import run_job as run_job``). :func:`attach_stub`
reads that stub and gives the package's ``__getattr__``, ``__dir__`` and ``__all__``, so the
names a checker sees are the names the package has. Nothing is imported with the package (a
command pays only for what it uses), and two packages that use each other's names never meet
half-initialized.

``SRARAP_EAGER_IMPORTS=1`` imports every name of every such package when the top package
(``srarap_cli``) is imported: a CI leg runs so, where a name a stub lists but its module
lacks, or an import that only works in one order, fails at once. (Cycles through the
packages are the import graph's test: tests/test_layers.py follows names through stubs.)
"""
import ast
import importlib
import os
from collections.abc import Callable
from typing import Any

ENV_EAGER = "SRARAP_EAGER_IMPORTS"


def stub_names(init_file: str) -> dict[str, tuple[str, str]]:
    """``{name: (relative module, name there)}`` of the ``from ... import`` lines of the stub
    beside ``init_file`` (its ``__init__.pyi``), in the stub's order.

    Examples
    --------
    >>> import srarap_cli.tasks.deform as wing
    >>> stub_names(wing.__file__)["run_job"]
    ('.job', 'run_job')
    """
    stub = os.path.splitext(init_file)[0] + ".pyi"
    with open(stub, encoding="utf-8") as fh:
        tree = ast.parse(fh.read(), stub)
    return {alias.asname or alias.name: ("." * node.level + (node.module or ""), alias.name)
            for node in tree.body if isinstance(node, ast.ImportFrom) and node.level
            for alias in node.names}


def attach_stub(package: str, init_file: str
                ) -> tuple[Callable[[str], Any], Callable[[], list[str]], list[str]]:
    """``(__getattr__, __dir__, __all__)`` for the package ``package`` whose ``__init__.py``
    is ``init_file``, from its stub (see :func:`stub_names`): ``name`` imported from its
    module on first use, AttributeError for a name the stub does not list."""
    names = stub_names(init_file)

    def __getattr__(name: str) -> Any:
        if name not in names:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, attribute = names[name]
        return getattr(importlib.import_module(module, package), attribute)

    def __dir__() -> list[str]:
        return sorted(names)

    if os.environ.get(ENV_EAGER) == "1" and "." not in package:
        for name in names:
            __getattr__(name)
        _import_every_name(package, init_file)
    return __getattr__, __dir__, sorted(names)


def _import_every_name(package: str, init_file: str) -> None:
    """Every name of every lazy package below ``package`` (a folder with an ``__init__.pyi``),
    imported."""
    root = os.path.dirname(init_file)
    for folder, dirs, files in sorted(os.walk(root)):
        dirs.sort()
        if folder == root or "__init__.pyi" not in files:
            continue
        name = package + "." + os.path.relpath(folder, root).replace(os.sep, ".")
        module = importlib.import_module(name)
        for attribute in stub_names(os.path.join(folder, "__init__.py")):
            getattr(module, attribute)
