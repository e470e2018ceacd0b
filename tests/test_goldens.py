"""Goldens that manage themselves (``tasks/comparison/goldens.py`` through ``srarap batch``):
a missing golden is its own status, ``--update-goldens`` writes exactly the goldens that are
missing or regressed (the others keep their bytes and time stamps), ``--accept-goldens``
passes, every output says which were written, and nothing is written outside the manifest's
folder or onto an input."""
import csv
import json
import os
import re
import shutil
import xml.etree.ElementTree as ET

import pytest
import yaml
from helpers import ROOT, run_cli

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
CONFIGS = os.path.join(ROOT, "configs")
JOBS = ("twist", "bend", "stiff")


@pytest.fixture()
def project(tmp_path):
    """A fresh project: the bar, two handle files, a manifest of three jobs whose goldens
    are not made yet (in ``golden/``)."""
    shutil.copy(BAR, tmp_path / "bar.obj")
    for name in ("bar-twist.yaml", "bar-bend.yaml"):
        shutil.copy(os.path.join(CONFIGS, name), tmp_path / name)
    shutil.copy(os.path.join(CONFIGS, "bar-bend.yaml"), tmp_path / "stiff.yaml")
    jobs = [{"name": name, "mesh": "bar.obj", "handles": handles, "output": f"{name}.obj",
             "settings": settings,
             "expect": {"golden": f"golden/{name}.obj", "tol": 1e-9, "relative": True}}
            for name, handles, settings in (("twist", "bar-twist.yaml", {}),
                                            ("bend", "bar-bend.yaml", {}),
                                            ("stiff", "stiff.yaml", {"alpha": 1.4}))]
    (tmp_path / "jobs.yaml").write_text(yaml.safe_dump({"defaults": {"max_iter": 300},
                                                        "jobs": jobs}))
    return tmp_path


def batch(project, *extra):
    out = project / "out"
    r = run_cli(["batch", project / "jobs.yaml", "-o", out, "--report", out / "r.html",
                 "--junit", out / "j.xml", "--summary-md", out / "s.md", "--metrics",
                 out / "metrics.txt", *extra])
    with open(out / "summary.csv") as fh:
        rows = {row["job"]: row for row in csv.DictReader(fh)}
    return r, rows


def goldens(project):
    """name -> (bytes, mtime) of everything in the golden folder."""
    folder = project / "golden"
    return {f.name: (f.read_bytes(), f.stat().st_mtime_ns) for f in sorted(folder.iterdir())} \
        if folder.exists() else {}


def junit_cases(project):
    root = ET.parse(project / "out" / "j.xml").getroot()
    return {c.get("name"): c for c in root.iter("testcase")}


def test_the_life_of_a_suite_first_run_update_rerun_change(project):
    r, rows = batch(project)
    assert r.returncode == 8 and {row["status"] for row in rows.values()} == {"no-golden"}
    assert all(row["exit_code"] == "8" for row in rows.values())
    assert "3 job(s) without a golden: srarap batch" in r.stderr
    assert "--update-goldens creates them" in r.stderr and not (project / "golden").exists()
    assert all(c.find("failure").get("type") == "no-golden"
               for c in junit_cases(project).values())
    assert (project / "out" / "r.html").read_text().count(">no-golden</span>") == 3
    assert (project / "out" / "s.md").read_text().count("**no-golden**") == 3

    r, rows = batch(project, "--update-goldens")  # created, and still a failing run
    assert r.returncode == 8 and "goldens written (created: twist, bend, stiff)" in r.stderr
    assert {row["golden"] for row in rows.values()} == {"created"}
    for name in JOBS:
        assert (project / "golden" / f"{name}.obj").read_bytes() == \
            (project / "out" / f"{name}.obj").read_bytes()
        record = json.loads((project / "golden" / f"{name}.obj.srarap.json").read_text())
        assert record["iterations"] == int(rows[name]["iterations"])
        assert record["energy"] == float(rows[name]["energy"])
    made = goldens(project)

    r, rows = batch(project)  # plain: passes, writes nothing there
    assert r.returncode == 0 and {row["status"] for row in rows.values()} == {"up-to-date"}
    assert goldens(project) == made

    bend = project / "bar-bend.yaml"
    bend.write_text(bend.read_text().replace("angle_deg: 60", "angle_deg: 61"))
    r, rows = batch(project)
    assert r.returncode == 8 and rows["bend"]["status"] == "regressed"
    assert rows["stiff"]["status"] == "up-to-date" and goldens(project) == made
    r, rows = batch(project, "--update-goldens")
    assert r.returncode == 8 and "goldens written (updated: bend)" in r.stderr
    now = goldens(project)
    for name in ("twist.obj", "twist.obj.srarap.json", "stiff.obj", "stiff.obj.srarap.json"):
        assert now[name] == made[name]  # bytes and time stamp kept
    assert now["bend.obj"][0] != made["bend.obj"][0]
    assert now["bend.obj"][0] == (project / "out" / "bend.obj").read_bytes()
    assert [rows[n]["golden"] for n in JOBS] == ["", "updated", ""]
    cases = junit_cases(project)
    assert "golden updated by this run" in cases["bend"].find("failure").get("message")
    assert cases["twist"].find("failure") is None
    assert "goldens written by this run: bend (updated)<" in \
        (project / "out" / "r.html").read_text()
    assert "Goldens written by this run: bend (updated)." in (project / "out" / "s.md").read_text()
    r, rows = batch(project)
    assert r.returncode == 0 and goldens(project) == now


def test_accept_goldens_passes_and_a_golden_in_another_format_is_encoded(project):
    manifest = yaml.safe_load((project / "jobs.yaml").read_text())
    manifest["jobs"][0]["expect"]["golden"] = "golden/twist.ply"
    (project / "jobs.yaml").write_text(yaml.safe_dump(manifest))
    r, rows = batch(project, "--accept-goldens")
    assert r.returncode == 0 and {row["status"] for row in rows.values()} == {"ok"}
    assert "accepted as the truth" in r.stderr
    assert (project / "golden" / "twist.ply").read_bytes().startswith(b"ply\n")
    r, rows = batch(project)
    assert r.returncode == 0


@pytest.mark.parametrize("golden, words", [
    ("../elsewhere/twist.obj", "a golden is written only inside"),
    ("bar.obj", "is the mesh of job 'twist'"),
    ("bar-bend.yaml", "is the handle file of job 'bend'"),
    ("jobs.yaml", "is the manifest"),
])
def test_update_never_writes_outside_the_manifests_folder_or_onto_an_input(project, golden,
                                                                          words):
    manifest = yaml.safe_load((project / "jobs.yaml").read_text())
    manifest["jobs"][0]["expect"]["golden"] = golden
    (project / "jobs.yaml").write_text(yaml.safe_dump(manifest))
    before = {p: p.read_bytes() for p in project.iterdir() if p.is_file()}
    r = run_cli(["batch", project / "jobs.yaml", "-o", project / "out", "--update-goldens"])
    assert r.returncode == 4 and words in r.stderr and len(r.stderr.splitlines()) == 1
    assert {p: p.read_bytes() for p in project.iterdir() if p.is_file()} == before
    assert not (project / "elsewhere").exists()


def test_a_golden_folder_linked_out_of_the_tree_is_refused(project, tmp_path_factory):
    outside = tmp_path_factory.mktemp("outside")
    (project / "golden").symlink_to(outside, target_is_directory=True)
    r = run_cli(["batch", project / "jobs.yaml", "-o", project / "out", "--update-goldens"])
    assert r.returncode == 4 and "leads to" in r.stderr and not os.listdir(outside)


def test_two_jobs_writing_one_golden_are_refused_only_when_updating(project):
    manifest = yaml.safe_load((project / "jobs.yaml").read_text())
    manifest["jobs"][2]["expect"]["golden"] = "golden/bend.obj"
    (project / "jobs.yaml").write_text(yaml.safe_dump(manifest))
    r = run_cli(["batch", project / "jobs.yaml", "-o", project / "out", "--update-goldens"])
    assert r.returncode == 4 and "is also job 'bend''s" in r.stderr


@pytest.mark.parametrize("gate, value, words", [
    ("energy_rtol", 1e-9, "energy "),
    ("max_iterations", 1, "iterations "),
    ("beyond_tol", 0.0, "max distance "),
])
def test_each_gate_of_a_manifest_fails_a_job_alone(project, gate, value, words):
    """The goldens made, then one job's gate tightened (or, for the fraction, its handles
    changed): that job regresses with that gate named, the others pass."""
    batch(project, "--accept-goldens")
    manifest = yaml.safe_load((project / "jobs.yaml").read_text())
    manifest["jobs"][0]["expect"][gate] = value
    if gate == "energy_rtol":  # the twist solved to a looser tolerance: another energy,
        manifest["jobs"][0]["settings"] = {"tol": 1e-2}  # positions within a loose tol
        manifest["jobs"][0]["expect"]["tol"] = 0.01
    if gate == "beyond_tol":
        manifest["jobs"][0]["settings"] = {"alpha": 0.2}
    (project / "jobs.yaml").write_text(yaml.safe_dump(manifest))
    r, rows = batch(project)
    assert r.returncode == 8 and rows["twist"]["status"] == "regressed"
    assert rows["twist"]["message"].startswith(words), rows["twist"]["message"]
    assert rows["twist"]["message"].count(";") == (1 if gate == "beyond_tol" else 0)
    assert rows["bend"]["status"] == rows["stiff"]["status"] == "up-to-date"


def test_a_misspelt_expect_key_is_exit_4_naming_it(project):
    manifest = yaml.safe_load((project / "jobs.yaml").read_text())
    manifest["jobs"][1]["expect"]["max_iteration"] = 3
    (project / "jobs.yaml").write_text(yaml.safe_dump(manifest))
    r = run_cli(["batch", project / "jobs.yaml", "-o", project / "out"])
    assert r.returncode == 4 and "job 1: unknown key 'max_iteration' in expect; did you mean " \
        "'max_iterations'?" in r.stderr


#: a value of every gate, as the regression guide's table documents it
GATE_VALUES = {"tol": 1e-6, "relative": True, "beyond_tol": 0.01, "p95": 1e-6, "p99": 1e-6,
               "energy_rtol": 1e-4, "max_iterations": 300, "iterations_within": 3,
               "max_seconds": 600, "align": "rigid"}
#: the gates ``compare`` takes as options (it has no solve: no energy, iterations or seconds)
COMPARE_OPTIONS = {"tol": "--tol", "relative": "--relative", "beyond_tol": "--beyond-tol",
                   "p95": "--p95", "p99": "--p99", "align": "--align"}


def test_every_gate_is_documented_and_runs_from_a_manifest_the_fixture_and_compare(
        project, tmp_path):
    from srarap_cli.io.mesh import read_mesh
    from srarap_cli.tasks.comparison import GATE_KEYS, CompareJob, run_compare
    from srarap_cli.tasks.regression_check import check_against_golden

    assert set(GATE_VALUES) == set(GATE_KEYS)
    guide = open(os.path.join(ROOT, "docs", "guides", "regression.md")).read()
    for key in ("golden", *GATE_KEYS):
        assert re.search(rf"^\| (`\w+`, )?`{key}`", guide, re.MULTILINE), key
    manifest = yaml.safe_load((project / "jobs.yaml").read_text())
    manifest["jobs"][0]["expect"].update(GATE_VALUES)
    (project / "jobs.yaml").write_text(yaml.safe_dump(manifest))
    r, rows = batch(project, "--accept-goldens")  # from a manifest
    assert r.returncode == 0 and rows["twist"]["status"] == "ok"
    r, rows = batch(project)
    assert r.returncode == 0 and rows["twist"]["status"] == "up-to-date"
    golden = str(project / "golden" / "twist.obj")
    done = check_against_golden(read_mesh(golden), golden, "check",  # the fixture's keywords
                                {k: v for k, v in GATE_VALUES.items()
                                 if k not in ("energy_rtol", "max_iterations",
                                              "iterations_within")})
    assert done.failure is None
    run_gates = check_against_golden(read_mesh(golden), golden, "check", GATE_VALUES)
    assert "energy: this result has none to gate" in run_gates.failure  # a mesh: no solve
    args = []
    for key, option in COMPARE_OPTIONS.items():  # the command line
        value = GATE_VALUES[key]
        args += [option] if value is True else [option, str(value)]
    r = run_cli(["compare", golden, golden, *args])
    assert r.returncode == 0, r.stderr
    python = run_compare(CompareJob(golden, golden,
                                    **{k: GATE_VALUES[k] for k in COMPARE_OPTIONS}))
    assert python.exit_code == 0


def test_a_golden_of_another_frame_or_mesh_says_how_far_each_way_in_every_output(project):
    """A golden moved rigidly passes with ``align: rigid`` and the motion is said; a golden
    that does not share the output's vertices (another job's shape with one stray vertex
    more) reports both one-sided distances in the summary, the card and JUnit."""
    import numpy as np

    from srarap_cli.io.mesh import Mesh, read_mesh, write_mesh
    batch(project, "--accept-goldens")
    made = read_mesh(str(project / "golden" / "twist.obj"))
    turn = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    write_mesh(str(project / "golden" / "twist.obj"), made.with_vertices(made.vertices @ turn.T + 5))
    V, F = made.vertices, made.triangles()[0]
    write_mesh(str(project / "golden" / "bend.obj"),
               Mesh.from_arrays(np.vstack([V, [[0.0, 0, 100]]]), F))  # one stray vertex more
    manifest = yaml.safe_load((project / "jobs.yaml").read_text())
    manifest["jobs"][0]["expect"]["align"] = "rigid"
    (project / "jobs.yaml").write_text(yaml.safe_dump(manifest))
    r, rows = batch(project)
    assert rows["twist"]["status"] == "up-to-date", rows["twist"]["message"]
    assert rows["twist"]["aligned"].startswith("turned 90 degrees about (0, 0, 1), moved by (5, 5, 5)")
    bend = rows["bend"]
    assert bend["status"] == "regressed" and float(bend["compare_a_to_b"]) > 0
    assert float(bend["compare_b_to_a"]) >= 0 and bend["compare_a_to_b"] != bend["compare_b_to_a"]
    message = junit_cases(project)["bend"].find("failure").get("message")
    assert "one-sided: A to B max" in message
    html = (project / "out" / "r.html").read_text()
    assert "<th>A to B</th>" in html and "aligned first: turned 90 degrees" in html
