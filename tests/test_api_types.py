"""The API takes what users have: (V, F) pairs, trimesh and meshio meshes, srarap's Mesh;
handles as a file, a dict or (ids, targets); results convert back; mistakes name the argument.
Every form gives the same bytes as the command line."""
import os

import meshio
import numpy as np
import pytest
import trimesh
from click.testing import CliRunner
from helpers import ROOT, tube

import srarap_cli
from srarap_cli.cli import main
from srarap_cli.io.mesh import format_mesh, read_mesh, write_mesh
from srarap_cli.io.mesh.mesh import Mesh

HANDLES = {"groups": {"base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]},
                               "fixed": True},
                      "tip": {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]},
                              "rotate": {"axis": [0, 1, 0], "angle": 40}}}}


@pytest.fixture
def case(tmp_path):
    import yaml

    V, F = tube(rings=8, segments=8)
    write_mesh(str(tmp_path / "m.obj"), (V, F))
    (tmp_path / "h.yaml").write_text(yaml.safe_dump(HANDLES))
    r = CliRunner().invoke(main, ["deform", str(tmp_path / "m.obj"), str(tmp_path / "h.yaml"),
                                  "-o", str(tmp_path / "cli.obj")])
    assert r.exit_code == 0, r.output
    return V, F, tmp_path


@pytest.mark.parametrize("form", ["pair", "mesh", "from_arrays", "trimesh", "meshio", "file"])
def test_every_mesh_form_gives_the_command_lines_bytes(case, form):
    V, F, folder = case
    mesh = {"pair": lambda: (V, F), "mesh": lambda: read_mesh(str(folder / "m.obj")),
            "from_arrays": lambda: Mesh.from_arrays(V, F),
            "trimesh": lambda: trimesh.Trimesh(V, F, process=False),
            "meshio": lambda: meshio.Mesh(V, [("triangle", F)]),
            "file": lambda: read_mesh(str(folder / "m.obj"))}[form]()
    handles = str(folder / "h.yaml") if form == "file" else HANDLES
    result = srarap_cli.deform(mesh, handles)
    out = folder / f"{form}.obj"
    write_mesh(str(out), result.to_arrays())
    assert out.read_bytes() == (folder / "cli.obj").read_bytes()
    assert isinstance(result.to_trimesh(), trimesh.Trimesh)
    assert np.array_equal(result.to_meshio().points, result.positions)


def test_handles_as_ids_and_targets_match_the_handle_file(case):
    V, F, folder = case
    c = srarap_cli.load_handles(str(folder / "h.yaml"), V)
    by_file = srarap_cli.deform((V, F), str(folder / "h.yaml"))
    by_pair = srarap_cli.deform((V, F), (c.ids[::-1], c.targets[::-1]))
    np.testing.assert_allclose(by_pair.positions, by_file.positions, atol=1e-9)


def test_the_array_form_still_works(case):
    V, F, _ = case
    r = srarap_cli.deform(V, F, [0, 1, 2], V[[0, 1, 2]] + 1.0)
    assert r.converged


@pytest.mark.parametrize("call, error, words", [
    (lambda V, F: srarap_cli.deform("m.obj", HANDLES), TypeError, "read_mesh"),
    (lambda V, F: srarap_cli.deform((V, F), 42), TypeError, "handles must be"),
    (lambda V, F: srarap_cli.deform((V, F), ([0, 1], [[0, 0, 0]])), ValueError, "targets"),
    (lambda V, F: srarap_cli.deform((V, F), {"groups": {}}), ValueError, "groups"),
    (lambda V, F: srarap_cli.deform((V, F), HANDLES, tolerance=1), TypeError, "tolerance"),
    (lambda V, F: write_mesh(Mesh.from_arrays(V, F), "o.obj"), TypeError, "(path, mesh)"),
])
def test_argument_mistakes_name_the_argument(case, call, error, words):
    V, F, _ = case
    with pytest.raises(error, match=None) as err:
        call(V, F)
    assert words in str(err.value)


def test_from_arrays_keeps_polygons():
    m = Mesh.from_arrays([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]],
                         [[0, 1, 2, 3], [1, 4, 2]])
    assert m.face_sizes.tolist() == [4, 3]
    assert b"f 1 2 3 4" in format_mesh(m, ".obj")[0]


def test_a_result_and_a_solver_print_as_one_short_line():
    """A notebook cell ending in a result or a Deformer shows one line, not every array."""
    from helpers import ROOT

    import srarap_cli
    from srarap_cli.solver.oneshot import make_deformer
    from srarap_cli.solver.settings import resolve

    bar = srarap_cli.read_mesh(f"{ROOT}/sample_meshes/bar.obj")
    handles = srarap_cli.load_handles(f"{ROOT}/configs/bar-twist.yaml", bar.vertices)
    d = srarap_cli.Deformer(bar.vertices, bar.triangles()[0], handles.ids)
    r = d.solve(handles.targets)
    assert repr(r) == (f"DeformResult(converged, {r.iterations} iterations, energy "
                       f"{r.energy:.6g}, 658 vertices, 0 warnings)")
    assert repr(d).startswith("Deformer(658 vertices, 1312 triangles, 34 constrained; ")
    spot = srarap_cli.read_mesh(f"{ROOT}/sample_meshes/spot.obj")
    nod = srarap_cli.load_handles(f"{ROOT}/configs/spot-nod.yaml", spot.vertices)
    md = make_deformer(spot.vertices, spot.triangles()[0], nod.ids,
                       settings=resolve({"multires": 2000}))
    mr = md.solve(nod.targets)
    for thing in (r, d, md, mr, mr.multires):
        text = repr(thing)
        assert "\n" not in text and len(text) < 200, text
    assert repr(mr).startswith("DeformResult(converged, ") and "coarse)" in repr(mr)
    assert repr(mr.multires).startswith("MultiresPart(refine, ")


def test_one_result_type_with_an_optional_multiresolution_part():
    """Both solvers return a DeformResult: the full-resolution one without a multires part,
    the multiresolution one with its coarse solve's part (refine and transfer)."""
    from helpers import ROOT

    import srarap_cli
    from srarap_cli.solver.result import MultiresPart

    bar = srarap_cli.read_mesh(f"{ROOT}/sample_meshes/bar.obj")
    twist = f"{ROOT}/configs/bar-twist.yaml"
    plain = srarap_cli.deform(bar, twist, multires="off")
    refined = srarap_cli.deform(bar, twist, multires=150)
    moved = srarap_cli.deform(bar, twist, multires=150, multires_mode="transfer")
    assert type(plain) is type(refined) is type(moved) is srarap_cli.DeformResult
    assert plain.multires is None and plain.coarse_iterations == 0 and not plain.approximate
    for r in (refined, moved):
        assert isinstance(r.multires, MultiresPart) and r.multires.coarse_vertices <= 150
        assert r.coarse_iterations == r.multires.iterations > 0 and r.multires.converged
    assert not refined.approximate and moved.approximate and moved.complete
    assert refined.energies() == {k: refined.log[-1][k] for k in ("membrane", "bending", "total")}
    assert moved.energies() == moved.multires.full_energy


@pytest.mark.slow
def test_the_public_names_type_check_for_a_user(tmp_path):
    """The lazily loaded names are typed for a checker (__init__.pyi): mypy sees the class,
    the functions' signatures, and refuses a wrong call."""
    import subprocess
    import sys

    from helpers import ROOT

    import srarap_cli

    stub = open(f"{ROOT}/srarap_cli/__init__.pyi").read()
    assert all(f"import {name} as {name}" in stub for name in srarap_cli.__all__)
    (tmp_path / "user.py").write_text(
        "import srarap_cli\n"
        "reveal_type(srarap_cli.Deformer)\n"
        "reveal_type(srarap_cli.read_mesh)\n"
        "srarap_cli.read_mesh(3.5, 1, 2, 3)\n")
    # the package's source on mypy's path: an editable install's import hook is invisible
    # to a checker (an installed wheel is found in site-packages)
    p = subprocess.run([sys.executable, "-m", "mypy", "--no-incremental",
                        str(tmp_path / "user.py")], capture_output=True, text=True,
                       timeout=600, cwd=tmp_path, env={**os.environ, "MYPYPATH": ROOT})
    out = p.stdout
    assert 'Revealed type is "def (V: ' in out and "srarap_cli.solver.deformer.Deformer" in out
    assert "def (path:" in out and "Any" not in out.splitlines()[0]
    assert "Too many arguments" in out


def test_the_api_page_documents_only_names_srarap_cli_exports():
    """docs/reference/api.md listed 6 names that ``from srarap_cli import ...`` did not
    give (issue 62): each name it documents is exported, as the very object documented."""
    import importlib
    import re

    import srarap_cli
    page = open(os.path.join(ROOT, "docs", "reference", "api.md"), encoding="utf-8").read()
    documented = re.findall(r"^::: (srarap_cli(?:\.\w+)+)$", page, re.M)
    assert len(documented) >= 20
    for path in documented:
        module, name = path.rsplit(".", 1)
        assert name in srarap_cli.__all__, name
        assert getattr(srarap_cli, name) is getattr(importlib.import_module(module), name), path
