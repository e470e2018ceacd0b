"""Property test: corrupted meshes and handle files never crash the command.

Whatever the input, ``srarap deform`` exits with a documented code, prints no traceback, and
either writes a complete output or none. ``SRARAP_FUZZ_EXAMPLES`` sets the budget (default 60;
the README reports a run with a larger one).
"""
import os
import tempfile

import numpy as np
import yaml
from click.testing import CliRunner
from helpers import tube_mesh
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from srarap_cli.cli import main
from srarap_cli.io.mesh import format_mesh, read_mesh

DOCUMENTED = {0, 2, 3, 4, 5, 6}
MESH = tube_mesh(rings=3, segments=4)
VALID = {
    ".obj": format_mesh(MESH, ".obj")[0].decode(),
    ".off": format_mesh(MESH, ".off")[0].decode(),
}
HANDLES = {"solver": {"max_iter": 5},
           "groups": {"base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]},
                               "fixed": True},
                      "tip": {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]},
                              "rotate": {"axis": [0, 1, 0], "angle": 30}}}}
TOKENS = st.sampled_from(["0", "-1", "nan", "inf", "-inf", "1e308", "99999", "x", "", "/",
                          "1//", "3.5", "f", "v", "#", "1e-320", "-0", "2/2/2",
                          "99999999999999999999", "9223372036854775808", "-99999999999",
                          "1e-150", "1e160"])
PLY = format_mesh(MESH, ".ply")[0]


@st.composite
def corrupted_mesh(draw):
    suffix = draw(st.sampled_from(sorted(VALID)))
    lines = VALID[suffix].splitlines()
    for _ in range(draw(st.integers(0, 4))):
        kind = draw(st.sampled_from(["drop", "dup", "token", "truncate", "garbage"]))
        if not lines:
            break
        i = draw(st.integers(0, len(lines) - 1))
        if kind == "drop":
            del lines[i]
        elif kind == "dup":
            lines.insert(i, lines[i])
        elif kind == "token":
            parts = lines[i].split(" ")
            j = draw(st.integers(0, len(parts) - 1))
            parts[j] = draw(TOKENS)
            lines[i] = " ".join(parts)
        elif kind == "truncate":
            lines = lines[:i]
        else:
            lines.insert(i, draw(st.text(max_size=20)))
    return suffix, ("\n".join(lines) + "\n").encode("utf-8", errors="replace")


def ascii_ply(mesh):
    rows = [" ".join(map(repr, v)) for v in mesh.vertices.tolist()]
    faces = np.split(mesh.face_vertices, np.cumsum(mesh.face_sizes)[:-1])
    rows += [" ".join(map(str, [len(f), *f.tolist()])) for f in faces]
    head = (f"ply\nformat ascii 1.0\nelement vertex {len(mesh.vertices)}\nproperty double x\n"
            f"property double y\nproperty double z\nelement face {len(faces)}\n"
            "property list uchar int vertex_indices\nend_header\n")
    return (head + "\n".join(rows) + "\n").encode()


PLY_ASCII = ascii_ply(MESH)


@st.composite
def corrupted_ply(draw):
    """The classes seen crashing or hanging other readers: header counts that disagree with
    the data, faces with 0-2 corners, a missing end_header, truncation, flipped bytes."""
    data = bytearray(draw(st.sampled_from([PLY, PLY_ASCII])))
    head_end = data.index(b"end_header")
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["count", "corners", "no_end", "truncate", "flip"]))
        if kind == "count":
            element = draw(st.sampled_from([b"vertex", b"face"]))
            at = data.find(b"element " + element + b" ")
            stop = data.find(b"\n", at)
            if at < 0 or stop < 0:
                continue
            value = draw(st.sampled_from([0, 1, 2, 10 ** 8, 2 ** 31 - 1, 2 ** 32, 10 ** 12]))
            data[at:stop] = b"element " + element + b" " + str(value).encode()
        elif kind == "corners":
            if b"end_header\n" not in data:
                continue
            body = data.index(b"end_header\n") + 11
            if data.startswith(b"ply\nformat ascii"):
                lines = bytes(data[body:]).split(b"\n")
                if len(lines) - 2 < len(MESH.vertices):
                    continue
                k = draw(st.integers(len(MESH.vertices), len(lines) - 2))
                lines[k] = b" ".join([str(draw(st.integers(0, 2))).encode(),
                                      *lines[k].split()[1:draw(st.integers(1, 4))]])
                data[body:] = b"\n".join(lines)
            else:
                # the first face's corner count byte follows the vertex table
                stride = (len(PLY) - PLY.index(b"end_header\n") - 11
                          - len(MESH.face_vertices) * 4 - len(MESH.face_sizes)) \
                    // len(MESH.vertices)
                pos = body + stride * len(MESH.vertices)
                if pos < len(data):
                    data[pos] = draw(st.sampled_from([0, 1, 2, 255]))
        elif kind == "no_end":
            data = data.replace(b"end_header", b"comment xx")
        elif kind == "truncate":
            data = data[:draw(st.integers(0, len(data)))]
        else:
            if len(data) > head_end:
                pos = draw(st.integers(head_end, len(data) - 1))
                data[pos] = draw(st.integers(0, 255))
    return ".ply", bytes(data)


JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-5, 10 ** 6) | st.integers(-2 ** 70, 2 ** 70)
    | st.floats(allow_nan=True)
    | st.text(max_size=8),
    lambda children: st.lists(children, max_size=4)
    | st.dictionaries(st.text(max_size=8), children, max_size=3), max_leaves=8)


@st.composite
def corrupted_handles(draw):
    doc = yaml.safe_load(yaml.safe_dump(HANDLES))
    for _ in range(draw(st.integers(0, 3))):
        group = doc["groups"][draw(st.sampled_from(["base", "tip"]))]
        kind = draw(st.sampled_from(["drop", "replace", "add", "root"]))
        key = draw(st.sampled_from(sorted(group) or ["box"]))
        if kind == "drop":
            group.pop(key, None)
        elif kind == "replace":
            group[key] = draw(JSON_VALUES)
        elif kind == "add":
            group[draw(st.sampled_from(["indices", "sphere", "matrix", "pivot", "bogus"]))] = \
                draw(JSON_VALUES)
        else:  # replace the whole document or its groups: nothing left to mutate after that
            return draw(st.sampled_from([{"groups": draw(JSON_VALUES)}, draw(JSON_VALUES)]))
    return doc


def alias_bomb(levels, width):
    lines = ["x0: &x0 [1, 2, 3, 4, 5, 6, 7, 8]"]
    lines += [f"x{k}: &x{k} [" + ", ".join([f"*x{k - 1}"] * width) + "]"
              for k in range(1, levels)]
    return "\n".join(lines) + "\n"


@st.composite
def handle_text(draw):
    """A handle file's text: a corrupted document, or one of the shapes that blow up parsers
    (alias bombs under any key, deep nesting)."""
    kind = draw(st.sampled_from(["doc", "doc", "doc", "bomb", "deep"]))
    if kind == "doc":
        return yaml.safe_dump(draw(corrupted_handles()))
    if kind == "bomb":
        key = draw(st.sampled_from(["solver", "bogus", "groups"]))
        bomb = alias_bomb(draw(st.integers(6, 10)), draw(st.integers(6, 10)))
        return yaml.safe_dump(HANDLES) + bomb.replace("x0:", f"{key}_0:", 1)
    depth = draw(st.integers(100, 3000))
    return "groups: " + "[" * depth + "]" * depth + "\n"


@settings(max_examples=int(os.environ.get("SRARAP_FUZZ_EXAMPLES", "60")), deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(mesh=corrupted_mesh() | corrupted_ply(), doc=handle_text(),
       suffix=st.sampled_from([".obj", ".ply", ".off"]))
def test_corrupted_input_never_crashes_or_leaves_partial_output(mesh, doc, suffix):
    with tempfile.TemporaryDirectory() as folder:
        mesh_path = os.path.join(folder, "m" + mesh[0])
        with open(mesh_path, "wb") as fh:
            fh.write(mesh[1])
        handle_path = os.path.join(folder, "h.yaml")
        with open(handle_path, "w") as fh:
            fh.write(doc)
        out = os.path.join(folder, "out" + suffix)
        r = CliRunner().invoke(main, ["deform", mesh_path, handle_path, "-o", out])
        event(f"exit code {r.exit_code}")
        assert r.exit_code in DOCUMENTED, r.output
        assert "Traceback" not in r.output
        lines = r.stderr.strip().splitlines()
        assert len(lines) >= 1
        if r.exit_code not in (0, 3):
            assert len(lines) == 1 and lines[0].startswith("srarap: error: "), r.stderr
        if r.exit_code == 0:
            written = read_mesh(out)
            assert len(written.vertices) == len(read_mesh(mesh_path).vertices)
            assert np.isfinite(written.vertices).all()
        else:
            assert sorted(os.listdir(folder)) == sorted(["m" + mesh[0], "h.yaml"])


BUDGET = int(os.environ.get("SRARAP_FUZZ_EXAMPLES", "60"))
SIDE_TOKENS = st.sampled_from(["0", "1", "2", "-1", "1e308", "-1e308", "nan", "inf", "a", "",
                               "0 0", "1 16", "3.5", "1e200", "\xe9", "0 0 0 1"])


@st.composite
def side_files(draw):
    """A handle file that names a .dmat, .sel or .def, with generated contents (binary .dmat
    headers, wrong sizes, huge and non-finite entries, affine rows) and maybe a BOM."""
    n = len(MESH.vertices)
    kind = draw(st.sampled_from(["dmat", "dmat-binary", "sel", "def"]))
    if kind == "dmat":
        body = f"1 {n}\n" + "\n".join(draw(st.lists(SIDE_TOKENS, min_size=n - 1, max_size=n + 1)))
        data, name = body.encode(), "g.dmat"
    elif kind == "dmat-binary":
        rows = draw(st.integers(-1, n + 1))
        data = b"0 0\n" + f"1 {rows}\n".encode() + draw(st.binary(max_size=8 * (n + 2)))
        name = "g.dmat"
    elif kind == "sel":
        data, name = "\n".join(draw(st.lists(SIDE_TOKENS, min_size=n - 1, max_size=n + 1))).encode(), "s.sel"
    else:
        data = "\n".join(" ".join(draw(st.lists(SIDE_TOKENS, min_size=4, max_size=4)))
                         for _ in range(4)).encode()
        name = "m.def"
    status = draw(st.sampled_from(["fixed", "handle", ["a"], {}, 3]))
    group = {"dmat": {"file": "g.dmat", "group": 0}} if name == "g.dmat" else \
        {"sel": {"file": "s.sel", "status": status}} if name == "s.sel" else \
        {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]}, "matrix": "m.def"}
    doc = {"groups": {"base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]},
                               "fixed": True},
                      "g": {**group, **({} if "matrix" in group else {"fixed": True})}}}
    bom = draw(st.booleans())
    return name, (b"\xef\xbb\xbf" if bom else b"") + data, yaml.safe_dump(doc)


@settings(max_examples=BUDGET, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(side=side_files(), bom_mesh=st.booleans(), bom_handles=st.booleans())
def test_side_files_and_byte_order_marks_never_crash(side, bom_mesh, bom_handles):
    name, data, doc = side
    with tempfile.TemporaryDirectory() as folder:
        mark = b"\xef\xbb\xbf"
        with open(os.path.join(folder, "m.obj"), "wb") as fh:
            fh.write(mark * bom_mesh + VALID[".obj"].encode())
        with open(os.path.join(folder, name), "wb") as fh:
            fh.write(data)
        with open(os.path.join(folder, "h.yaml"), "wb") as fh:
            fh.write(mark * bom_handles + doc.encode())
        before = sorted(os.listdir(folder))
        out = os.path.join(folder, "out.obj")
        r = CliRunner().invoke(main, ["deform", os.path.join(folder, "m.obj"),
                                      os.path.join(folder, "h.yaml"), "-o", out])
        event(f"exit code {r.exit_code}")
        assert r.exit_code in DOCUMENTED, r.output
        if r.exit_code not in (0, 3):
            assert r.stderr.count("\n") == 1 and r.stderr.startswith("srarap: error: ")
            assert sorted(os.listdir(folder)) == before
        if r.exit_code == 0:
            assert len(read_mesh(out).vertices) == len(MESH.vertices)


LOG_VALUES = st.sampled_from(["0", "1.5", "", "x", "nan", "inf", "-1", "1e400", "null", "[]"])


@settings(max_examples=BUDGET, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rows=st.lists(st.tuples(LOG_VALUES, LOG_VALUES, LOG_VALUES), min_size=0, max_size=4),
       kind=st.sampled_from(["csv", "jsonl", "jsonl-list"]), bom=st.booleans())
def test_plot_of_generated_logs_is_a_picture_or_one_line(rows, kind, bom):
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "log." + kind.split("-")[0])
        if kind == "csv":
            text = "iteration,total,seconds\n" + "".join(",".join(r) + "\n" for r in rows)
        elif kind == "jsonl":
            text = "".join("{" + ", ".join(f'"{k}": {v or chr(34) * 2}' for k, v in
                                           zip(("iteration", "total", "seconds"), r)) + "}\n"
                           for r in rows)
        else:
            text = "".join("[" + ", ".join(v or "0" for v in r) + "]\n" for r in rows)
        with open(path, "wb") as fh:
            fh.write(b"\xef\xbb\xbf" * bom + text.encode())
        out = os.path.join(folder, "p.png")
        r = CliRunner().invoke(main, ["plot", path, "-o", out])
        event(f"exit code {r.exit_code}")
        assert r.exit_code in (0, 4), r.output
        assert os.path.exists(out) == (r.exit_code == 0)
        if r.exit_code:
            assert r.stderr.count("\n") == 1


@settings(max_examples=max(BUDGET // 4, 10), deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(alias=st.sampled_from(["same", "dot", "absolute", "hard", "soft"]),
       which=st.sampled_from(["mesh", "handles", "dmat"]),
       role=st.sampled_from(["-o", "--log", "--preview"]))
def test_an_output_naming_an_input_in_any_way_is_refused(alias, which, role):
    with tempfile.TemporaryDirectory() as folder:
        mesh = os.path.join(folder, "m.obj")
        with open(mesh, "w") as fh:
            fh.write(VALID[".obj"])
        with open(os.path.join(folder, "g.dmat"), "w") as fh:
            fh.write(f"1 {len(MESH.vertices)}\n" + "0\n" * len(MESH.vertices))
        doc = yaml.safe_load(yaml.safe_dump(HANDLES))
        doc["groups"]["tip"]["dmat"] = {"file": "g.dmat", "group": 1}
        with open(os.path.join(folder, "h.yaml"), "w") as fh:
            yaml.safe_dump(doc, fh)
        target = {"mesh": mesh, "handles": os.path.join(folder, "h.yaml"),
                  "dmat": os.path.join(folder, "g.dmat")}[which]
        ext = {"-o": ".obj", "--log": ".csv", "--preview": ".png"}[role]
        name = os.path.join(folder, "alias" + ext)
        if alias in ("same", "dot", "absolute"):
            os.symlink(target, name)  # a name with the role's extension for the same file
        elif alias == "hard":
            os.link(target, name)
        else:
            os.symlink(os.path.relpath(target, folder), name)
        given_name = {"dot": os.path.join(folder, ".", "alias" + ext)}.get(alias, name)
        contents = {p: open(os.path.join(folder, p), "rb").read() for p in os.listdir(folder)}
        args = ["deform", mesh, os.path.join(folder, "h.yaml"), "-o",
                os.path.join(folder, "o.obj")]
        args = args[:4] + [given_name] if role == "-o" else args + [role, given_name]
        r = CliRunner().invoke(main, args)
        assert r.exit_code == 4 and "refusing to overwrite an input" in r.stderr, r.output
        assert {p: open(os.path.join(folder, p), "rb").read()
                for p in os.listdir(folder)} == contents
