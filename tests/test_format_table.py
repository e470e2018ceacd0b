"""One table of mesh formats: standard input's format is told from its bytes, and a format
registered from outside the package is read and written through the command line with no
other module edited."""
import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import ROOT

from srarap_cli.cli import main
from srarap_cli.io.mesh import FORMATS, Mesh, MeshFormat, read_mesh, register_format, write_mesh
from srarap_cli.io.mesh.formats import by_content, extensions
from srarap_cli.runtime.errors import InputError

BAR = f"{ROOT}/sample_meshes/bar.obj"
TWIST = f"{ROOT}/configs/bar-twist.yaml"


def _deform(*args, stdin=None):
    return CliRunner().invoke(main, ["deform", *args], input=stdin)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """The bar in every built-in format and variant (written by srarap: the bytes other
    tools would give are tested by the readers' own tests)."""
    folder = tmp_path_factory.mktemp("formats")
    bar = read_mesh(BAR)
    tri = Mesh.from_arrays(bar.vertices, bar.triangles()[0])
    out = {"obj": BAR}
    for name, ascii in (("off", False), ("ply", False), ("ply", True), ("stl", False)):
        path = folder / f"bar{'-ascii' if ascii else ''}.{name}"
        path.write_bytes(FORMATS[name].write(tri, ascii)[0])
        out[f"{name}{'-ascii' if ascii else ''}"] = str(path)
    facets = "".join(
        "facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {x:.17g} {y:.17g} {z:.17g}\n"
                                                    for x, y, z in tri.vertices[f])
        + "endloop\nendfacet\n" for f in tri.triangles()[0])
    path = folder / "bar-ascii.stl"
    path.write_text(f"solid bar\n{facets}endsolid bar\n")
    out["stl-ascii"] = str(path)
    return out


@pytest.mark.parametrize("variant", ["obj", "off", "ply", "ply-ascii", "stl", "stl-ascii"])
def test_standard_input_is_read_in_the_format_its_bytes_show(files, variant, tmp_path):
    """``cat m.off | srarap deform - h.yaml -o -``: no --input-format, and the output in
    the input's format, the same bytes as from the file."""
    path = files[variant]
    name = variant.split("-")[0]
    data = open(path, "rb").read()
    assert by_content(data[:4096], len(data)) is FORMATS[name]
    piped = _deform("-", TWIST, "-o", "-", "-q", stdin=data)
    assert piped.exit_code == 0, piped.output
    ref = tmp_path / f"ref.{name}"
    named = _deform(path, TWIST, "-o", str(ref), "-q")
    assert named.exit_code == 0 and piped.stdout_bytes == ref.read_bytes()


def test_binary_stl_through_a_real_pipe(files):
    """A pipe has no size to look at before it is read: the whole stream decides."""
    data = open(files["stl"], "rb").read()
    p = subprocess.run(f"cat '{files['stl']}' | {sys.executable} -m srarap_cli deform - "
                       f"'{TWIST}' -o - -q", shell=True, capture_output=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert p.stdout[80:84] == data[80:84] and len(p.stdout) == len(data)


@pytest.mark.parametrize("data, message", [
    (b"", "standard input is empty"),
    (b"hello world\n" * 10, "<stdin>: not a mesh: it is text of no mesh format"),
    (b"hello world\n" * 10, "give --input-format obj|off|ply|stl"),
])
def test_unknown_content_on_standard_input_is_one_clear_line(data, message):
    r = _deform("-", TWIST, "-o", "-", stdin=data)
    assert r.exit_code == 4 and message in r.output and r.stdout_bytes == b""


def test_input_format_still_overrides_what_the_bytes_say(files):
    r = _deform("-", TWIST, "-o", "-", "--input-format", "ply", stdin=open(BAR, "rb").read())
    assert r.exit_code == 4 and "<stdin>" in r.output


# --- a format from outside the package: "TRI" files, one "v x y z" or "t a b c" a line --

def _read_tri(path):
    rows = [line.split() for line in open(path).read().splitlines()[1:] if line.strip()]
    V = np.array([[float(x) for x in r[1:]] for r in rows if r[0] == "v"])
    F = np.array([[int(i) for i in r[1:]] for r in rows if r[0] == "t"])
    if not len(V) or not len(F):
        raise InputError(f"{path}: a TRI file needs v and t lines")
    return Mesh.from_arrays(V, F)


def _write_tri(mesh, ascii):
    V, F = mesh.vertices, mesh.triangles()[0]
    lines = ["TRI"] + [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in V] + [f"t {a} {b} {c}"
                                                                   for a, b, c in F]
    return ("\n".join(lines) + "\n").encode(), ["TRI writes in its own way"]


@pytest.fixture
def toy():
    fmt = register_format(MeshFormat(
        "tri", (".tri",), _read_tri, _write_tri, read_factor=30,
        signature=lambda head, size: head.startswith(b"TRI\n"),
        description="a toy format of the tests"))
    yield fmt
    del FORMATS["tri"]


def test_a_format_registered_from_outside_is_read_and_written_by_the_cli(toy, tmp_path):
    bar = read_mesh(BAR)
    # what it does not declare it keeps is said for it, before its own lines
    assert write_mesh(str(tmp_path / "bar.tri"), bar) == [
        f"{int((bar.face_sizes == 4).sum())} quads written as triangles (TRI keeps "
        "triangles) [format-drops]",
        "texture coordinates not written: TRI does not keep them (.obj does) [format-drops]",
        "TRI writes in its own way [format-drops]"]
    assert ".tri" in extensions() and "tri" in CliRunner().invoke(
        main, ["deform", "--help"]).output
    r = _deform(str(tmp_path / "bar.tri"), TWIST, "-o", str(tmp_path / "out.tri"))
    assert r.exit_code == 0, r.output
    assert "warning: TRI writes in its own way" in r.output
    out = read_mesh(str(tmp_path / "out.tri"))
    ref = tmp_path / "ref.obj"
    assert _deform(BAR, TWIST, "-o", str(ref), "-q").exit_code == 0
    np.testing.assert_allclose(out.vertices, read_mesh(str(ref)).vertices, atol=1e-9)
    piped = _deform("-", TWIST, "-o", "-", "-q", stdin=(tmp_path / "bar.tri").read_bytes())
    assert piped.exit_code == 0 and piped.stdout_bytes == (tmp_path / "out.tri").read_bytes()
    as_obj = _deform(str(tmp_path / "bar.tri"), TWIST, "-o", "-", "--format", "obj", "-q")
    assert as_obj.exit_code == 0 and as_obj.stdout_bytes.startswith(b"# written by srarap")
    info = CliRunner().invoke(main, ["info", str(tmp_path / "bar.tri")])
    assert info.exit_code == 0 and str(len(bar.vertices)) in info.output


def test_a_format_cannot_take_another_formats_extension():
    with pytest.raises(ValueError, match=r"\.obj is already obj's"):
        register_format(MeshFormat("mine", (".obj",), _read_tri, _write_tri, 1,
                                   lambda head, size: False))
    assert "mine" not in FORMATS


def test_the_memory_guard_reads_the_factor_from_the_table(monkeypatch, tmp_path):
    monkeypatch.setenv("SRARAP_MEMORY_LIMIT", "1000000")
    big = tmp_path / "big.obj"
    big.write_bytes(open(BAR, "rb").read())  # about 60 kB: 20 x that is over 1 MB
    with pytest.raises(InputError, match="reading it needs about"):
        read_mesh(str(big))
    r = _deform("-", TWIST, "-o", "-", stdin=big.read_bytes())
    assert r.exit_code == 4 and "<stdin>: reading it needs about" in r.output
