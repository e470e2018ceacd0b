"""Handle files from standard input, a FIFO and a process substitution, read by their content
(YAML or JSON), as meshes are: the same bytes out as from the file itself (issue 60)."""
import json
import os
import re
import subprocess
import sys
import threading

import pytest
import yaml
from helpers import ROOT

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
TWIST = os.path.join(ROOT, "configs", "bar-twist.yaml")


def _deform(cwd, handles, out, **kwargs):
    return subprocess.run([sys.executable, "-m", "srarap_cli", "deform", BAR, handles, "-o",
                           out, "-q"], cwd=cwd, capture_output=True, timeout=120, **kwargs)


@pytest.fixture(scope="module")
def from_file(tmp_path_factory):
    folder = tmp_path_factory.mktemp("file")
    done = _deform(folder, TWIST, "file.obj")
    assert done.returncode == 0, done.stderr
    return (folder / "file.obj").read_bytes()


@pytest.mark.parametrize("form", ["yaml", "json"])
def test_a_handle_file_on_standard_input_is_read_by_its_content(tmp_path, from_file, form):
    text = open(TWIST, "rb").read()
    if form == "json":
        text = json.dumps(yaml.safe_load(text)).encode()
    done = _deform(tmp_path, "-", "out.obj", input=text)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out.obj").read_bytes() == from_file


def test_a_handle_file_through_a_fifo_is_read_once(tmp_path, from_file):
    fifo = tmp_path / "handles"
    os.mkfifo(fifo)

    def write():  # one writer, once: a second read of the FIFO would wait for another
        with open(fifo, "wb") as fh:
            fh.write(open(TWIST, "rb").read())

    writer = threading.Thread(target=write, daemon=True)
    writer.start()
    done = _deform(tmp_path, str(fifo), "out.obj")
    writer.join(timeout=5)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out.obj").read_bytes() == from_file


def test_a_process_substitution_templates_a_pose_in_one_line(tmp_path, from_file):
    twist45 = subprocess.run(["bash", "-c", f"{sys.executable} -m srarap_cli deform {BAR} "
                              f"<(sed 's/angle_deg: 90/angle_deg: 45/' {TWIST}) -o out.obj -q"],
                             cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert twist45.returncode == 0, twist45.stderr
    (tmp_path / "h45.yaml").write_text(open(TWIST).read().replace("angle_deg: 90",
                                                                  "angle_deg: 45"))
    assert _deform(tmp_path, "h45.yaml", "file45.obj").returncode == 0
    assert (tmp_path / "out.obj").read_bytes() == (tmp_path / "file45.obj").read_bytes()
    assert (tmp_path / "out.obj").read_bytes() != from_file
    info = subprocess.run(["bash", "-c", f"{sys.executable} -m srarap_cli info {BAR} "
                           f"<(cat {TWIST})"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=120)
    assert info.returncode == 0 and "top: " in info.stdout, info.stderr


@pytest.mark.parametrize("given, stdin, code, says", [
    ("-", b"", 4, "<stdin>: the stream is empty"),
    ("-", b"groups: [", 4, "<stdin>: not valid YAML"),
    ("-", b"{\"groups\": ", 4, "<stdin>: not valid JSON"),
])
def test_a_bad_stream_is_one_line(tmp_path, given, stdin, code, says):
    done = _deform(tmp_path, given, "out.obj", input=stdin)
    err = done.stderr.decode()
    assert done.returncode == code and says in err and err.count("\n") == 1, err
    assert not (tmp_path / "out.obj").exists()


def test_mesh_and_handles_cannot_both_be_standard_input(tmp_path):
    done = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", "-", "-", "-o",
                           "out.obj"], cwd=tmp_path, input=open(BAR, "rb").read(),
                          capture_output=True, timeout=120)
    err = done.stderr.decode()
    assert done.returncode == 2 and "cannot both be '-'" in err and err.count("\n") == 1


def test_a_sel_file_from_a_stream_is_refused_with_its_reason(tmp_path):
    fifo = tmp_path / "shape.sel"
    os.mkfifo(fifo)
    done = _deform(tmp_path, str(fifo), "out.obj")  # refused before the FIFO is opened
    err = done.stderr.decode()
    assert done.returncode == 4 and ".def" in err and err.count("\n") == 1, err


def test_a_handle_file_on_standard_input_waits_for_its_writer_as_a_fifo_does(tmp_path):
    """Issue 71 (HANG-4): ``-`` as the handle file waited for its writer without bound; the
    line says the time it really waited."""
    import subprocess
    import sys

    from helpers import ROOT
    code = ("import sys; import srarap_cli.io.documents as d; d.STREAM_WAIT = 1.0\n"
            "from srarap_cli.cli import main\n"
            f"sys.argv = ['srarap', 'deform', {ROOT + '/sample_meshes/bar.obj'!r}, '-', '-o',"
            f" {str(tmp_path / 'o.obj')!r}]\nmain()\n")
    p = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    try:  # the writer (this test) holds the pipe open and sends nothing
        p.wait(timeout=120)
        err = p.stderr.read()
    finally:
        p.kill()
        p.stdin.close()
    # the time as measured, to a tenth: a loaded machine may say 1.1
    assert p.returncode == 4 and re.search(r"<stdin>: nothing came through it in 1(\.\d)? s",
                                           err), err
    assert not (tmp_path / "o.obj").exists()
