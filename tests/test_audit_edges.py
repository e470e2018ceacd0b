"""The classes an outside audit found (issue 52), each checked against its contract: one line
and the documented exit code, nothing half-written, or it simply works."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest
import yaml
from helpers import ROOT, run_cli

import srarap_cli
from srarap_cli import Deformer, read_mesh
from srarap_cli.io.handles import parse_handles

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
TWIST = os.path.join(ROOT, "configs", "bar-twist.yaml")
V = read_mesh(BAR).vertices
BASE = {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True}
TOP = {"box": {"min": [-2, -2, 9.99], "max": [2, 2, 10.01]}}


def one_line(r, code):
    assert r.returncode == code, r.stderr
    lines = [line for line in r.stderr.splitlines() if line.startswith("srarap: error:")]
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    return lines[0]


# --- documents that refer to themselves ---------------------------------------------------

@pytest.mark.timeout(60)
@pytest.mark.parametrize("text", ["a: &a [*a]\n", "a: &a {b: *a}\n", "a: &a [1, [2, {c: *a}]]\n",
                                  "- &a [*a, *a]\n"])
def test_a_document_that_refers_to_itself_is_refused_at_once(tmp_path, text):
    path = tmp_path / "r.yaml"
    path.write_text(text + ("groups: {f: {indices: [0], fixed: true}}\n"
                            if not text.startswith("-") else ""))
    for args in (["info", BAR, path], ["deform", BAR, path, "-o", tmp_path / "o.obj"]):
        line = one_line(run_cli(args), 4)
        assert "refers to itself" in line and str(path) in line
    manifest = tmp_path / "m.yaml"
    manifest.write_text("x: &x [*x]\njobs: []\n")
    assert "refers to itself" in one_line(run_cli(["batch", manifest, "-o", tmp_path]), 4)


def test_shared_aliases_that_do_not_loop_are_read():
    from srarap_cli.io.documents import _check_graph

    node = yaml.compose("a: &x [1, 2]\nb: [*x, *x, {c: *x}]\n", Loader=yaml.SafeLoader)
    _check_graph(node, "ok.yaml")  # no error


# --- numbers as YAML and JSON spell them ----------------------------------------------------

@pytest.mark.parametrize("spelled, value", [("9e1", 90.0), ("90", 90.0), ("9.0e1", 90.0),
                                            ("+9E+1", 90.0), ("1_0", 10.0)])
def test_a_scalar_reads_as_the_number_it_spells_like_a_vector_does(spelled, value):
    doc = yaml.safe_load(f"groups:\n  base: {json.dumps(BASE)}\n  top:\n"
                         f"    box: {json.dumps(TOP['box'])}\n"
                         f"    rotate: {{axis: [0, 0, {spelled}], angle_deg: {spelled}}}\n")
    c = parse_handles(doc, V)
    ref = parse_handles({"groups": {"base": BASE, "top": {
        **TOP, "rotate": {"axis": [0, 0, 1], "angle_deg": value}}}}, V)
    assert np.allclose(c.targets, ref.targets, atol=1e-12)


def test_times_frames_and_settings_take_exponents_without_a_dot():
    doc = yaml.safe_load("solver: {tol: 1e-6, max_iter: 1e3}\ngroups:\n"
                         f"  base: {json.dumps(BASE)}\n  top:\n    box: {json.dumps(TOP['box'])}\n"
                         "    keyframes:\n      - {time: 0}\n      - {time: 5e-1, translate: [0, 1, 0]}\n"
                         "      - {frame: 2e1, translate: [0, 2, 0]}\n")
    c = parse_handles(doc, V, fps=24)
    assert c.solver == {"tol": 1e-6, "max_iter": 1000}
    assert c.tracks[0][2].frames.tolist() == [0.0, 12.0, 20.0]


@pytest.mark.parametrize("value, words", [("1" + "0" * 400, "beyond the float range"),
                                          ("1e400", "must be finite"), ("abc", "numeric")])
def test_numbers_out_of_range_or_not_numbers_are_exit_4(tmp_path, value, words):
    path = tmp_path / "h.yaml"
    path.write_text(f"groups:\n  base: {json.dumps(BASE)}\n  top:\n"
                    f"    box: {json.dumps(TOP['box'])}\n    translate: [{value}, 0, 0]\n")
    line = one_line(run_cli(["deform", BAR, path, "-o", tmp_path / "o.obj"]), 4)
    assert words in line and "translate" in line and not (tmp_path / "o.obj").exists()


@pytest.mark.parametrize("args", [["bench", BAR, TWIST, "--time-budget", "nan"],
                                  ["deform", BAR, TWIST, "-o", "o.obj", "--alpha", "nan"],
                                  ["deform", BAR, TWIST, "-o", "o.obj", "--frame", "inf"],
                                  ["compare", BAR, BAR, "--tol", "nan"],
                                  ["render", BAR, "-o", "o.gif", "--fps", "nan"],
                                  ["animate", BAR, TWIST, "-o", "f{}.obj", "--fps", "inf"]])
def test_every_float_option_refuses_nan_and_infinity_as_usage(tmp_path, args):
    assert "not a finite number" in one_line(run_cli(args, cwd=tmp_path), 2)


# --- keyframes checked like static actions ---------------------------------------------------

@pytest.mark.parametrize("group", [
    {"pivot": [1e308, 0, 0], "keyframes": [{"frame": 0}, {"frame": 4, "rotate": {
        "axis": [0, 0, 1], "angle_deg": 90}}]},
    {"keyframes": [{"frame": 0}, {"frame": 3, "translate": [1e300, 0, 0]}]},
    {"pivot": [1e200, 0, 0], "keyframes": [{"frame": 0}, {"frame": 2}]},
])
def test_a_keyframe_that_sends_vertices_away_is_refused_before_frame_0(tmp_path, group):
    path = tmp_path / "k.yaml"
    path.write_text(yaml.safe_dump({"groups": {"base": BASE, "top": {**TOP, **group}}}))
    line = one_line(run_cli(["animate", BAR, path, "-o", str(tmp_path / "f_{:02d}.obj")]), 4)
    assert "group 'top'" in line and not list(tmp_path.glob("f_*"))


# --- outputs: streams that are full, names that are not UTF-8 --------------------------------

def test_a_full_standard_error_loses_lines_not_the_run(tmp_path):
    with open("/dev/full", "w") as full:
        p = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", BAR, TWIST, "-o",
                            str(tmp_path / "o.obj")], stderr=full, timeout=300)
    assert p.returncode == 0 and (tmp_path / "o.obj").stat().st_size > 0


@pytest.mark.parametrize("args", [["info", BAR], ["info", BAR, "--json"],
                                  ["bench", BAR, TWIST, "--methods", "sr-linear",
                                   "--time-budget", "2"]])
def test_a_full_standard_output_is_exit_6_naming_it(args):
    with open("/dev/full", "w") as full:
        p = subprocess.run([sys.executable, "-m", "srarap_cli", *args], stdout=full,
                           stderr=subprocess.PIPE, text=True, timeout=300)
    assert "<stdout>" in one_line(p, 6)


def test_names_the_shell_allows_are_written_escaped_where_the_format_needs_it(tmp_path):
    odd = os.fsdecode(b"a\xff.obj")  # not UTF-8: Python holds it as a lone surrogate
    (tmp_path / odd).write_bytes(open(BAR, "rb").read())
    r = run_cli(["compare", odd, BAR, "--report", "r.html", "--junit", "j.xml",
                 "--json", "c.json"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    from test_report import check_junit

    assert check_junit((tmp_path / "j.xml").read_text())[0][-1].get("name").startswith(
        "a\\udcff.obj")
    assert "a\\udcff.obj" in (tmp_path / "r.html").read_text()
    manifest = tmp_path / "m.json"
    manifest.write_text(json.dumps({"jobs": [{"name": "x\ud800y", "mesh": BAR,
                                              "handles": TWIST, "output": "o.obj"}]}))
    r = run_cli(["batch", manifest, "-o", tmp_path / "out", "--junit", tmp_path / "out/j.xml",
                 "--report", tmp_path / "out/r.html"])
    assert r.returncode == 0, r.stderr
    assert "x\\ud800y" in (tmp_path / "out" / "summary.csv").read_text()
    assert json.loads((tmp_path / "out" / "summary.json").read_text())[0]["job"] == "x\ud800y"


def test_summary_csv_holds_one_row_a_job_whatever_its_name_or_message_holds(tmp_path):
    """Issue 61: a lone carriage return in a job's name (or message) went into summary.csv
    unquoted, and every CSV reader saw an extra row."""
    import csv

    names = ["cr\rin the middle", "lf\nin the middle", "crlf\r\nboth", "plain", 'q"uote,comma']
    manifest = tmp_path / "m.json"
    manifest.write_text(json.dumps({"jobs": [
        {"name": name, "mesh": BAR, "handles": TWIST, "output": f"o{k}.obj"}
        for k, name in enumerate(names)]}))
    r = run_cli(["batch", manifest, "-o", tmp_path / "out", "-q"])
    assert r.returncode == 0, r.stderr
    with open(tmp_path / "out" / "summary.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [row["job"] for row in rows] == names
    with open(tmp_path / "out" / "summary.csv", newline="") as fh:
        plain = fh.read().split("\n")
    assert any(line.startswith("plain,") for line in plain)  # ordinary rows stay unquoted


# --- manifests ------------------------------------------------------------------------------

def _manifest(tmp_path, outputs):
    path = tmp_path / "m.yaml"
    path.write_text(yaml.safe_dump({"jobs": [
        {"name": f"j{k}", "mesh": BAR, "handles": TWIST, "output": out}
        for k, out in enumerate(outputs)]}))
    return path


@pytest.mark.parametrize("outputs", [["x.obj", "x.obj/y.obj"], ["a/b.obj", "a/b.obj/c/d.obj"],
                                     ["x.obj/y.obj", "x.obj"]])
def test_an_output_inside_another_jobs_output_is_refused_when_read(tmp_path, outputs):
    line = one_line(run_cli(["batch", _manifest(tmp_path, outputs), "-o", tmp_path / "out"]), 4)
    assert "folder holding the other" in line and not (tmp_path / "out").exists()


def test_an_output_a_symlink_carries_outside_the_folder_is_refused(tmp_path):
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "sub").symlink_to(elsewhere)
    line = one_line(run_cli(["batch", _manifest(tmp_path, ["sub/x.obj"]), "-o", out]), 4)
    assert "leads out of the output folder" in line and not list(elsewhere.iterdir())


@pytest.mark.parametrize("linked", ["x.obj.srarap.json", "summary.csv", "summary.json"])
def test_a_record_or_summary_a_symlink_carries_outside_is_refused_before_any_job(tmp_path,
                                                                                 linked):
    """Issue 61: the job's record and the summaries were written through links to anywhere
    (a victim file overwritten by the record, a summary created outside ``-o``)."""
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "victim"
    victim.write_text("precious")
    (out / linked).symlink_to(victim)
    line = one_line(run_cli(["batch", _manifest(tmp_path, ["x.obj"]), "-o", out]), 4)
    assert "leads out of the output folder" in line and victim.read_text() == "precious"
    assert not (out / "x.obj").exists()


def test_a_link_made_while_the_batch_runs_carries_nothing_outside(tmp_path):
    """The check that runs before the jobs cannot see a link made after it: each write checks
    again when it happens, and the job fails without writing (its mesh and record stay
    out of the other folder)."""
    from srarap_cli.tasks.batch.manifest import check_outputs, load_manifest
    from srarap_cli.tasks.batch.run import run_jobs

    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    manifest = _manifest(tmp_path, ["a.obj", "sub/b.obj"])
    jobs = load_manifest(str(manifest))
    check_outputs(jobs, str(out), str(manifest))  # nothing leads out yet
    (out / "sub").symlink_to(elsewhere)           # ... then a link appears
    rows = {r.job: r for r in run_jobs(jobs, str(out))}
    assert rows["j0"].status.value == "ok" and (out / "a.obj").exists()
    assert rows["j1"].status.value == "failed" and "leads out of the output folder" in \
        rows["j1"].message
    assert not list(elsewhere.iterdir())


def test_the_output_folder_swapped_for_a_link_mid_run_carries_nothing_there(tmp_path,
                                                                            monkeypatch):
    """Issue 71 (OUTSIDE-3): the batch's -o folder itself replaced by a link while the run
    went on, every later file landed in the link's target (the check resolved the folder's
    name again at each write). The folder is held as it was when the run started: later
    jobs fail without writing, the summary is refused, the link's target stays empty."""
    from srarap_cli.tasks.batch import run as batch_run

    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    elsewhere.mkdir()
    manifest = _manifest(tmp_path, ["a.obj", "b.obj", "c.obj"])
    real = batch_run.run_job

    def then_swap(job, *args, **kwargs):
        row = real(job, *args, **kwargs)
        if job.name == "j0":
            out.rename(tmp_path / "moved")
            out.symlink_to(elsewhere)
        return row
    monkeypatch.setattr(batch_run, "run_job", then_swap)
    r = run_cli(["batch", str(manifest), "-o", str(out)])
    assert r.returncode == 6 and "leads out of the output folder" in r.stderr, r.stderr
    assert not list(elsewhere.iterdir())
    assert sorted(p.name for p in (tmp_path / "moved").iterdir() if p.suffix == ".obj") == \
        ["a.obj"]


def test_commit_files_inside_a_folder_refuses_every_way_out(tmp_path):
    from srarap_cli.runtime.commit import commit_files
    from srarap_cli.runtime.errors import OutputError

    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "link.txt").symlink_to(elsewhere / "target.txt")
    (out / "dir").symlink_to(elsewhere)
    for name in ("link.txt", "dir/x.txt", "dir/new/y.txt", "../escape.txt"):
        with pytest.raises(OutputError, match="leads out of the output folder"):
            commit_files([(str(out / "ok.txt"), b"1"), (str(out / name), b"2")], inside=str(out))
    assert not list(elsewhere.iterdir()) and not (out / "ok.txt").exists()
    assert not (tmp_path / "escape.txt").exists()
    commit_files([(str(out / "ok.txt"), b"1"), (str(out / "new" / "z.txt"), b"2")],
                 inside=str(out))
    assert (out / "new" / "z.txt").read_bytes() == b"2"


def test_a_symlink_that_loops_is_never_replaced_by_a_file(tmp_path):
    (tmp_path / "loop.obj").symlink_to("loop.obj")
    line = one_line(run_cli(["deform", BAR, TWIST, "-o", "loop.obj"], cwd=tmp_path), 6)
    assert "loop.obj" in line and os.path.islink(tmp_path / "loop.obj")


def test_a_report_that_cannot_be_written_leaves_the_summary(tmp_path):
    out = tmp_path / "out"
    r = run_cli(["batch", _manifest(tmp_path, ["a.obj"]), "-o", out, "--junit", "/dev/full"])
    assert "/dev/full" in one_line(r, 6)
    rows = json.loads((out / "summary.json").read_text())
    assert rows[0]["status"] == "ok" and (out / "a.obj").exists()


# --- info says what the file says -------------------------------------------------------------

def test_info_states_a_collinear_groups_rotation_as_written(tmp_path):
    x, y = np.meshgrid(np.arange(5.0), np.arange(5.0))
    grid = np.c_[x.ravel(), y.ravel(), np.zeros(25)]
    F = [[a, a + 1, a + 6] for a in range(20) if a % 5 < 4] + \
        [[a, a + 6, a + 5] for a in range(20) if a % 5 < 4]
    srarap_cli.write_mesh(str(tmp_path / "g.obj"), (grid, np.array(F)))
    (tmp_path / "h.yaml").write_text(yaml.safe_dump({"groups": {
        "base": {"indices": [0, 1, 2, 3, 4], "fixed": True},
        "row": {"indices": [20, 21, 22, 23, 24],
                "rotate": {"axis": [0, 1, 0], "angle_deg": 90}}}}))
    r = run_cli(["info", tmp_path / "g.obj", tmp_path / "h.yaml"])
    row = next(line for line in r.stdout.splitlines() if line.strip().startswith("row:"))
    assert "fixed" not in row and "rotate 90 degrees (angle_deg) about axis (0, 1, 0)" in row
    assert "centroid (2, 4, 0)" in row and "e-1" not in row


def test_a_motion_of_collinear_vertices_is_not_called_fixed():
    from srarap_cli.tasks.info import describe_motion

    rest = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    turned = rest @ np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]]).T
    assert "fixed" not in describe_motion(rest, turned)
    assert describe_motion(rest, rest + [0, 1, 0]) == "translate (0, 1, 0)"


# --- the Python API names what is wrong -------------------------------------------------------

M = read_mesh(BAR)
F = M.triangles()[0]
IDS = np.arange(10)


@pytest.mark.parametrize("call, kind, words", [
    (lambda: Deformer(V * 1e200, F, IDS), ValueError, "V: vertex 0 has a coordinate beyond"),
    (lambda: Deformer(np.zeros_like(V), F, IDS), ValueError, "V, F:"),
    (lambda: Deformer(V, F, IDS, area=float("nan")), ValueError, "area must be"),
    (lambda: Deformer(V, F, IDS, area=0), ValueError, "area must be"),
    (lambda: Deformer(V, F, IDS, area=-5), ValueError, "area must be"),
    (lambda: Deformer(V, F, IDS, area="big"), TypeError, "area must be a number"),
    (lambda: Deformer(V, F, IDS, labels=np.zeros(3, int)), ValueError, "labels must be a 1-d"),
    (lambda: Deformer(V, F, IDS, labels=np.full(10, 0.5)), TypeError, "labels must hold"),
    (lambda: Deformer(V, F, IDS, labels=np.full(10, -1)), ValueError, "labels must be >= 0"),
    (lambda: Deformer(V, F, IDS).solve(V[IDS], driver="nope"), ValueError, "driver 'nope'"),
    (lambda: Deformer(V, F, IDS).solve(V[IDS] + 1e200), ValueError,
     "targets has coordinates beyond 1e"),  # was "Factor is exactly singular"
    (lambda: srarap_cli.read_mesh(12), TypeError, "path must be"),
])
def test_api_mistakes_name_the_argument(call, kind, words):
    with pytest.raises(kind, match=words.replace("(", r"\(")):
        call()


def test_a_callback_that_changes_its_row_does_not_break_the_solve():
    d = Deformer(V, F, IDS)
    r = d.solve(V[IDS] + [0, 0, 0.1], callback=lambda row: row.clear())
    assert r.converged and "total" in r.log[-1]


def test_a_path_given_as_bytes_is_read():
    assert len(srarap_cli.read_mesh(os.fsencode(BAR)).vertices) == len(V)


# --- the newcomer's papercuts (issue 53) ------------------------------------------------------

@pytest.mark.parametrize("text, words", [
    ("jobz:\n  - {mesh: a.obj, handles: h.yaml, output: o.obj}\n",
     "unknown key 'jobz' in the manifest; did you mean 'jobs'?"),
    ("jobs:\n  - {mesh: a.obj, handles: h.yaml, outptu: o.obj}\n",
     "job 0: unknown key 'outptu' in the job; did you mean 'output'?"),
    ("jobs:\n  - {mesh: a.obj, handles: h.yaml, output: o.obj, expect: {golden: g.obj, "
     "tool: 1}}\n", "unknown key 'tool' in expect; did you mean 'tol'?"),
])
def test_a_typo_in_a_manifest_key_gets_a_did_you_mean(tmp_path, text, words):
    (tmp_path / "m.yaml").write_text(text)
    assert words in one_line(run_cli(["batch", tmp_path / "m.yaml", "-o", tmp_path / "o"]), 4)


def test_a_yaml_error_says_its_reason_not_only_its_context(tmp_path):
    (tmp_path / "h.yaml").write_text("groups:\n\tbase: {indices: [0], fixed: true}\n")
    line = one_line(run_cli(["info", BAR, tmp_path / "h.yaml"]), 4)
    assert "found character '\\t' that cannot start any token" in line and "line 2" in line


# --- duplicate keys ----------------------------------------------------------------------------

@pytest.mark.parametrize("name, text, key, line", [
    ("groups.yaml", "groups: {fix: {indices: [0, 1, 2, 3], fixed: true},\n"
     "         fix: {indices: [12, 13, 14, 15], translate: [0, 0, 1]}}\n", "'fix'", 2),
    ("group.yaml", "groups:\n  top:\n    indices: [12, 13]\n    rotate: {axis: [0, 0, 1], "
     "angle_deg: 90}\n    rotate: {axis: [0, 0, 1], angle_deg: 45}\n", "'rotate'", 5),
    ("top.yaml", "groups: {a: {indices: [0], fixed: true}}\ngroups: {b: {indices: [1], "
     "fixed: true}}\n", "'groups'", 2),
    ("groups.json", '{"groups": {"fix": {"indices": [0, 1], "fixed": true},\n'
     '"fix": {"indices": [12, 13], "translate": [0, 0, 1]}}}', '"fix"', 2),
    ("group.json", '{"groups": {"a": {"indices": [0], "fixed": true,\n"fixed": false}}}',
     '"fixed"', 2),
])
def test_a_key_given_twice_is_refused_naming_it_and_its_line(tmp_path, name, text, key, line):
    """Issue 61: the loaders kept the last of two equal keys without a word (a group's held
    vertices no longer held, a second ``jobs:`` list dropping the first)."""
    path = tmp_path / name
    path.write_text(text)
    said = one_line(run_cli(["deform", BAR, path, "-o", tmp_path / "o.obj"]), 4)
    assert f"key {key} given twice" in said and f"line {line}" in said, said
    assert not (tmp_path / "o.obj").exists()
    from srarap_cli.io.handles import load_handles
    from srarap_cli.io.mesh import read_mesh
    from srarap_cli.runtime.errors import InputError

    with pytest.raises(InputError, match="given twice"):  # the API's loader too
        load_handles(str(path), read_mesh(BAR).vertices)


def test_a_manifest_with_two_job_lists_or_a_job_key_twice_is_refused(tmp_path):
    for text, key in [(f"jobs:\n  - {{name: a, mesh: {BAR}, handles: {TWIST}, output: a.obj}}\n"
                       f"jobs:\n  - {{name: b, mesh: {BAR}, handles: {TWIST}, output: b.obj}}\n",
                       "'jobs'"),
                      (f"jobs:\n  - {{name: a, mesh: {BAR}, handles: {TWIST}, output: a.obj,"
                       " output: b.obj}\n", "'output'")]:
        (tmp_path / "m.yaml").write_text(text)
        said = one_line(run_cli(["batch", tmp_path / "m.yaml", "-o", tmp_path / "out"]), 4)
        assert f"key {key} given twice" in said, said
        assert not (tmp_path / "out").exists()


def test_the_same_key_in_other_mappings_and_yaml_merges_still_load(tmp_path):
    path = tmp_path / "h.yaml"
    path.write_text("base: &b {fixed: true}\ngroups:\n  a: {<<: *b, indices: [0, 1]}\n"
                    "  b: {<<: *b, indices: [2, 3]}\n")
    from srarap_cli.io.documents import load_document

    doc = load_document(str(path), "yaml")
    assert doc["groups"]["b"] == {"fixed": True, "indices": [2, 3]}


# --- records ----------------------------------------------------------------------------------

@pytest.mark.parametrize("change", [
    {"iterations": "many"}, {"status": "bogus"}, {"warnings": 5}, {"warnings": [1, 2]},
    {"energy": "low"}, {"iterations": True}, {"stop": "<script>alert(1)</script>"},
    {"status": "up-to-date"}, {"seconds": "slow"}])
def test_a_record_with_fields_srarap_never_writes_is_no_record(tmp_path, change):
    """Issue 61: a record carrying the job's fingerprint (a restored CI cache, a shared
    folder) with a field of the wrong type ended the batch with exit 1 after its summary, and
    its ``stop`` went into the report unescaped. Such a record is now no record: the job is
    solved again, and the report escapes every field."""
    manifest = _manifest(tmp_path, ["x.obj"])
    out = tmp_path / "out"
    assert run_cli(["batch", manifest, "-o", out, "-q"]).returncode == 0
    sidecar = out / "x.obj.srarap.json"
    rec = json.loads(sidecar.read_text())
    sidecar.write_text(json.dumps({**rec, **change}))
    r = run_cli(["batch", manifest, "-o", out, "-q", "--report", out / "r.html"])
    assert r.returncode == 0, r.stderr
    row = json.loads((out / "summary.json").read_text())[0]
    assert row["status"] == "ok"  # solved again: not "up-to-date" from the doctored record
    assert "<script>" not in (out / "r.html").read_text()
    again = json.loads(sidecar.read_text())  # and the record written anew (the solve's
    assert isinstance(again.pop("seconds"), float)  # seconds, for a seconds gate, measured)
    assert again == {k: v for k, v in rec.items() if k != "seconds"}


def test_the_report_escapes_every_field_of_a_row():
    from srarap_cli.tasks.job_status import JobResult, JobStatus
    from srarap_cli.tasks.reports import report_html

    row = JobResult("j<b>", JobStatus.OK, 0, stop="<script>x</script>", message="<i>m</i>",
                    warnings=["<w>"])
    page = report_html([row], {"j<b>": {}}, "t<t>")
    assert "<script>" not in page and "<i>" not in page and "<w>" not in page
    assert "&lt;script&gt;" in page
    assert '<span class="seconds">' in page  # the report's own markup stays markup


@pytest.mark.parametrize("resume", [False, True])
def test_an_animation_run_again_with_fewer_frames_leaves_only_its_own(tmp_path, resume):
    """Issue 61: a rerun with fewer frames left the earlier run's later frames beside the
    new ones, and ``render 'f_{}.obj'`` drew a mixed animation."""
    keys = os.path.join(ROOT, "configs", "bar-twist-animated.yaml")
    pattern = str(tmp_path / "fr" / "f_{:02d}.obj")
    first = run_cli(["animate", BAR, keys, "-o", pattern, "--frames", "6", "-q"])
    assert first.returncode == 0, first.stderr
    again = run_cli(["animate", BAR, keys, "-o", pattern, "--frames", "3", "-q"]
                    + (["--resume"] if resume else []))
    assert again.returncode == 0, again.stderr
    assert sorted(os.listdir(tmp_path / "fr")) == ["f_00.obj", "f_01.obj", "f_02.obj"]
    assert "removed 3 later frame(s) of an earlier run" in again.stderr


def test_batch_strict_makes_every_jobs_warnings_errors(tmp_path):
    """Issue 60: the README's ``--strict`` for a batch exited 2 "No such option"."""
    handles = tmp_path / "h.yaml"
    handles.write_text(open(TWIST).read().replace("angle_deg: 90", "angle_rad: 30"))
    manifest = tmp_path / "m.yaml"
    manifest.write_text(yaml.safe_dump({"jobs": [
        {"name": "j", "mesh": BAR, "handles": str(handles), "output": "x.obj"}]}))
    assert run_cli(["batch", manifest, "-o", tmp_path / "lax", "-q"]).returncode == 0
    strict = run_cli(["batch", manifest, "-o", tmp_path / "strict", "-q", "--strict"])
    assert strict.returncode == 8
    row = json.loads((tmp_path / "strict" / "summary.json").read_text())[0]
    assert row["status"] == "failed" and row["exit_code"] == 4 and "strict" in row["message"]
    assert not (tmp_path / "strict" / "x.obj").exists()


def test_a_relative_distance_says_its_unit(tmp_path):
    """Issue 60: with ``relative: true`` the message gave a fraction of the diagonal as if it
    were a length."""
    out = tmp_path / "out"
    manifest = tmp_path / "m.yaml"
    golden = tmp_path / "golden.obj"
    golden.write_bytes(open(BAR, "rb").read())  # the rest shape: far from the twisted one
    manifest.write_text(yaml.safe_dump({"jobs": [
        {"name": "j", "mesh": BAR, "handles": TWIST, "output": "x.obj",
         "expect": {"golden": str(golden), "tol": 1e-6, "relative": True}}]}))
    assert run_cli(["batch", manifest, "-o", out, "-q"]).returncode == 8
    row = json.loads((out / "summary.json").read_text())[0]
    assert row["status"] == "regressed" and "fractions of the golden mesh's diagonal" in \
        row["message"]


def test_a_strict_failure_names_every_warning_that_failed_it(tmp_path):
    """Issue 60: a strict failure named only the first warning: one round trip per warning."""
    handles = tmp_path / "h.yaml"
    handles.write_text(
        "groups:\n  base: {box: {min: [-2, -2, -0.01], max: [2, 2, 0.01]}, fixed: true}\n"
        "  top: {box: {min: [-2, -2, 9.99], max: [2, 2, 10.01]}, rotate: {axis: [0, 0, 1], "
        "angle_rad: 30}}\n  mid: {box: {min: [-2, -2, 4.99], max: [2, 2, 5.01]}, "
        "translate: [0, 0, 25]}\n")  # 2.4 diagonals: warned (from 3 on, refused at once)
    lax = run_cli(["deform", BAR, handles, "-o", tmp_path / "lax.obj", "--max-iter", "3",
                   "--keep-unconverged"])
    warned = [line for line in lax.stderr.splitlines() if line.startswith("srarap: warning:")]
    assert len(warned) == 2, lax.stderr
    said = one_line(run_cli(["deform", BAR, handles, "-o", tmp_path / "o.obj", "--strict"]), 4)
    assert all(w[len("srarap: warning: "):] in said for w in warned), said
    assert "(and 1 more: " in said and not (tmp_path / "o.obj").exists()


def test_a_job_whose_output_was_deleted_runs_again(tmp_path):
    """Issue 62: a job whose output was deleted after an ok run could have been reported
    ``up-to-date`` from its record alone without a test noticing."""
    manifest = _manifest(tmp_path, ["x.obj"])
    out = tmp_path / "out"
    assert run_cli(["batch", manifest, "-o", out, "-q"]).returncode == 0
    assert run_cli(["batch", manifest, "-o", out, "-q"]).returncode == 0
    assert json.loads((out / "summary.json").read_text())[0]["status"] == "up-to-date"
    first = (out / "x.obj").read_bytes()
    (out / "x.obj").unlink()
    assert run_cli(["batch", manifest, "-o", out, "-q"]).returncode == 0
    assert json.loads((out / "summary.json").read_text())[0]["status"] == "ok"
    assert (out / "x.obj").read_bytes() == first


@pytest.mark.parametrize("setting, value, words", [
    ("tol", 18446744073709551616, None),  # a big tolerance is a valid (if loose) one
    ("feedback", 18446744073709551616, "feedback must be <= 1e+12"),
    ("alpha", 1e308, "alpha must be <= 1e+12"),
    ("feedback", 1e308, "feedback must be <= 1e+12"),
    ("max_iter", 2 ** 64, "max_iter must be <= 9007199254740992"),
    ("threads", 2 ** 64, None),  # capped at the CPUs (issue 71): any count, the same bytes
    ("tol", 10 ** 400, "tol must be finite"),
])
def test_settings_past_64_bits_or_past_what_a_solve_holds_are_exit_4(tmp_path, setting, value,
                                                                     words):
    """An integer past 64 bits (tol, feedback with sr-linear) was an internal error, exit 1;
    feedback 1e308 a "singular system" blamed on the geometry (issue 61)."""
    h = tmp_path / "h.yaml"
    top = {**TOP, "translate": [0, 0, 1]}
    h.write_text(json.dumps({"solver": {"method": "sr-linear", "max_iter": 50, setting: value},
                             "groups": {"base": BASE, "top": top}}))
    r = run_cli(["deform", BAR, h, "-o", tmp_path / "o.obj", "--keep-unconverged"])
    if words is None:
        assert r.returncode in (0, 3), r.stderr
    else:
        assert words in one_line(r, 4)


def test_batch_refuses_an_unwritable_summary_before_solving_any_job(tmp_path):
    """``batch -o`` where the summary cannot be written solved every job first (issue 61)."""
    manifest = tmp_path / "jobs.yaml"
    manifest.write_text(json.dumps({"jobs": [{"mesh": BAR, "handles": TWIST,
                                              "output": "a.obj"}]}))
    (tmp_path / "out" / "summary.csv").mkdir(parents=True)
    r = run_cli(["batch", manifest, "-o", tmp_path / "out"])
    assert "summary.csv: is a folder" in one_line(r, 6)
    assert not (tmp_path / "out" / "a.obj").exists()


def test_info_writes_control_characters_of_group_names_out_as_deform_does(tmp_path):
    h = tmp_path / "h.yaml"
    h.write_text(json.dumps({"groups": {"fix\x1b[31mRED\n2": BASE,
                                        "top": {**TOP, "translate": [0, 0, 1]}}}))
    r = run_cli(["info", BAR, h])
    assert r.returncode == 0 and "\x1b" not in r.stdout
    assert "  fix\\x1b[31mRED\\n2: " in r.stdout


@pytest.mark.parametrize("command", [
    lambda tmp: ["animate", BAR, tmp / "missing.yaml", "-o", tmp / "frames" / "f_{}.obj"],
    lambda tmp: ["bench", BAR, tmp / "missing.yaml", "-o", tmp / "frames"],
])
def test_a_failed_animate_or_bench_leaves_no_folder_it_made(tmp_path, command):
    r = run_cli(command(tmp_path))
    assert r.returncode == 4, r.stderr
    assert not (tmp_path / "frames").exists()


def test_a_short_animation_in_a_log_prints_no_progress_line(tmp_path):
    r = subprocess.run([sys.executable, "-m", "srarap_cli", "animate", BAR,
                        os.path.join(ROOT, "configs", "bar-twist-animated.yaml"), "-o",
                        str(tmp_path / "f_{}.obj"), "--frames", "3"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and "progress" not in r.stderr, r.stderr


@pytest.mark.parametrize("error", [RuntimeError("SuperLU malloc failed"),
                                   OSError(12, "Cannot allocate memory"), MemoryError()])
def test_a_memory_failure_in_the_solve_is_exit_4_from_every_command(tmp_path, monkeypatch,
                                                                     error):
    """Issue 62's mutation: an out-of-memory failure arriving as SuperLU's RuntimeError or
    as ENOMEM could exit 1 unnoticed. deform, animate and a batch job each say 4."""
    from srarap_cli.tasks import pipeline

    def fail(*args, **kwargs):
        raise error

    monkeypatch.setattr(pipeline, "make_deformer", fail)
    r = run_cli(["deform", BAR, TWIST, "-o", tmp_path / "o.obj"])
    assert one_line(r, 4).startswith("srarap: error: out of memory")
    r = run_cli(["animate", BAR, os.path.join(ROOT, "configs", "bar-twist-animated.yaml"),
                 "-o", tmp_path / "f_{}.obj", "--frames", "2"])
    assert one_line(r, 4).startswith("srarap: error: out of memory")
    manifest = tmp_path / "jobs.yaml"
    manifest.write_text(json.dumps({"jobs": [{"mesh": BAR, "handles": TWIST,
                                              "output": "a.obj"}]}))
    r = run_cli(["batch", manifest, "-o", tmp_path / "out"])
    rows = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert r.returncode == 8 and rows[0]["exit_code"] == 4
    assert rows[0]["message"].startswith("out of memory")


GROUP = "{box: {min: [-2, -2, -0.01], max: [2, 2, 0.01]}, fixed: true}"
MOVE = "{box: {min: [-2, -2, 9.99], max: [2, 2, 10.01]}, translate: [1, 0, 0]}"


@pytest.mark.parametrize("first, second, words", [
    ("1", "0x1", "key '0x1' given twice in one mapping (line 3, the same key as '1')"),
    ("1", "01", "the same key as '1'"),
    ("true", "yes", "key 'yes' given twice"),
    ("1", "true", "key 'true' given twice"),
    ("1.0", "1", "key '1' given twice"),
    ("1", '"1"', "group names 1 and '1' read as one name ('1')"),
])
def test_two_spellings_of_one_key_are_refused_by_value(tmp_path, first, second, words):
    """Issue 71 (SILENT-2): keys were compared as spelt: ``1:`` and ``0x1:`` are one key,
    and the first group was dropped with exit 0; ``1:`` and ``"1":`` are two groups that
    every report names alike."""
    h = tmp_path / "h.yaml"
    h.write_text(f"groups:\n  {first}: {GROUP}\n  {second}: {MOVE}\n")
    for command in (["info", BAR, h], ["deform", BAR, h, "-o", tmp_path / "o.obj"]):
        r = run_cli(command)
        assert r.returncode == 4 and words in r.stderr, r.stderr
        assert len(r.stderr.splitlines()) == 1 and not (tmp_path / "o.obj").exists()


DIGITS = "1" * 5000


@pytest.mark.parametrize("where, args, code, env", [
    ("yaml", ["info", BAR, "{doc}.yaml"], 4, {}),
    ("json", ["info", BAR, "{doc}.json"], 4, {}),
    ("option", ["deform", BAR, TWIST, "-o", "o.obj", "--max-iter", DIGITS], 2, {}),
    ("multires", ["deform", BAR, TWIST, "-o", "o.obj", "--multires", DIGITS, "-q"], 0, {}),
    ("threads", ["deform", BAR, TWIST, "-o", "o.obj", "--threads", DIGITS, "-q"], 0, {}),
    ("variable", ["info", BAR], 0, {"SRARAP_THREADS": DIGITS})])
def test_a_number_of_thousands_of_digits_is_read_or_refused_in_our_words(tmp_path, monkeypatch,
                                                                         where, args, code,
                                                                         env):
    """Issue 71 (MSG-4): a 5000-digit integer gave Python's advice to raise
    sys.set_int_max_str_digits(), or an internal error (exit 1) for a thread count. A count
    that large is a count like any large one (capped); elsewhere it is refused, in one
    short line."""
    doc = tmp_path / "h"
    (tmp_path / "h.yaml").write_text(f"groups:\n  a: {{indices: [{DIGITS}], fixed: true}}\n")
    (tmp_path / "h.json").write_text(json.dumps({"groups": {"a": {"fixed": True}}})
                                     .replace('"fixed"', f'"indices": [{DIGITS}], "fixed"'))
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    r = run_cli([a.format(doc=doc) for a in args], cwd=tmp_path)
    assert r.returncode == code, r.stderr
    assert "set_int_max_str_digits" not in r.stderr and "Traceback" not in r.stderr
    assert all(len(line) < 300 for line in r.stderr.splitlines())
    if code == 4:
        assert "a number of 5000 digits" in one_line(r, 4)
