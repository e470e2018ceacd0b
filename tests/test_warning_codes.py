"""Every warning has a stable code and a kind (issue 60): a walk over the package's source
finds every place a warning is made and checks its code; a walk over cases that provoke each
code checks that what a user reads carries it; ``--strict`` fails on the request's warnings,
``--strict=all`` on every one, ``--allow`` accepts a code, from the command line, a handle
file and a batch manifest."""
import ast
import json
import os
import re

import numpy as np
import pytest
from helpers import ROOT, run_cli, torus, tube_mesh

from srarap_cli.io.mesh import write_mesh
from srarap_cli.io.mesh.mesh import Mesh
from srarap_cli.runtime.warning_codes import CODES, NOTE, REQUEST, Note, as_note, failing, note, reworded
from srarap_cli.solver.multires.simplify import _topology_warnings

PACKAGE = os.path.join(ROOT, "srarap_cli")
LINE = re.compile(r"^srarap: warning: .* \[([a-z-]+)\]( \(\d+ times\))?$")


def _calls():
    """(path, line, code or None) of every ``note(...)``, ``ctx.warn(...)`` and
    ``coded(text, code)`` in the package."""
    out = []
    for folder, _, files in os.walk(PACKAGE):
        for name in files:
            if not name.endswith(".py"):
                continue
            path = os.path.join(folder, name)
            for node in ast.walk(ast.parse(open(path, encoding="utf-8").read())):
                if not isinstance(node, ast.Call):
                    continue
                f = node.func
                called = f.id if isinstance(f, ast.Name) else f.attr if isinstance(
                    f, ast.Attribute) else ""
                if called == "coded" and len(node.args) == 2:
                    second = node.args[1]
                    out.append((os.path.relpath(path, ROOT), node.lineno,
                                second.value if isinstance(second, ast.Constant) else None))
                elif called in ("note", "warn") and node.args and not (
                        isinstance(f, ast.Attribute) and called == "warn"
                        and getattr(f.value, "id", "") in ("warnings", "logging")):
                    first = node.args[0]
                    if isinstance(first, ast.Name) and first.id == "code":
                        continue  # Context.warn passing its caller's code on
                    code = first.value if isinstance(first, ast.Constant) else None
                    out.append((os.path.relpath(path, ROOT), node.lineno, code))
    return out


def test_every_warning_made_in_the_code_names_a_known_code_and_every_code_is_made():
    calls = [c for c in _calls() if not c[0].endswith("warning_codes.py")]
    assert len(calls) >= len(CODES)
    unknown = [c for c in calls if c[2] not in CODES]
    assert not unknown, unknown
    assert {c[2] for c in calls} == set(CODES)
    assert {c.kind for c in CODES.values()} == {REQUEST, NOTE}


def test_plain_string_warnings_are_not_appended_anywhere():
    """No list named like a warnings list gets an f-string: each goes through note(). (A
    format writer's lines, ``lost``, are plain by the plug-in contract: ``MeshFormat.encode``
    codes them.)"""
    found = []
    for folder, _, files in os.walk(PACKAGE):
        for name in (n for n in files if n.endswith(".py")):
            path = os.path.join(folder, name)
            for node in ast.walk(ast.parse(open(path, encoding="utf-8").read())):
                if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                        and node.func.attr == "append" and node.args
                        and isinstance(node.args[0], ast.JoinedStr)):
                    target = ast.unparse(node.func.value)
                    if re.search(r"warn|notes", target):
                        found.append((os.path.relpath(path, ROOT), node.lineno, target))
    assert not found, found


def test_a_note_keeps_its_code_through_text_json_and_a_prefix():
    w = note("needles", "3 needle faces")
    assert (w, w.code, w.kind, w.text) == ("3 needle faces [needles]", "needles", NOTE,
                                           "3 needle faces")
    back = as_note(json.loads(json.dumps([w]))[0])
    assert isinstance(back, Note) and back.code == "needles"
    moved = reworded(w, "multires: ")
    assert moved == "multires: 3 needle faces [needles]" and moved.code == "needles"
    assert as_note("no code here") == "no code here"
    assert as_note("x [not-a-code]") == "x [not-a-code]"
    with pytest.raises(ValueError):
        note("not-a-code", "x")


def test_failing_follows_the_kind_the_level_and_allow():
    mesh, motion = note("needles", "a"), note("units", "b")
    plain = "a plug-in's warning"
    assert failing([mesh, motion, plain], "off", ()) == []
    assert failing([mesh, motion, plain], "request", ()) == [motion, plain]
    assert failing([mesh, motion, mesh], "all", ()) == [mesh, motion]
    assert failing([mesh, motion], "all", ("units",)) == [mesh]
    assert failing([str(mesh)], "all", ("needles",)) == []  # read back from a record


# --- the cases: each provokes codes through what a user runs --------------------------------

def _grid(n=6):
    """A flat n x n grid of triangles in z = 0, its side 1."""
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n), indexing="ij")
    V = np.column_stack([u.ravel(), v.ravel(), np.zeros(n * n)])
    i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="ij")
    a = (i * n + j).ravel()
    F = np.concatenate([np.column_stack([a, a + n, a + 1]), np.column_stack([a + 1, a + n, a + n + 1])])
    return V, F


def _obj(path, V, F):
    write_mesh(path, Mesh.from_arrays(np.asarray(V, float), np.asarray(F)))
    return path


def _yaml(path, doc):
    path.write_text(json.dumps(doc))
    return path


EDGE = {"box": {"min": [-0.01, -0.01, -1], "max": [0.01, 1.01, 1]}}
FAR = {"box": {"min": [0.99, -0.01, -1], "max": [1.01, 1.01, 1]}}


def _bend(extra=None):
    return {"groups": {"fix": {**EDGE, "fixed": True},
                       "move": {**FAR, "translate": [0, 0, 0.2], **(extra or {})}}}


def _defective(tmp_path):
    """The grid with one of each mesh defect: a collapsed, a duplicate, a zero-area (three
    points in a row) and a needle face, a third face on an edge, an unreferenced vertex and
    a flap glued on at coincident border vertices."""
    V, F = _grid()
    n = len(V)
    V = np.vstack([V, [[0.5, 0.5, 1.0]],                      # n: a third face's apex
                   [[2.0, 2.0, 2.0]],                           # n+1: in no face
                   [[0.0, 0.0, 0.0], [0.2, 0.0, 0.0], [0.1, -0.3, 0]],  # n+2..: coincident flap
                   [[0.5, -1.0, 0], [0.6, -1.0, 0], [0.7, -1.0, 0],      # n+5..: in a row
                    [3.0, -1.0, 0], [3.0, -1.001, 0]]])               # needle with n+5
    F = np.vstack([F, F[:1], [[F[0, 0], F[0, 0], F[0, 1]]], [[F[0, 0], F[0, 1], n]],
                   [[n + 2, n + 4, n + 3]], [[n + 5, n + 6, n + 7]], [[n + 5, n + 8, n + 9]]])
    return _obj(tmp_path / "defects.obj", V, F)


def _two_parts(tmp_path):
    V, F = _grid()
    return _obj(tmp_path / "parts.obj", np.vstack([V, V + [3, 0, 0], V + [6, 0, 0]]),
                np.vstack([F, F + len(V), F + 2 * len(V)]))


def _codes(output):
    lines = [line for line in output.splitlines() if line.startswith("srarap: warning:")]
    bad = [line for line in lines if not LINE.match(line) or LINE.match(line)[1] not in CODES]
    assert not bad, bad
    return {LINE.match(line)[1] for line in lines}


def _deform(mesh, handles, tmp_path, *args):
    r = run_cli(["deform", mesh, handles, "-o", tmp_path / "out.obj",
                 "--max-iter", "3", "--keep-unconverged", *args])
    assert r.returncode in (0, 3), r.stderr
    return _codes(r.stderr)


def test_every_code_reaches_the_user_with_its_code(tmp_path):
    seen = set()
    grid = _obj(tmp_path / "grid.obj", *_grid())
    h = tmp_path / "h.yaml"
    for extra in ({"translate": [50, 0, 0]}, {"rotate": {"axis": [0, 0, 1], "angle_rad": 30}},
                  {"rotate": {"axis": [0, 0, 1], "angle_deg": 720}},
                  {"rotate": {"axis": [0, 0, 1], "angle_deg": 270}},
                  {"matrix": [[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]},
                  {"rotate": {"quaternion": [2, 0, 0, 0.1]}}):
        doc = _bend()
        doc["groups"]["move"] = {**FAR, **extra}
        far = ["--allow", "units"] if "translate" in extra else []  # else refused at once
        seen |= _deform(grid, _yaml(h, doc), tmp_path, *far)
    seen |= _deform(grid, _yaml(h, _bend()), tmp_path, "--weights", "cotan")
    seen |= _deform(grid, _yaml(h, _bend()), tmp_path, "--multires", "1000")
    seen |= _deform(grid, _yaml(h, {"groups": {"fix": {**EDGE, "fixed": True}}}), tmp_path)
    every = {"box": {"min": [-1, -1, -1], "max": [2, 2, 1]}, "translate": [0, 0, 0.1]}
    seen |= _deform(grid, _yaml(h, {"groups": {"all": every}}), tmp_path)
    parts = _two_parts(tmp_path)
    doc = {"groups": {"fix": {**EDGE, "fixed": True},
                      "carry": {"box": {"min": [2.9, -1, -1], "max": [4.1, 2, 1]},
                                "translate": [0, 0, 1]}}}
    seen |= _deform(parts, _yaml(h, doc), tmp_path)
    seen |= _deform(_defective(tmp_path), _yaml(h, _bend()), tmp_path, "--weights", "cotan")
    tube = tube_mesh()
    write_mesh(tmp_path / "tube.obj", tube)  # with texture coordinates, which STL drops
    doc = {"groups": {"fix": {"box": {"min": [-2, -2, -0.1], "max": [2, 2, 0.1]}, "fixed": True},
                      "top": {"box": {"min": [-2, -2, 5.9], "max": [2, 2, 6.1]},
                              "translate": [0, 0.5, 0]}}}
    r = run_cli(["deform", tmp_path / "tube.obj", _yaml(h, doc), "-o", tmp_path / "t.stl"])
    seen |= _codes(r.stderr)
    # a mesh of many tiny parts simplifies hardly at all; a tiny coarse size changes topology
    soup_V, soup_F = _grid(12)
    soup_V = soup_V[soup_F].reshape(-1, 3)
    soup = _obj(tmp_path / "soup.obj", soup_V, np.arange(len(soup_V)).reshape(-1, 3))
    doc = {"groups": {"fix": {"box": {"min": [-1, -1, -1], "max": [0.2, 2, 1]}, "fixed": True}}}
    seen |= _deform(soup, _yaml(h, doc), tmp_path, "--multires", "50")
    tor = tmp_path / "torus.obj"
    _obj(tor, *torus(rings=40, segments=20))
    doc = {"groups": {"fix": {"box": {"min": [1.0, -3, -1], "max": [3, 3, 1]}, "fixed": True},
                      "move": {"box": {"min": [-3, -3, -1], "max": [-1.0, 3, 1]},
                               "translate": [0, 0, 0.2]}}}
    seen |= _deform(tor, _yaml(h, doc), tmp_path, "--multires", "6")
    (tmp_path / "a-file").write_text("")
    seen |= _deform(tor, _yaml(h, doc), tmp_path, "--multires", "30", "--cache",
                    tmp_path / "a-file" / "sub")
    _deform(tor, _yaml(h, doc), tmp_path, "--multires", "30", "--cache", tmp_path / "cache")
    for entry in (tmp_path / "cache").iterdir():
        entry.write_bytes(b"not an npz")
    seen |= _deform(tor, _yaml(h, doc), tmp_path, "--multires", "30", "--cache",
                    tmp_path / "cache")
    # no mesh here makes the simplification change the topology: its check is called
    seen |= {w.code for w in _topology_warnings(torus()[1], _grid()[1], len(torus()[0]), 36)}
    keys = {"groups": {"fix": {**EDGE, "fixed": True},
                       "move": {**FAR, "keyframes": [{"frame": 0, "translate": [0, 0, 0]},
                                                     {"frame": 9, "translate": [0, 0, 0.2]}]}}}
    pattern = str(tmp_path / "f_{}.obj")
    for frames in ("4", "3"):  # keys past frame 3; the rerun leaves frame 3 of the first stale
        r = run_cli(["animate", grid, _yaml(h, keys), "-o", pattern, "--frames", frames,
                     "--max-iter", "3", "--keep-unconverged"])
        assert r.returncode in (0, 3), r.stderr
        seen |= _codes(r.stderr)
    assert seen == set(CODES), sorted(set(CODES) - seen)


# --- strict levels and allow, from every place they are given ----------------------------

def _noted(tmp_path):
    """The grid with a duplicate face and an unreferenced vertex: notes, no request warning."""
    V, F = _grid()
    return _obj(tmp_path / "noted.obj", np.vstack([V, [[3.0, 3, 3]]]), np.vstack([F, F[:1]]))


def _manifest(tmp_path, defaults, job_settings=None):
    mesh, h = _noted(tmp_path), _yaml(tmp_path / "h.yaml", _bend())
    far = _yaml(tmp_path / "far.yaml", _bend({"translate": [10, 0, 0]}))
    jobs = [{"name": "noted", "mesh": str(mesh), "handles": str(h), "output": "noted.obj",
             **({"settings": job_settings} if job_settings else {})},
            {"name": "far", "mesh": str(mesh), "handles": str(far), "output": "far.obj"}]
    return _yaml(tmp_path / "jobs.yaml", {"defaults": {"max_iter": 3, **defaults},
                                          "jobs": jobs})


def _statuses(tmp_path, out):
    rows = json.loads((tmp_path / out / "summary.json").read_text())
    return {r["job"]: (r["status"], r["exit_code"]) for r in rows}, rows


@pytest.mark.parametrize("how", ["flag", "manifest"])
def test_a_manifest_of_meshes_with_notes_passes_strict_and_fails_strict_all(tmp_path, how):
    flags = {"flag": (["--strict"], ["--strict=all"]), "manifest": ([], [])}[how]
    levels = {"flag": ({}, {}), "manifest": ({"strict": True}, {"strict": "all"})}[how]
    r = run_cli(["batch", _manifest(tmp_path, levels[0]), "-o", tmp_path / "a",
                 "--keep-unconverged", *flags[0]])
    got, rows = _statuses(tmp_path, "a")
    assert got["noted"][1] in (0, 3), r.stderr  # notes only: passes under --strict
    assert got["far"] == ("failed", 4), r.stderr  # a translation twice the mesh: fails
    far = next(row for row in rows if row["job"] == "far")
    assert "[units]" in far["message"] and "[duplicate-faces]" not in far["message"]
    noted = next(row for row in rows if row["job"] == "noted")
    assert {as_note(w).code for w in noted["warnings"]} == {"duplicate-faces",
                                                           "unreferenced-vertices"}
    r = run_cli(["batch", _manifest(tmp_path, levels[1]), "-o", tmp_path / "b",
                 "--keep-unconverged", *flags[1]])
    got, rows = _statuses(tmp_path, "b")
    assert got["noted"] == ("failed", 4), r.stderr
    message = next(row for row in rows if row["job"] == "noted")["message"]
    # every warning that failed it, in the one message
    assert "[duplicate-faces]" in message and "[unreferenced-vertices]" in message


def test_allow_adds_up_from_the_manifest_the_job_and_the_command_line(tmp_path):
    manifest = _manifest(tmp_path, {"strict": "all", "allow": ["units"]},
                         {"allow": "duplicate-faces"})
    r = run_cli(["batch", manifest, "-o", tmp_path / "a", "--keep-unconverged",
                 "--allow", "unreferenced-vertices"])
    got, rows = _statuses(tmp_path, "a")
    assert got["noted"][1] in (0, 3), r.stderr
    far = next(row for row in rows if row["job"] == "far")["message"]  # its own duplicate face
    assert got["far"] == ("failed", 4) and "[duplicate-faces]" in far and "[units]" not in far
    r = run_cli(["batch", manifest, "-o", tmp_path / "b", "--keep-unconverged"])
    got, rows = _statuses(tmp_path, "b")
    assert got["noted"] == ("failed", 4), r.stderr  # the unreferenced vertex is not allowed
    message = next(row for row in rows if row["job"] == "noted")["message"]
    assert "[unreferenced-vertices]" in message and "[duplicate-faces]" not in message


def test_deform_strict_levels_from_the_handle_file_and_the_command_line(tmp_path):
    mesh = _noted(tmp_path)
    out = tmp_path / "o.obj"
    for solver, args, code in (({}, ["--strict"], 0), ({}, ["--strict=all"], 4),
                               ({"strict": "all"}, [], 4), ({"strict": True}, [], 0),
                               ({"strict": "all", "allow": ["duplicate-faces"]},
                                ["--allow", "unreferenced-vertices"], 0),
                               ({"strict": "all"}, ["--allow", "duplicate-faces"], 4)):
        h = _yaml(tmp_path / "h.yaml", {**_bend(), "solver": {"max_iter": 3, **solver}})
        r = run_cli(["deform", mesh, h, "-o", out, "--keep-unconverged", *args])
        assert (r.returncode == 4) == (code == 4), (solver, args, r.stderr)
        assert out.exists() == (code != 4)
        if code == 4:
            assert r.stderr.count("srarap: error:") == 1 and "--allow CODE" in r.stderr
        out.unlink(missing_ok=True)


def test_a_bare_strict_never_takes_the_mesh_as_its_value(tmp_path):
    h = _yaml(tmp_path / "h.yaml", {**_bend(), "solver": {"max_iter": 3}})
    r = run_cli(["deform", "--strict", _noted(tmp_path), h, "-o", tmp_path / "o.obj",
                 "--keep-unconverged"])
    assert r.returncode in (0, 3), r.stderr
    r = run_cli(["deform", "--strict=some", _noted(tmp_path), h, "-o", tmp_path / "o.obj"])
    assert r.returncode == 2 and "'some' is not one of" in r.stderr
    r = run_cli(["deform", _noted(tmp_path), h, "-o", tmp_path / "o.obj", "--allow", "nope"])
    assert r.returncode == 2 and "--allow" in r.stderr
    h = _yaml(tmp_path / "h.yaml", {**_bend(), "solver": {"allow": ["nope"]}})
    r = run_cli(["deform", _noted(tmp_path), h, "-o", tmp_path / "o.obj"])
    assert r.returncode == 4 and "allow has no warning code 'nope'" in r.stderr
