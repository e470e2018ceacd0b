"""The rules of docs/background/architecture.md, checked on the code's own imports: five
layers, each importing only those below it; no import cycle; every layer's ``__init__``
states its rule; every public function in every layer has type hints (mypy, run over the
whole package in CI, then checks their bodies)."""
import ast
import os
import re

import pytest
from helpers import ROOT

PACKAGE = os.path.join(ROOT, "srarap_cli")
#: bottom to top; the package's own top-level modules (entry, __main__) sit above them all
LAYERS = ("runtime", "solver", "io", "tasks", "cli")


def _modules():
    """module name -> path, every module of the package but the sample data's scripts."""
    out = {}
    for folder, dirs, files in os.walk(PACKAGE):
        dirs[:] = [d for d in dirs if d not in ("data", "__pycache__")]
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                parts = os.path.relpath(path, ROOT)[:-3].split(os.sep)
                out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


MODULES = _modules()


def _layer(module):
    parts = module.split(".")
    return LAYERS.index(parts[1]) if len(parts) > 1 and parts[1] in LAYERS else len(LAYERS)


def _lazy(package):
    """``{name: module}`` of a package that loads its names from its stub on first use
    (``runtime/lazy_names.py``), each name's module absolute; {} for another package."""
    from srarap_cli.runtime.lazy_names import stub_names
    path = MODULES.get(package, "")
    if not path.endswith("__init__.py") or not os.path.exists(path[:-3] + ".pyi"):
        return {}
    out = {}
    for name, (relative, _) in stub_names(path).items():
        level = len(relative) - len(relative.lstrip("."))
        base = package.split(".")[:len(package.split(".")) - level + 1]
        out[name] = ".".join(base + ([relative.lstrip(".")] if relative.lstrip(".") else []))
    return out


def _defining(target, name):
    """The module that defines ``name`` taken from ``target``: through a lazy package's stub
    (and a stub that names another lazy package, through its stub in turn), else
    ``target``."""
    seen = set()
    while target not in seen and name in _lazy(target):
        seen.add(target)
        target = _lazy(target)[name]
    return target


def _imports(module, path, through_stubs=True):
    """The package's modules ``module`` imports at run time (anywhere in it, functions too;
    not what an ``if TYPE_CHECKING:`` block imports for annotations only). A name taken from
    a lazy package counts as an import of the module that defines it (``through_stubs``):
    the package's ``__init__`` imports nothing, and an edge that stopped there would hide a
    cycle through it; without, the package as written."""
    tree = ast.parse(open(path, encoding="utf-8").read())
    hidden = {id(n) for node in ast.walk(tree) if isinstance(node, ast.If)
              and getattr(node.test, "id", "") == "TYPE_CHECKING" for n in ast.walk(node)}
    package = module if path.endswith("__init__.py") else module.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if id(node) in hidden:
            continue
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                found.add(sub if sub in MODULES else _defining(target, alias.name)
                          if through_stubs else target)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return {m for m in found if m in MODULES and m != module}


GRAPH = {m: _imports(m, p) for m, p in MODULES.items()}


def test_the_graph_is_read():
    assert len(MODULES) > 100 and sum(map(len, GRAPH.values())) > 300
    assert "srarap_cli.solver.oneshot" in GRAPH["srarap_cli.tasks.pipeline"]


def test_no_layer_imports_a_layer_above_it():
    upward = [f"{m} -> {t}" for m, targets in GRAPH.items() for t in targets
              if _layer(t) > _layer(m)]
    assert upward == []


def test_the_import_graph_has_no_cycle():
    assert _cycles(GRAPH) == []


def test_a_cycle_through_lazy_wings_is_seen():
    """Issue 72: an edge to a lazy package was a dead end (its ``__init__`` imports
    nothing), so a cycle through two wings passed. Planted: ``pictures/preview.py`` takes
    ``run_job`` from the deform wing, whose job module reaches the pictures wing."""
    assert _defining("srarap_cli.tasks.deform", "run_job") == "srarap_cli.tasks.deform.job"
    assert _defining("srarap_cli", "RenderJob") == "srarap_cli.tasks.pictures.jobs"
    planted = {m: set(t) for m, t in GRAPH.items()}
    planted["srarap_cli.tasks.pictures.preview"].add(_defining("srarap_cli.tasks.deform",
                                                               "run_job"))
    assert any("srarap_cli.tasks.pictures.preview" in cycle for cycle in _cycles(planted))


def _cycles(graph):
    """Depth-first search; a module met again on the current path closes a cycle."""
    state, cycles = {}, []

    def visit(m, path):
        state[m] = "open"
        for t in sorted(graph[m]):
            if state.get(t) == "open":
                cycles.append(path[path.index(t):] + [t])
            elif t not in state:
                visit(t, path + [t])
        state[m] = "done"

    for m in sorted(graph):
        if m not in state:
            visit(m, [m])
    return cycles


@pytest.mark.parametrize("layer", LAYERS)
def test_every_layer_states_its_rule(layer):
    """The ``Rule:`` paragraph of the layer's docstring names every layer below it before any
    ``never``, and no layer above it there."""
    doc = ast.get_docstring(ast.parse(open(os.path.join(PACKAGE, layer, "__init__.py")).read()))
    rule = re.search(r"^Rule: (.*?)(?:\n\n|$)", doc or "", re.M | re.S)
    assert rule, f"{layer}/__init__.py states no rule"
    allowed = rule.group(1).split("never")[0]
    below, above = LAYERS[:LAYERS.index(layer)], LAYERS[LAYERS.index(layer) + 1:]
    assert all(f"``{b}``" in allowed for b in below), allowed
    assert not any(f"``{a}``" in allowed for a in above), allowed
    if not below:
        assert "nothing else of srarap" in allowed


def _public_functions(tree):
    """Top-level functions and the methods of top-level classes whose names are public."""
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
            yield node
        elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            for item in node.body:
                if isinstance(item, ast.FunctionDef) and (
                        not item.name.startswith("_") or item.name == "__init__"):
                    yield item


def test_every_public_function_in_every_layer_is_type_hinted():
    loose = []
    for path in sorted(MODULES.values()):
        tree = ast.parse(open(path, encoding="utf-8").read())
        for node in _public_functions(tree):
            args = node.args.posonlyargs + node.args.args + node.args.kwonlyargs
            args = [a for a in args if a.arg not in ("self", "cls")]
            args += [a for a in (node.args.vararg, node.args.kwarg) if a is not None]
            if (node.returns is None and node.name != "__init__") or any(
                    a.annotation is None for a in args):
                loose.append(f"{os.path.relpath(path, ROOT)}:{node.lineno} {node.name}")
    assert loose == []


def test_mypy_runs_over_the_whole_package():
    import tomllib
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        mypy = tomllib.load(fh)["tool"]["mypy"]
    assert mypy["files"] == ["srarap_cli"]
    with open(os.path.join(ROOT, ".ci", "run")) as fh:
        assert re.search(r"^mypy$", fh.read(), re.M)


def test_package_files_only_re_export():
    """A package's ``__init__`` holds its docstring and re-exports (imports, ``__all__``; a
    lazy package its table of names and module ``__getattr__`` / ``__dir__``): the code lives
    in modules named for what they do."""
    allowed_names = {"__all__", "__getattr__", "__dir__", "_getattr", "_dir"}
    for module, path in MODULES.items():
        if not path.endswith("__init__.py"):
            continue
        tree = ast.parse(open(path, encoding="utf-8").read())
        for node in tree.body:
            ok = (isinstance(node, (ast.Import, ast.ImportFrom))
                  or (isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant))
                  or (isinstance(node, (ast.Assign, ast.AnnAssign)) and all(
                      isinstance(t, ast.Name) and t.id in allowed_names
                      for target in (node.targets if isinstance(node, ast.Assign)
                                     else [node.target])
                      for t in (target.elts if isinstance(target, ast.Tuple) else [target])))
                  or (isinstance(node, ast.FunctionDef) and node.name in ("__getattr__",
                                                                          "__dir__")))
            assert ok, f"{module}: line {node.lineno} is not a re-export"


#: what the command line may take from the lower layers besides tasks/ and runtime/: the
#: format table (its Click type) and the settings table (options, their value types)
CLI_MAY_IMPORT = {"srarap_cli.io.mesh", "srarap_cli.io.mesh.formats", "srarap_cli.solver.settings",
                  "srarap_cli.solver.multires.size"}


def test_the_cli_is_options_and_a_call_into_tasks():
    """Issue 62: each command's work lives in tasks/ (callable from Python); cli/ turns options
    into a job, calls it and says its summary. From io/ and solver/ it imports only the
    format and settings tables its option types are made of."""
    found = {}
    for module, path in MODULES.items():
        if not module.startswith("srarap_cli.cli"):
            continue
        lower = {m for m in _imports(module, path)
                 if m.split(".")[1] in ("io", "solver") and m not in CLI_MAY_IMPORT}
        if lower:
            found[module] = sorted(lower)
    assert not found, found


#: the kinds of work of tasks/, each a package with one entry (issue 62)
WINGS = ("deform", "animate", "comparison", "pictures", "bench", "batch")


def _wing(module):
    parts = module.split(".")
    return parts[2] if len(parts) > 2 and parts[1] == "tasks" and parts[2] in WINGS else None


def test_a_wing_reaches_another_only_through_its_package():
    """tasks/ is in wings; code outside a wing (another wing, the command line, the shared
    modules) takes a wing's names from its package, never from a module inside it."""
    found = []
    for module, path in MODULES.items():
        for target in _imports(module, path, through_stubs=False):
            wing = _wing(target)
            if wing and _wing(module) != wing and target != f"srarap_cli.tasks.{wing}":
                found.append(f"{module} -> {target}")
    assert not found, found


LAZY = sorted(m for m in MODULES if _lazy(m))


def test_the_lazy_packages_are_the_wings_the_solvers_multires_and_the_top():
    assert LAZY == sorted(["srarap_cli", "srarap_cli.solver.multires",
                           *(f"srarap_cli.tasks.{w}" for w in WINGS)])


@pytest.mark.parametrize("package", LAZY)
def test_a_lazy_packages_stub_is_its_one_list_and_names_where_each_name_is_made(package):
    """Issue 72: the names were kept twice (a table and the stub), and a stub could take a
    name from a module that only re-imports it. The stub is the only list; each name is
    defined (def, class, assignment) in the module it names, or taken from another lazy
    package's list; ``dir()``, ``__all__`` and attribute access follow the stub."""
    import importlib
    loaded = importlib.import_module(package)
    names = _lazy(package)
    assert loaded.__all__ == sorted(names) and set(names) <= set(dir(loaded))
    for name, module in names.items():
        if _lazy(module):
            assert name in _lazy(module), (name, module)
            continue
        tree = ast.parse(open(MODULES[module], encoding="utf-8").read())
        made = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
        made |= {t.id for n in tree.body if isinstance(n, (ast.Assign, ast.AnnAssign))
                 for t in (n.targets if isinstance(n, ast.Assign) else [n.target])
                 if isinstance(t, ast.Name)}
        assert name in made, f"{package}.{name}: not made in {module}"
        assert getattr(loaded, name) is getattr(importlib.import_module(module), name)


def test_every_lazy_name_imports_eagerly_in_a_fresh_process():
    """The CI leg's check, here too: with SRARAP_EAGER_IMPORTS=1 importing the package
    imports every name of every lazy package, so a name a stub lists but its module lacks
    fails at once."""
    import subprocess
    import sys
    code = ("import sys, srarap_cli; loaded = sorted(m for m in sys.modules if "
            f"m.startswith('srarap_cli.')); missing = [m for m in {LAZY!r} if m not in "
            "sys.modules and m != 'srarap_cli']; assert not missing, missing; "
            "assert 'srarap_cli.tasks.deform.job' in loaded")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={**os.environ, "SRARAP_EAGER_IMPORTS": "1"}, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
