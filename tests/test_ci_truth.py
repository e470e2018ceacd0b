"""What CI relies on (issue 49): every command's exit code for every mesh path a shell can
give, one job runner (the same exit code for the same failure from ``deform`` and a batch
row), warnings in every output of a batch, JUnit that parses and shows its texts whatever the
jobs are called, plausibility warnings, and a summary that tells the truth under signals."""
import json
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from helpers import ROOT
from test_report import check_junit

from srarap_cli.cli import main
from srarap_cli.io.mesh import Mesh, read_mesh, write_mesh
from srarap_cli.runtime.errors import (
    InputError,
    NumericalError,
    OutputError,
    SingularSystemError,
)
from srarap_cli.tasks.batch import run as batch
from srarap_cli.tasks.batch.manifest_job import ManifestJob
from srarap_cli.tasks.batch.rows import interrupted_row
from srarap_cli.tasks.deform import job
from srarap_cli.tasks.job_status import JobStatus

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
TWIST = os.path.join(ROOT, "configs", "bar-twist.yaml")
ANIMATED = os.path.join(ROOT, "configs", "bar-twist-animated.yaml")


def invoke(args, **kwargs):
    return CliRunner().invoke(main, [str(a) for a in args], **kwargs)


def error_lines(text):
    return [line for line in text.splitlines() if line.startswith("srarap: error:")]


# --- every mesh path a shell gives ----------------------------------------------------------

@pytest.fixture(scope="module")
def paths(tmp_path_factory):
    """name -> (path, exit codes allowed): meshes under names no format claims, and what is
    not a mesh at all."""
    tmp = tmp_path_factory.mktemp("paths")
    shutil.copy(BAR, tmp / "bar.txt")
    shutil.copy(BAR, tmp / "bar")
    (tmp / "notes.txt").write_text("shopping list\neggs\n")
    (tmp / "noise").write_bytes(np.random.default_rng(0).bytes(20000))
    (tmp / "folder").mkdir()
    return {"swapped (handles as the mesh)": (TWIST, {4}),
            ".txt holding an OBJ": (tmp / "bar.txt", {0}),
            "no extension, an OBJ": (tmp / "bar", {0}),
            ".txt holding text": (tmp / "notes.txt", {4}),
            "no extension, random bytes": (tmp / "noise", {4}),
            "missing, known extension": (tmp / "nope.obj", {4}),
            "missing, no extension": (tmp / "nope", {4}),
            "a folder": (tmp / "folder", {4}),
            "the current folder": (".", {4})}


def commands(mesh, tmp):
    return {"deform": ["deform", mesh, TWIST, "-o", tmp / "o.obj", "-q"],
            "info": ["info", mesh],
            "info with handles": ["info", mesh, TWIST],
            "compare": ["compare", mesh, BAR, "-q"],
            "compare, second": ["compare", BAR, mesh, "-q"],
            "render": ["render", mesh, "-o", tmp / "r.png"],
            "animate": ["animate", mesh, ANIMATED, "-o", str(tmp / "f_{:02d}.obj"),
                        "--frames", "2", "-q"],
            "bench": ["bench", mesh, TWIST, "--methods", "sr-linear", "--time-budget", "1",
                      "-o", tmp / "bench"]}


COMMANDS = ["deform", "info", "info with handles", "compare", "compare, second", "render",
            "animate", "bench"]


@pytest.mark.parametrize("command", [pytest.param(c, marks=[pytest.mark.slow] if c == "bench"
                                                  else []) for c in COMMANDS])
def test_every_command_gives_0_2_or_4_and_one_line_for_any_mesh_path(paths, command,
                                                                      tmp_path):
    for name, (path, allowed) in paths.items():
        r = invoke(commands(path, tmp_path)[command])
        lines = error_lines(r.stderr)
        assert r.exit_code in allowed, (name, r.exit_code, r.stderr)
        assert "internal error" not in r.stderr and "Traceback" not in r.stderr, name
        if r.exit_code:
            assert len(lines) == 1 and str(path) in lines[0], (name, r.stderr)


def test_swapped_arguments_are_named_as_such():
    r = invoke(["deform", TWIST, BAR, "-o", "x.obj"])
    assert r.exit_code == 4 and "mesh and handles swapped?" in r.stderr


def _shell(command, **kwargs):
    return subprocess.run(["bash", "-c", command], capture_output=True, timeout=300,
                          **kwargs)


@pytest.mark.slow
@pytest.mark.slow
@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("how", ["cat {bar} | {cmd}", "{cmd} < {bar}", "{cmd_fifo}"])
def test_every_command_reads_a_mesh_from_a_pipe_fifo_or_dev_stdin(command, how, tmp_path):
    srarap = f"{sys.executable} -m srarap_cli"
    args = [str(a) for a in commands("MESH", tmp_path)[command]]
    cmd = srarap + " " + " ".join(f"'{a}'" for a in args)
    fifo = tmp_path / "pipe"
    line = how.format(cmd=cmd.replace("'MESH'", "/dev/stdin"), bar=BAR,
                      cmd_fifo=f"mkfifo {fifo}; (cat {BAR} > {fifo} &); "
                               + cmd.replace("'MESH'", str(fifo)))
    p = _shell(line)
    assert p.returncode == 0, (line, p.stderr.decode()[-600:])


@pytest.mark.parametrize("how", [
    "cat {bar} | {srarap} deform /dev/stdin {twist} -o {out} -q",
    "{srarap} deform <(cat {bar}) {twist} -o {out} -q",
    "mkfifo {tmp}/pipe; (cat {bar} > {tmp}/pipe &); {srarap} deform {tmp}/pipe {twist} -o {out} -q",
    "cat {twist} | {srarap} deform /dev/stdin {twist} -o {out} -q",
    "head -c 300000000 /dev/urandom | {srarap} info /dev/stdin",
])
def test_streams_under_any_name_are_read_by_their_content(how, tmp_path):
    srarap = f"{sys.executable} -m srarap_cli"
    p = _shell(how.format(srarap=srarap, bar=BAR, twist=TWIST, out=tmp_path / "o.obj",
                          tmp=tmp_path))
    err = p.stderr.decode()
    if "cat {bar}" in how:
        assert p.returncode == 0, err
        assert np.allclose(read_mesh(tmp_path / "o.obj").vertices.shape, (658, 3))
    else:  # a handle file, random bytes: refused after their first bytes, exit 4, one line
        assert p.returncode == 4 and len(error_lines(err)) == 1, err
        assert "not a mesh" in err


@pytest.mark.slow
def test_garbage_on_standard_input_is_refused_before_it_is_spooled(tmp_path, monkeypatch):
    """Refused from its first kilobytes: nothing is written to the temporary folder (a
    stream that never ends would otherwise fill it)."""
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "info", "-"],
                       input=np.random.default_rng(1).bytes(50_000_000), capture_output=True,
                       timeout=300, env={**os.environ, "TMPDIR": str(tmp_path)})
    assert p.returncode == 4 and b"not a mesh" in p.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_stream_larger_than_the_temporary_folder_can_keep_is_refused(monkeypatch):
    from srarap_cli.io.mesh import stream

    text = open(BAR, "rb").read()
    monkeypatch.setattr(stream, "TMP_RESERVE",
                        shutil.disk_usage(os.environ.get("TMPDIR", "/tmp")).free - 5000)

    class Endless:
        def read(self, size):
            return (text * (size // len(text) + 1))[:size]

    with pytest.raises(InputError, match="larger than the temporary folder"):
        stream.read_mesh_stream(Endless(), name="pipe")


@pytest.mark.slow
def test_devices_are_written_through_as_outputs(tmp_path):
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "compare", BAR, BAR,
                        "--json", "/dev/stdout", "--junit", "/dev/null", "-q"],
                       capture_output=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout)["max"] == 0.0


# --- one runner: the same failure, the same exit code -----------------------------------------

FAILURES = [(InputError("m.obj: bad"), 4), (SingularSystemError("exactly singular"), 5),
            (np.linalg.LinAlgError("singular"), 5), (NumericalError("non-finite"), 5),
            (MemoryError(), 4), (OutputError("out: cannot write"), 6),
            (RuntimeError("unexpected"), 1)]


@pytest.mark.parametrize("exc, code", FAILURES, ids=[type(e).__name__ for e, _ in FAILURES])
def test_a_failure_gets_the_same_exit_code_from_deform_and_from_a_batch_row(
        exc, code, tmp_path, monkeypatch):
    def fail(*args, **kwargs):
        raise exc

    monkeypatch.setattr(job, "deform_mesh", fail)
    r = invoke(["deform", BAR, TWIST, "-o", tmp_path / "o.obj"])
    assert r.exit_code == code and len(error_lines(r.stderr)) == 1, r.stderr
    row = batch.run_job(ManifestJob("j", BAR, TWIST, "o.obj"), str(tmp_path / "b"))
    assert row.status is JobStatus.FAILED and row.exit_code == code
    # the same text, less what deform adds of the files it had written
    assert error_lines(r.stderr)[0].removeprefix("srarap: error: ").startswith(row.message)


def test_the_deform_command_is_a_call_into_the_job_runner():
    import inspect

    from srarap_cli.cli import deform

    source = inspect.getsource(deform.deform.callback)
    body = source[source.index('"""', source.index('"""') + 3) + 3:]
    assert "run_job(" in body and "deform_mesh" not in body and "commit_files" not in body


# --- strict means the same everywhere ---------------------------------------------------------

def test_strict_refuses_what_the_output_drops_in_deform_animate_and_batch(tmp_path):
    """bar.obj has texture coordinates, which STL cannot hold."""
    r = invoke(["deform", BAR, TWIST, "-o", tmp_path / "o.stl", "--strict"])
    assert r.exit_code == 4 and "strict" in r.stderr and not (tmp_path / "o.stl").exists()
    r = invoke(["animate", BAR, ANIMATED, "-o", str(tmp_path / "f_{:02d}.stl"), "--frames", "2",
                "--strict"])
    assert r.exit_code == 4 and not list(tmp_path.glob("f_*.stl"))
    manifest = tmp_path / "m.yaml"
    manifest.write_text(yaml.safe_dump({"defaults": {"strict": True}, "jobs": [
        {"name": "j", "mesh": BAR, "handles": TWIST, "output": "o.stl"}]}))
    r = invoke(["batch", manifest, "-o", tmp_path / "out", "-q"])
    rows = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert r.exit_code == 8 and rows[0]["status"] == "failed" and rows[0]["exit_code"] == 4
    assert not (tmp_path / "out" / "o.stl").exists()


# --- warnings wherever a result goes ----------------------------------------------------------

@pytest.fixture(scope="module")
def two_parts(tmp_path_factory):
    """Two bars side by side: the second is held only by the moving group (the teapot's
    spout): it moves as a rigid piece."""
    tmp = tmp_path_factory.mktemp("parts")
    m = read_mesh(BAR)
    V, F = m.vertices, m.triangles()[0]
    write_mesh(tmp / "two.obj", Mesh.from_arrays(np.vstack([V, V + [5, 0, 0]]),
                                                 np.vstack([F, F + len(V)])))
    (tmp / "h.yaml").write_text(yaml.safe_dump({"groups": {
        "base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True},
        "top": {"box": {"min": [-2, -2, 9.99], "max": [8, 2, 10.01]},
                "translate": [0, 1, 0]}}}))
    return tmp


def test_a_part_held_only_by_moving_handles_is_named_with_its_size(two_parts):
    r = invoke(["deform", two_parts / "two.obj", two_parts / "h.yaml", "-o",
                two_parts / "o.obj", "-q"])
    assert r.exit_code == 0
    assert "1 connected part(s) (658 vertices" in r.stderr and "'top'" in r.stderr
    out = read_mesh(two_parts / "o.obj").vertices[658:]
    assert np.allclose(out, read_mesh(two_parts / "two.obj").vertices[658:] + [0, 1, 0])
    r = invoke(["deform", two_parts / "two.obj", two_parts / "h.yaml", "-o",
                two_parts / "s.obj", "-q", "--strict"])
    assert r.exit_code == 4 and not (two_parts / "s.obj").exists()


def test_a_batch_shows_every_warning_in_every_output(two_parts, tmp_path):
    manifest = tmp_path / "m.yaml"
    manifest.write_text(yaml.safe_dump({"jobs": [
        {"name": "parts", "mesh": str(two_parts / "two.obj"),
         "handles": str(two_parts / "h.yaml"), "output": "parts.obj"},
        {"name": "clean", "mesh": BAR, "handles": TWIST, "output": "clean.obj"}]}))
    out = tmp_path / "out"
    r = invoke(["batch", manifest, "-o", out, "--report", out / "r.html", "--junit",
                out / "j.xml"])
    assert r.exit_code == 0, r.stderr
    assert "1 warning(s)" in r.stderr and "1 with warnings" in r.stderr
    rows = {row["job"]: row for row in json.loads((out / "summary.json").read_text())}
    assert len(rows["parts"]["warnings"]) == 1 and rows["clean"]["warnings"] == []
    assert "connected part" in rows["parts"]["warnings"][0]
    csv_text = (out / "summary.csv").read_text()
    assert csv_text.splitlines()[0].endswith(",warnings") and "connected part" in csv_text
    sidecar = json.loads((out / "parts.obj.srarap.json").read_text())
    assert sidecar["warnings"] == rows["parts"]["warnings"]
    assert "warning: 1 connected part" in (out / "r.html").read_text()
    root = check_junit((out / "j.xml").read_text())
    case = {c.get("name"): c for c in root.iter("testcase")}["parts"]
    assert "connected part" in case.find("system-err").text
    props = {p.get("name"): p.get("value") for p in root.iter("property")}
    assert props["parts.warnings"] == "1" and props["clean.warnings"] == "0"
    # the rerun is up to date and says the same warnings (from the record)
    r = invoke(["batch", manifest, "-o", out, "-q"])
    rows = {row["job"]: row for row in json.loads((out / "summary.json").read_text())}
    assert rows["parts"]["status"] == "up-to-date" and len(rows["parts"]["warnings"]) == 1


HOSTILE = ["ctrl\x01a", "esc\x1b[31mred", "nul\x00", "vt\x0bff\x0c", "bom\ufffe", "new\nline",
           "amp&<lt>\"q'"]


def test_junit_and_the_console_survive_any_job_name(tmp_path):
    manifest = tmp_path / "m.json"
    manifest.write_text(json.dumps({"jobs": [
        {"name": name, "mesh": BAR if k % 2 else str(tmp_path / "missing.obj"),
         "handles": TWIST, "output": f"o{k}.obj"} for k, name in enumerate(HOSTILE)]}))
    out = tmp_path / "out"
    r = invoke(["batch", str(manifest), "-o", out, "--junit", out / "j.xml"])
    assert r.exit_code == 8
    root = check_junit((out / "j.xml").read_text(encoding="utf-8"))
    names = [c.get("name") for c in root.iter("testcase")]
    assert names[0] == "ctrl\\x01a" and names[1] == "esc\\x1b[31mred" and names[2] == "nul\\x00"
    assert names[4] == "bom\\ufffe" and names[6] == "amp&<lt>\"q'"
    errors = [c.find("error") for c in root.iter("testcase") if c.find("error") is not None]
    assert len(errors) == 4 and all("missing.obj" in e.text for e in errors)
    assert "\x1b" not in r.stderr and "esc\\x1b[31mred" in r.stderr
    table = [line for line in r.stderr.splitlines() if line.startswith("new")]
    assert table and "\\n" in table[0]
    ET.fromstring((out / "j.xml").read_bytes())  # parses as bytes too


# --- plausibility -----------------------------------------------------------------------------

def _handles(tmp_path, action):
    path = tmp_path / "h.yaml"
    path.write_text(yaml.safe_dump({"groups": {
        "base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True},
        "top": {"box": {"min": [-2, -2, 9.99], "max": [2, 2, 10.01]}, **action}}}))
    return path


@pytest.mark.parametrize("action, words", [
    ({"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 20], [0, 0, 0, 1]]}, "mirror"),
    ({"matrix": [[1, 0.5, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}, "shears"),
    ({"rotate": {"axis": [0, 0, 1], "angle_deg": 720}}, "2 whole turn(s)"),
    ({"rotate": {"axis": [0, 0, 1], "angle_rad": 2 * np.pi}}, "1 whole turn(s)"),
    ({"rotate": {"axis": [0, 0, 1], "angle_deg": 270}}, "same targets as -90 degrees"),
])
def test_motions_no_static_solve_can_show_warn_and_fail_under_strict(tmp_path, action, words):
    h = _handles(tmp_path, action)
    r = invoke(["info", BAR, h])
    assert r.exit_code == 0 and words in r.output, r.output
    r = invoke(["deform", BAR, h, "-o", tmp_path / "o.obj", "--strict"])
    assert r.exit_code == 4 and words in r.stderr and not (tmp_path / "o.obj").exists()


def test_a_rotation_or_turn_under_half_a_turn_says_nothing(tmp_path):
    h = _handles(tmp_path, {"rotate": {"axis": [0, 0, 1], "angle_deg": 170}})
    r = invoke(["deform", BAR, h, "-o", tmp_path / "o.obj", "--strict", "-q"])
    assert r.exit_code == 0 and r.stderr == ""


def test_keyframes_no_frame_reaches_are_said(tmp_path):
    h = tmp_path / "k.yaml"
    h.write_text(yaml.safe_dump({"groups": {
        "base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True},
        "top": {"box": {"min": [-2, -2, 9.99], "max": [2, 2, 10.01]}, "keyframes": [
            {"time": 0, "rotate": {"axis": [0, 0, 1], "angle_deg": 0}},
            {"time": 0.01, "rotate": {"axis": [0, 0, 1], "angle_deg": 90}}]}}}))
    r = invoke(["animate", BAR, h, "-o", str(tmp_path / "f_{:02d}.obj"), "--fps", "24", "-q"])
    assert r.exit_code == 0 and "frame(s) 0.24 at --fps 24" in r.stderr
    r = invoke(["animate", BAR, h, "-o", str(tmp_path / "s_{:02d}.obj"), "--fps", "24",
                "--strict"])
    assert r.exit_code == 4 and not list(tmp_path.glob("s_*"))


# --- the summary under signals ----------------------------------------------------------------

def test_a_job_committed_before_the_stop_is_reported_done(tmp_path):
    jobs = [ManifestJob("j", BAR, TWIST, "o.obj")]
    import dataclasses
    import time

    before = time.time()
    assert batch.run_job(jobs[0], str(tmp_path)).status is JobStatus.OK
    # the signal came after its commit, before its result: the record tells
    done = interrupted_row(jobs[0], str(tmp_path), since=before)
    assert done.status is JobStatus.OK and "finished as the batch was stopped" in done.message
    # committed by an earlier batch: up to date; no record: interrupted
    assert interrupted_row(jobs[0], str(tmp_path), since=time.time() + 1).status \
        is JobStatus.UP_TO_DATE
    other = dataclasses.replace(jobs[0], output="p.obj")
    assert interrupted_row(other, str(tmp_path), since=before).status is JobStatus.INTERRUPTED


def test_a_sigint_as_a_job_commits_reports_it_done(tmp_path, monkeypatch):
    """In-process: the signal arrives right after the job's files are committed."""
    from srarap_cli.runtime import commit

    real = commit.commit_files

    def commit_then_interrupt(files, **kwargs):
        real(files, **kwargs)
        if any(path.endswith(".srarap.json") for path, _ in files):
            raise KeyboardInterrupt

    monkeypatch.setattr(job, "commit_files", commit_then_interrupt)
    manifest = tmp_path / "m.yaml"
    manifest.write_text(yaml.safe_dump({"jobs": [
        {"name": "a", "mesh": BAR, "handles": TWIST, "output": "a.obj"},
        {"name": "b", "mesh": BAR, "handles": TWIST, "output": "b.obj"}]}))
    r = invoke(["batch", manifest, "-o", tmp_path / "out", "-q"])
    rows = {row["job"]: row for row in json.loads((tmp_path / "out" / "summary.json")
                                                    .read_text())}
    assert r.exit_code == 130
    assert rows["a"]["status"] == "ok" and (tmp_path / "out" / "a.obj").exists()
    assert rows["b"]["status"] == "interrupted" and not (tmp_path / "out" / "b.obj").exists()



@pytest.mark.slow
def test_a_signal_as_a_local_dask_cluster_starts_leaves_nothing_running(tmp_path):
    """A SIGINT while LocalCluster starts its workers: the cluster object never existed to
    be closed, and the fork server waited forever for the workers it had forked (seen at
    0.6-0.9 s after the start: 3 hangs in 6 runs before the fix)."""
    import signal
    import time

    jobs = [{"name": f"j{i}", "mesh": BAR, "handles": TWIST, "output": f"o{i}.obj",
             "settings": {"tol": 0, "max_iter": 2000}} for i in range(4)]
    (tmp_path / "jobs.yaml").write_text(yaml.safe_dump({"jobs": jobs}))
    for delay in (0.55, 0.65, 0.75, 0.9):
        p = subprocess.Popen([sys.executable, "-m", "srarap_cli", "batch", "jobs.yaml", "-o",
                              f"out-{delay}", "--workers", "2", "--scheduler", "local"],
                             cwd=tmp_path, stderr=subprocess.PIPE, start_new_session=True)
        time.sleep(delay)
        os.killpg(p.pid, signal.SIGINT)
        try:
            _, err = p.communicate(timeout=120)
        finally:
            subprocess.run(["pkill", "-KILL", "-g", str(p.pid)])
        assert p.returncode == 130, err.decode()[-800:]
        lines = err.decode().splitlines()
        # no library's own lines: the table, the summary or the one error line only
        assert all(line.startswith(("srarap", "j")) for line in lines), lines


def test_a_job_regresses_on_its_farthest_vertex_not_its_mean(tmp_path):
    """One vertex 0.1 away and the rest exact: the mean is far below tol, the job regressed."""
    from srarap_cli.tasks.deform.golden import check_golden
    from srarap_cli.tasks.job_status import JobResult

    bar = read_mesh(BAR)
    moved = bar.vertices.copy()
    moved[5] += [0.1, 0, 0]
    write_mesh(tmp_path / "out.obj", bar.with_vertices(moved))
    result = JobResult("j", JobStatus.OK, 0)
    check_golden(result, {"golden": BAR, "tol": 0.01, "relative": False}, str(tmp_path / "out.obj"))
    assert result.status is JobStatus.REGRESSED and result.exit_code == 7
    assert abs(result.compare_max - 0.1) < 1e-12 and result.compare_mean < 0.01
    assert "vertex 5" in result.message
    within = JobResult("j", JobStatus.OK, 0)
    check_golden(within, {"golden": BAR, "tol": 0.2, "relative": False}, str(tmp_path / "out.obj"))
    assert within.status is JobStatus.OK
