"""Valid input that looks like a mistake: a warning naming file, group and value, exit 0;
``--strict`` (or ``strict: true`` in a handle file's solver section, a manifest's settings,
the API's keyword) makes the first warning the error, exit 4, nothing written."""
import csv
import os

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from helpers import ROOT, SHARED, needs_shared, rounded_turn

import srarap_cli
from srarap_cli.cli import main
from srarap_cli.io.handles import parse_handles
from srarap_cli.io.mesh import read_mesh, write_mesh

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
V = read_mesh(BAR).vertices  # 1 x 1 x 10: bounding-box diagonal sqrt(102)
BASE = {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True}
TOP = {"box": {"min": [-2, -2, 9.99], "max": [2, 2, 10.01]}}


def warnings_of(action, **top):
    doc = {"groups": {"base": BASE, "top": dict(TOP, **action, **top)}}
    return parse_handles(doc, V, "h.yaml").warnings


@pytest.mark.parametrize("radians", [6.3, -7.0, 30.0, 1e4])
def test_radians_beyond_a_full_turn_warn_with_the_value_in_degrees(radians):
    (w,) = warnings_of({"rotate": {"axis": [0, 0, 1], "angle_rad": radians}})
    assert w.startswith("h.yaml: group 'top': angle_rad ") and f"{np.degrees(radians):g}" in w
    assert "angle_deg" in w


@pytest.mark.parametrize("radians", [0.0, 0.5, -3.0, 3.0])
def test_radians_within_half_a_turn_and_explicit_degrees_are_quiet(radians):
    assert warnings_of({"rotate": {"axis": [0, 0, 1], "angle_rad": radians}}) == []
    assert warnings_of({"rotate": {"axis": [0, 0, 1], "angle_deg": -179.0}}) == []


@pytest.mark.parametrize("key, value, same", [("angle_deg", 3000.0, "120"),
                                              ("angle_deg", -190.0, "170"),
                                              ("angle_rad", 2 * np.pi, None),
                                              ("angle_deg", 1080, None)])
def test_a_static_turn_beyond_half_a_turn_says_what_it_reaches(key, value, same):
    """A static solve sees only where the vertices end: 3000 degrees lands where 120 does,
    a whole number of turns at the rest pose."""
    (w,) = warnings_of({"rotate": {"axis": [0, 0, 1], key: value}})
    assert (f"same targets as {same} degrees" in w) if same else ("whole turn(s)" in w)


def test_an_angle_without_unit_says_degrees_were_assumed_and_suspects_radians_when_small():
    (big,) = warnings_of({"rotate": {"axis": [0, 0, 1], "angle": 90}})
    (small,) = warnings_of({"rotate": {"axis": [0, 0, 1], "angle": 0.52}})
    for w in (big, small):
        assert "read as degrees" in w and "angle_deg or angle_rad" in w
    assert "radians" not in big.split(";")[0] and "looks like radians" in small


def test_a_motion_beyond_the_bounding_box_diagonal_warns_and_one_within_does_not():
    diagonal = float(np.linalg.norm(np.ptp(V, axis=0)))
    (far,) = warnings_of({"translate": [0, 0, 1.01 * diagonal]})
    assert "h.yaml: group 'top'" in far and f"{diagonal:.4g}" in far and "units" in far
    assert warnings_of({"translate": [0, 0, 0.99 * diagonal]}) == []
    # a matrix, a keyframe: the same test on where the vertices end up
    M = np.eye(4)
    M[0, 3] = 2 * diagonal
    assert len(warnings_of({"matrix": M.tolist()})) == 1
    (key,) = warnings_of({}, keyframes=[{"frame": 0}, {"frame": 4, "translate": [30, 0, 0]}])
    assert "keyframe 1" in key


@pytest.mark.parametrize("decimals", [4, 6, 12])
def test_a_rotation_matrix_written_with_rounded_decimals_is_a_rotation(decimals):
    for degrees in (10, 30, -45):  # within the bounding-box diagonal: no other warning
        M = rounded_turn([0, 1, 0], degrees, decimals)
        M[0, 3] = 0.5
        assert warnings_of({"matrix": M.tolist()}) == []


@pytest.mark.parametrize("diagonal, words", [
    ([1, 1.001, 1], "scales unevenly (by 1, 1.001, 1 along x, y, z)"),
    ([0.999, 0.999, 0.999], "scales by 0.999"),
    ([1.01, 1.01, 1.01], "scales by 1.01"),
])
def test_a_stretch_a_thousandth_or_more_warns_with_the_factors_it_has(diagonal, words):
    M = np.diag([*diagonal, 1.0]).tolist()
    (warning,) = warnings_of({"matrix": M})
    assert words in warning, warning


@needs_shared
def test_the_shared_cylinder_def_deforms_under_strict(tmp_path):
    # its matrix is a 120-degree turn written with six decimals (-0.866025, 0.866025)
    out = tmp_path / "out.obj"
    r = CliRunner().invoke(main, ["deform", os.path.join(SHARED, "cylinder.off"),
                                  os.path.join(SHARED, "cylinder.sel"), "-o", str(out),
                                  "--strict", "--max-iter", "3", "--tol", "0"])
    assert r.exit_code == 0 and "warning" not in r.stderr, r.stderr
    assert out.exists()


def run(tmp_path, handles, *extra, mesh=BAR):
    h = tmp_path / "h.yaml"
    h.write_text(yaml.safe_dump(handles))
    out = tmp_path / "out.obj"
    r = CliRunner().invoke(main, ["deform", mesh, str(h), "-o", str(out), *extra])
    return r, out


def test_the_silent_mistakes_exit_0_with_a_warning_and_4_under_strict(tmp_path):
    doc = {"groups": {"base": BASE, "top": dict(TOP, rotate={"axis": [0, 0, 1],
                                                             "angle_rad": 30})}}
    r, out = run(tmp_path, doc)
    assert r.exit_code == 0 and "warning:" in r.stderr and "angle_rad 30" in r.stderr
    out.unlink()
    r, out = run(tmp_path, doc, "--strict")
    assert r.exit_code == 4 and not out.exists()
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith("srarap: error: ") and "angle_rad 30" in line and "strict" in line
    r, out = run(tmp_path, dict(doc, solver={"strict": True}))
    assert r.exit_code == 4 and not out.exists()


def test_strict_refuses_mesh_warnings_too(tmp_path):
    # a triangle soup: every triangle its own corners, coincident with its neighbours'
    mesh = read_mesh(BAR)
    F = mesh.triangles()[0]
    soup = tmp_path / "soup.obj"
    write_mesh(str(soup), (mesh.vertices[F.ravel()], np.arange(F.size).reshape(-1, 3)))
    doc = {"groups": {"base": BASE, "top": dict(TOP, translate=[0, 0, 1])}}
    r, out = run(tmp_path, doc, mesh=str(soup))
    assert r.exit_code == 0 and "warning:" in r.stderr
    out.unlink()
    r, out = run(tmp_path, doc, "--strict", mesh=str(soup))
    assert r.exit_code == 4 and not out.exists() and "strict" in r.stderr


def test_a_manifest_job_with_strict_fails_with_the_warning(tmp_path):
    h = tmp_path / "h.yaml"
    h.write_text(yaml.safe_dump({"groups": {"base": BASE, "top": dict(TOP, translate=[0, 0, 20])}}))
    jobs = [{"name": "far", "mesh": BAR, "handles": str(h), "output": "far.obj",
             "settings": {"strict": True}},
            {"name": "lenient", "mesh": BAR, "handles": str(h), "output": "lenient.obj"}]
    m = tmp_path / "jobs.yaml"
    m.write_text(yaml.safe_dump({"defaults": {"max_iter": 50}, "jobs": jobs}))
    out = tmp_path / "out"
    CliRunner().invoke(main, ["batch", str(m), "-o", str(out)])
    with open(out / "summary.csv") as fh:
        rows = {row["job"]: row for row in csv.DictReader(fh)}
    assert rows["far"]["status"] == "failed" and not (out / "far.obj").exists()
    assert "units" in rows["far"]["message"] and "strict" in rows["far"]["message"]
    assert rows["lenient"]["status"] in ("ok", "not converged")


def test_the_api_raises_under_strict_and_lists_the_warning_otherwise():
    mesh = read_mesh(BAR)
    doc = {"groups": {"base": BASE, "top": dict(TOP, translate=[0, 0, 20])}}
    result = srarap_cli.deform(mesh, doc, max_iter=5)
    assert any("bounding-box diagonal" in w for w in result.warnings)
    with pytest.raises(ValueError, match="bounding-box diagonal"):
        srarap_cli.deform(mesh, doc, strict=True)
    with pytest.raises(TypeError, match="strict"):  # a solver class has no run settings
        srarap_cli.Deformer(mesh.vertices, mesh.triangles()[0], [0], strict=True)


@pytest.mark.parametrize("config", ["bar-twist.yaml", "bar-bend.yaml", "spot-nod.yaml"])
def test_the_shipped_handle_files_pass_strict(config, tmp_path):
    mesh = os.path.join(ROOT, "sample_meshes", "spot.obj" if "spot" in config else "bar.obj")
    out = tmp_path / "out.obj"
    r = CliRunner().invoke(main, ["deform", mesh, os.path.join(ROOT, "configs", config),
                                  "-o", str(out), "--strict"])
    assert r.exit_code == 0, r.stderr


def test_info_reports_what_deform_would_warn_about_the_handle_file(tmp_path):
    h = tmp_path / "h.yaml"
    h.write_text(yaml.safe_dump({"groups": {"base": BASE, "top": dict(
        TOP, rotate={"axis": [0, 0, 1], "angle_rad": 30})}}))
    r = CliRunner().invoke(main, ["info", BAR, str(h)])
    assert r.exit_code == 0 and "  warning: " in r.output and "angle_rad 30" in r.output
    r = CliRunner().invoke(main, ["info", BAR, str(h), "--json"])
    assert any("angle_rad 30" in w for w in yaml.safe_load(r.output)["warnings"])


def test_targets_several_diagonals_away_are_refused_at_once_unless_allowed(tmp_path):
    """A units slip (13.5 diagonals, as an audit's user made) is exit 4 before the setup,
    with the handle file's own line; --allow units solves it (and still says it)."""
    h = tmp_path / "h.yaml"
    h.write_text(yaml.safe_dump({"groups": {"base": BASE, "top": dict(TOP, translate=[0, 0, 140])}}))
    r = CliRunner().invoke(main, ["deform", BAR, str(h), "-o", str(tmp_path / "o.obj")])
    assert r.exit_code == 4 and not (tmp_path / "o.obj").exists()
    assert "13.5 times the mesh's bounding-box diagonal" in r.stderr
    assert "--allow units solves them" in r.stderr and len(r.stderr.splitlines()) == 1
    r = CliRunner().invoke(main, ["deform", BAR, str(h), "-o", str(tmp_path / "o.obj"),
                                  "--allow", "units", "--max-iter", "3", "--keep-unconverged"])
    assert r.exit_code in (0, 3) and "[units]" in r.stderr
    with pytest.raises(ValueError, match="--allow units"):
        srarap_cli.deform(read_mesh(BAR), (np.array([0]), np.array([[0.0, 0, 1000]])))
