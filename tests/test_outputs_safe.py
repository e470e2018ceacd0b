"""Nothing the user did not ask to overwrite is touched, and a run that fails leaves every
output as it was: outputs refused when they resolve to an input (every command, every way of
naming the same file), and all outputs of a run committed as one unit."""
import os
import subprocess
import sys

import pytest
from click.testing import CliRunner
from helpers import run_cli, tube_mesh

from srarap_cli.cli import main
from srarap_cli.io.mesh import write_mesh
from srarap_cli.runtime import commit
from srarap_cli.runtime.errors import OutputError

HANDLES = ("groups:\n  base: {box: {min: [-2, -2, -0.01], max: [2, 2, 0.01]}, fixed: true}\n"
           "  tip: {box: {min: [-2, -2, 5.99], max: [2, 2, 6.01]}, rotate: "
           "{axis: [0, 0, 1], angle_deg: 30}}\n")
KEYED = ("groups:\n  base: {box: {min: [-2, -2, -0.01], max: [2, 2, 0.01]}, fixed: true}\n"
         "  tip:\n    box: {min: [-2, -2, 5.99], max: [2, 2, 6.01]}\n"
         "    keyframes:\n      - {frame: 0, rotate: {axis: [0, 0, 1], angle_deg: 0}}\n"
         "      - {frame: 2, rotate: {axis: [0, 0, 1], angle_deg: 20}}\n")


@pytest.fixture
def folder(tmp_path):
    write_mesh(str(tmp_path / "m.obj"), tube_mesh(rings=6, segments=6))
    write_mesh(str(tmp_path / "m.off"), tube_mesh(rings=6, segments=6))
    (tmp_path / "h.yaml").write_text(HANDLES)
    (tmp_path / "k.yaml").write_text(KEYED)
    (tmp_path / "g.dmat").write_text("1 3\n0\n0\n0\n")
    (tmp_path / "d.yaml").write_text(
        "groups:\n  g: {dmat: {file: g.dmat, group: 0}, fixed: true}\n")
    (tmp_path / "log.csv").write_text("iteration,total,seconds\n0,1.0,0.0\n")
    os.link(tmp_path / "m.obj", tmp_path / "hard.obj")
    os.link(tmp_path / "g.dmat", tmp_path / "dmat.obj")
    for link, target in [("soft.obj", "m.obj"), ("h.csv", "h.yaml"), ("m.png", "m.obj"),
                         ("k.csv", "k.yaml"), ("m.json", "m.obj"), ("log.png", "log.csv")]:
        os.symlink(tmp_path / target, tmp_path / link)
    return tmp_path


def _run(folder, *args):
    return run_cli(args, cwd=folder)


def _snapshot(folder):
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}


@pytest.mark.parametrize("args", [
    ["deform", "m.obj", "h.yaml", "-o", "m.obj"],
    ["deform", "m.obj", "h.yaml", "-o", "./m.obj"],
    ["deform", "m.obj", "h.yaml", "-o", "{abs}/m.obj"],
    ["deform", "m.obj", "h.yaml", "-o", "hard.obj"],
    ["deform", "soft.obj", "h.yaml", "-o", "m.obj"],
    ["deform", "m.off", "h.yaml", "-o", "m.off", "--keep-unconverged", "--max-iter", "1"],
    ["deform", "m.obj", "h.yaml", "-o", "o.obj", "--log", "h.csv"],
    ["deform", "m.obj", "d.yaml", "-o", "dmat.obj"],
    ["deform", "m.obj", "h.yaml", "-o", "o.obj", "--preview", "m.png"],
    ["animate", "m.obj", "k.yaml", "-o", "{:1d}.obj"],  # frame 0 is 0.obj, see below
    ["animate", "m.obj", "k.yaml", "-o", "f_{}.obj", "--log", "k.csv"],
    ["bench", "m.obj", "h.yaml", "-o", ".", "--time-budget", "1"],
    ["compare", "m.obj", "hard.obj", "--json", "m.json"],
    ["render", "m.obj", "-o", "m.png"],
    ["render", "hard.obj", "--handles", "h.yaml", "-o", "m.png"],
    ["plot", "log.csv", "-o", "log.png"],
])
def test_an_output_that_is_an_input_is_refused_before_any_work(folder, args):
    args = [a.replace("{abs}", str(folder)) for a in args]
    if args[0] == "animate" and args[4] == "{:1d}.obj":
        write_mesh(str(folder / "0.obj"), tube_mesh(rings=6, segments=6))
        args[1] = "0.obj"
    if args[0] == "bench":
        (folder / "summary.json").write_text(HANDLES)  # handles named like bench's summary
        args[2] = "summary.json"
    before = _snapshot(folder)
    p = _run(folder, *args)
    assert p.returncode == 4, p.stderr
    assert p.stderr.startswith("srarap: error: ") and p.stderr.count("\n") == 1, p.stderr
    assert "refusing to overwrite an input" in p.stderr
    assert _snapshot(folder) == before


def test_commit_puts_back_what_it_replaced_when_a_later_rename_fails(tmp_path, monkeypatch):
    a, b, c = tmp_path / "a.obj", tmp_path / "b.csv", tmp_path / "c.png"
    a.write_bytes(b"old a")
    b.write_bytes(b"old b")
    real, calls = os.replace, []

    def flaky(src, dst):
        calls.append(dst)
        if len(calls) == 3:
            raise OSError(28, "No space left on device", src)
        return real(src, dst)

    monkeypatch.setattr(commit.os, "replace", flaky)
    with pytest.raises(OutputError, match=r"c\.png: cannot write: No space left"):
        commit.commit_files([(str(a), b"new a"), (str(b), b"new b"), (str(c), b"new c")])
    assert a.read_bytes() == b"old a" and b.read_bytes() == b"old b" and not c.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.obj", "b.csv"]


def test_commit_names_the_users_file_not_a_temporary_one(tmp_path):
    long_name = str(tmp_path / ("x" * 300 + ".obj"))
    with pytest.raises(OutputError) as err:
        commit.commit_files([(str(tmp_path / "ok.obj"), b"1"), (long_name, b"2")])
    assert ".srarap-" not in str(err.value) and "x" * 300 in str(err.value)
    assert list(tmp_path.iterdir()) == []


def test_a_folder_placed_at_a_target_after_the_check_leaves_every_output_as_it_was(
        folder, monkeypatch):
    (folder / "o.obj").write_bytes(b"previous mesh")
    real = commit.commit_files

    def swap_then_commit(files, **kwargs):
        os.mkdir(folder / "o.csv")  # the log's target became a folder after the check
        return real(files, **kwargs)

    monkeypatch.setattr("srarap_cli.tasks.deform.job.commit_files", swap_then_commit)
    monkeypatch.chdir(folder)
    r = CliRunner().invoke(main, ["deform", "m.obj", "h.yaml", "-o", "o.obj", "--log", "o.csv",
                                  "--preview", "o.png"])
    assert r.exit_code == 6, r.output
    assert "o.csv: is a folder" in r.output
    assert (folder / "o.obj").read_bytes() == b"previous mesh"
    assert not (folder / "o.png").exists()
    assert not [p for p in os.listdir(folder) if p.startswith(".srarap-")]


def test_a_batch_job_whose_sidecar_cannot_be_written_leaves_its_mesh_as_it_was(folder):
    (folder / "jobs.yaml").write_text("jobs:\n  - {mesh: m.obj, handles: h.yaml, output: o.obj}\n")
    (folder / "out").mkdir()
    (folder / "out" / "o.obj").write_bytes(b"previous mesh")
    (folder / "out" / "o.obj.srarap.json").mkdir()
    p = _run(folder, "batch", "jobs.yaml", "-o", "out")
    assert p.returncode == 8, p.stderr
    assert (folder / "out" / "o.obj").read_bytes() == b"previous mesh"


def test_a_file_size_limit_mid_write_leaves_every_output_as_it_was(folder):
    """RLIMIT_FSIZE below the mesh's size: the write fails with EFBIG (Python ignores
    SIGXFSZ), reported against the user's file; the old mesh and log stay, nothing is left."""
    import resource

    (folder / "o.obj").write_bytes(b"previous mesh")
    (folder / "o.csv").write_bytes(b"previous log")
    limit = 4096  # the log fits, the mesh (about 40 KB) does not

    def small_files():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    p = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", "m.obj", "h.yaml", "-o",
                        "o.obj", "--log", "o.csv"], cwd=folder, capture_output=True, text=True,
                       timeout=120, preexec_fn=small_files)
    assert p.returncode == 6, p.stderr
    assert p.stderr.startswith("srarap: error: o.obj: cannot write") and p.stderr.count("\n") == 1
    assert (folder / "o.obj").read_bytes() == b"previous mesh"
    assert (folder / "o.csv").read_bytes() == b"previous log"
    assert not [p for p in os.listdir(folder) if p.startswith(".srarap-")]


@pytest.mark.parametrize("name", [".srarap-99999999999999999999-x.tmp",
                                  ".srarap-99999999999999999999-abcdefgh.tmp",
                                  ".srarap-4194305123-abcdefgh.tmp", ".srarap-12-not-ours.tmp",
                                  ".srarap-0-abcdefgh.tmp"])
def test_a_strangers_file_named_like_ours_is_left_alone_and_breaks_no_write(tmp_path, name):
    """Issue 71 (EXIT-4): an id past a C long in such a name made every write in the folder
    exit 1 (OverflowError); an id no process can have is someone else's file."""
    from srarap_cli.runtime.commit import commit_files
    stranger = tmp_path / name
    stranger.write_text("theirs")
    commit_files([(str(tmp_path / "out.obj"), b"mine")])
    assert (tmp_path / "out.obj").read_bytes() == b"mine" and stranger.read_text() == "theirs"


def test_a_dead_writers_leftover_is_still_swept(tmp_path):
    import subprocess
    import sys
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()
    left = tmp_path / f".srarap-{dead}-abcd1234.tmp"
    left.write_text("half")
    from srarap_cli.runtime.commit import commit_files
    commit_files([(str(tmp_path / "out.obj"), b"mine")])
    assert not left.exists()
