"""``srarap deform`` end to end: outputs, logs, determinism and exit codes."""
import csv
import json
import os
import subprocess
import sys

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from helpers import ROOT, run_cli, tube_mesh

from srarap_cli.cli import main
from srarap_cli.io.mesh import read_mesh, write_mesh

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
TWIST = os.path.join(ROOT, "configs", "bar-twist.yaml")


def run(*args):
    return CliRunner().invoke(main, ["deform", *map(str, args)])


@pytest.fixture()
def small(tmp_path):
    """A small quad tube with UVs and a handle file bending it."""
    mesh_path = tmp_path / "tube.obj"
    write_mesh(str(mesh_path), tube_mesh(rings=6, segments=6))
    handles = {"groups": {
        "base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True},
        "tip": {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]},
                "rotate": {"axis": [0, 1, 0], "angle": 40}, "translate": [1, 0, 0]}}}
    handle_path = tmp_path / "h.yaml"
    handle_path.write_text(yaml.safe_dump(handles))
    return mesh_path, handle_path


def test_sample_case_converges_and_keeps_uvs_and_polygons(tmp_path):
    out, log = tmp_path / "bar.obj", tmp_path / "bar.csv"
    r = run(BAR, TWIST, "-o", out, "--log", log)
    assert r.exit_code == 0, r.output
    src, res = read_mesh(BAR), read_mesh(str(out))
    assert np.array_equal(res.face_sizes, src.face_sizes)
    assert np.array_equal(res.face_vertices, src.face_vertices)
    assert np.array_equal(res.uv, src.uv) and np.array_equal(res.face_uv, src.face_uv)
    base = src.vertices[:, 2] < 1e-9
    assert np.array_equal(res.vertices[base], src.vertices[base])
    top = src.vertices[:, 2] > 10 - 1e-9
    x, y = src.vertices[top][:, 0], src.vertices[top][:, 1]  # 90 degrees about z: (-y, x)
    assert np.allclose(res.vertices[top][:, :2], np.column_stack([-y, x]), atol=1e-12)
    with open(log) as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["iteration", "membrane", "bending", "total", "rel_change",
                             "max_move", "seconds", "step", "stop"]
    assert float(rows[-1]["rel_change"]) <= 1e-6 and "converged" in r.stderr
    assert [row["stop"] for row in rows] == [""] * (len(rows) - 1) + ["converged"]


def test_same_inputs_give_byte_identical_output(small, tmp_path):
    mesh, handles = small
    outs = [tmp_path / "a.ply", tmp_path / "b.ply"]
    for out in outs:
        assert run(mesh, handles, "-o", out, "--max-iter", 30, "-q").exit_code in (0, 3)
    assert outs[0].read_bytes() == outs[1].read_bytes()


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".off"])
def test_every_output_format_keeps_vertex_order(small, tmp_path, suffix):
    mesh, handles = small
    out = tmp_path / f"out{suffix}"
    r = run(mesh, handles, "-o", out, "--max-iter", 5, "-q", "--keep-unconverged")
    assert r.exit_code == 3  # 5 iterations do not converge
    # quiet: warnings only (PLY drops the bar's seamed UVs), no summary line
    assert all(line.startswith("srarap: warning: ") for line in r.stderr.splitlines())
    a, b = read_mesh(str(mesh)), read_mesh(str(out))
    assert len(b.vertices) == len(a.vertices)
    assert np.array_equal(b.face_vertices, a.face_vertices)
    assert np.array_equal(b.vertices[:6], a.vertices[:6])  # base ring, fixed


def test_jsonl_log_and_option_override(small, tmp_path):
    mesh, handles = small
    log = tmp_path / "log.jsonl"
    r = run(mesh, handles, "-o", tmp_path / "o.obj", "--log", log, "--max-iter", 4)
    rows = [json.loads(line) for line in log.read_text().splitlines()]
    assert [row["iteration"] for row in rows] == [0, 1, 2, 3, 4]
    assert rows[0]["rel_change"] is None
    assert all(row["total"] == row["membrane"] + row["bending"] for row in rows)
    assert r.exit_code == 3 and "NOT converged after 4 full-resolution iterations" in r.stderr


def test_solver_settings_in_file_apply_unless_overridden(small, tmp_path):
    mesh, handles = small
    doc = yaml.safe_load(handles.read_text())
    doc["solver"] = {"max_iter": 2}
    handles.write_text(yaml.safe_dump(doc))
    log = tmp_path / "l.csv"
    run(mesh, handles, "-o", tmp_path / "o.obj", "--log", log)
    assert len(log.read_text().splitlines()) == 1 + 3
    run(mesh, handles, "-o", tmp_path / "o.obj", "--log", log, "--max-iter", 1)
    assert len(log.read_text().splitlines()) == 1 + 2


def test_region_of_interest_leaves_the_rest_untouched(small, tmp_path):
    mesh, handles = small
    doc = yaml.safe_load(handles.read_text())
    doc["region"] = {"box": {"min": [-2, -2, 3.9], "max": [2, 2, 7]}}
    handles.write_text(yaml.safe_dump(doc))
    out = tmp_path / "o.obj"
    assert run(mesh, handles, "-o", out, "-q").exit_code == 0
    a, b = read_mesh(str(mesh)).vertices, read_mesh(str(out)).vertices
    outside = a[:, 2] < 3.9
    assert np.array_equal(a[outside], b[outside])
    assert np.abs(a[~outside] - b[~outside]).max() > 0.5


def test_missing_mesh_is_invalid_input_without_traceback(small, tmp_path):
    _, handles = small
    out = tmp_path / "o.obj"
    r = run(tmp_path / "nope.obj", handles, "-o", out)
    assert r.exit_code == 4 and "nope.obj" in r.stderr and "Traceback" not in r.output
    assert not out.exists()


def test_malformed_handle_file_is_invalid_input_and_writes_nothing(small, tmp_path):
    mesh, _ = small
    bad = tmp_path / "bad.yaml"
    bad.write_text("groups:\n  tip:\n    sphere: {center: [0, 0, 0], radius: -1}\n    fixed: true\n")
    out = tmp_path / "o.obj"
    r = run(mesh, bad, "-o", out)
    assert r.exit_code == 4
    assert r.stderr.strip() == f"srarap: error: {bad}: group 'tip': radius must be > 0"
    assert not out.exists()


def test_usage_and_output_errors(small, tmp_path):
    mesh, handles = small
    assert run(mesh, handles, "-o", tmp_path / "o.xyz").exit_code == 2
    assert run(mesh, handles, "-o", tmp_path / "o.obj", "--alpha", "0").exit_code == 2
    r = run(mesh, handles, "-o", tmp_path / "new" / "folders" / "o.obj")  # made, as animate's
    assert r.exit_code == 0 and (tmp_path / "new" / "folders" / "o.obj").is_file()
    (tmp_path / "file").write_text("x")
    r = run(mesh, handles, "-o", tmp_path / "file" / "sub" / "o.obj")
    assert r.exit_code == 6 and "is a file, not a folder" in r.stderr


def test_existing_output_survives_a_failed_run(small, tmp_path):
    _, handles = small
    out = tmp_path / "o.obj"
    out.write_text("precious")
    bad_mesh = tmp_path / "bad.off"
    bad_mesh.write_text("OFF\n3 1 0\n0 0 0\n")
    assert run(bad_mesh, handles, "-o", out).exit_code == 4
    assert out.read_text() == "precious"
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".srarap-")] == []


def test_module_entry_point_and_console_script(small, tmp_path):
    mesh, handles = small
    out = tmp_path / "o.off"
    cmd = [sys.executable, "-m", "srarap_cli", "deform", str(mesh), str(handles), "-o", str(out)]
    p = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert p.returncode == 0 and "converged" in p.stderr and out.exists()
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", str(mesh),
                        str(tmp_path / "missing.yaml"), "-o", str(out)],
                       capture_output=True, text=True, check=False)
    assert p.returncode == 4 and "Traceback" not in p.stderr
    assert p.stderr.count("\n") == 1


def test_json_handles_and_sel_file_through_the_command(small, tmp_path):
    mesh, handles = small
    doc = yaml.safe_load(handles.read_text())
    (tmp_path / "h.json").write_text(json.dumps(doc))
    a, b = tmp_path / "a.obj", tmp_path / "b.obj"
    assert run(mesh, handles, "-o", a, "-q").exit_code == 0
    assert run(mesh, tmp_path / "h.json", "-o", b, "-q").exit_code == 0
    assert a.read_bytes() == b.read_bytes()
    V = read_mesh(str(mesh)).vertices
    status = np.where(V[:, 2] < 1e-9, 0, np.where(V[:, 2] > 6 - 1e-9, 2, 1))
    (tmp_path / "c.sel").write_text("# status\n# per vertex\n" + "\n".join(map(str, status)))
    (tmp_path / "c.def").write_text("# move\n1 0 0 0.5\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    out = tmp_path / "c.off"
    assert run(mesh, tmp_path / "c.sel", "-o", out, "-q").exit_code == 0
    P = read_mesh(str(out)).vertices
    assert np.array_equal(P[status == 0], V[status == 0])
    assert np.allclose(P[status == 2], V[status == 2] + [0.5, 0, 0], atol=1e-15)


HEAVY = ("numpy", "scipy", "igl", "meshio", "matplotlib", "distributed", "yaml",
         "srarap_cli.solver.multires.deformer", "srarap_cli.solver.multires.collapse")


@pytest.mark.parametrize("code", ["import srarap_cli",
                                  "from srarap_cli.cli import main\n"
                                  "main(['--help'], standalone_mode=False)"])
def test_the_package_and_the_top_level_help_load_no_numerical_stack(code):
    probe = code + "\nimport sys\nprint(sorted(m for m in sys.modules if m.split('.')[0] in " \
        f"{HEAVY!r} or m in {HEAVY!r}))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip().splitlines()[-1] == "[]"


def test_the_top_level_help_lists_each_commands_own_summary():
    from srarap_cli.cli import COMMANDS
    for name, (_, _, summary) in COMMANDS.items():
        assert main.get_command(None, name).get_short_help_str(limit=300) == summary
    listed = CliRunner().invoke(main, ["--help"]).output
    assert all(name in listed for name in COMMANDS)


def test_the_public_api_is_reachable_from_the_package():
    import srarap_cli
    for name in srarap_cli.__all__:
        assert getattr(srarap_cli, name) is not None
    with pytest.raises(AttributeError):
        srarap_cli.no_such_name  # noqa: B018


@pytest.mark.parametrize("args, words", [
    (["defrom", "m.obj", "h.yaml"], "No such command 'defrom'. Did you mean 'deform'?"),
    (["deform", "m.obj", "h.yaml", "-o", "x.obj", "--strict", "all"],
     "(all); a level of --strict goes after an equals sign: --strict=all"),
])
def test_a_usage_slip_gets_what_it_most_likely_meant(args, words):
    """Issue 70: 'srarap defrom' got no "did you mean", '--strict all' no hint."""
    r = run_cli(args)
    assert r.returncode == 2 and words in r.stderr and len(r.stderr.splitlines()) == 1
