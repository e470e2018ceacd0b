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
from srarap_cli.mesh_io import format_mesh, read_mesh

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
                          "1//", "3.5", "f", "v", "#", "1e-320", "-0", "2/2/2"])


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
    return suffix, "\n".join(lines) + "\n"


JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-5, 10 ** 6) | st.floats(allow_nan=True)
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


@settings(max_examples=int(os.environ.get("SRARAP_FUZZ_EXAMPLES", "60")), deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(mesh=corrupted_mesh(), doc=corrupted_handles(), suffix=st.sampled_from([".obj", ".ply", ".off"]))
def test_corrupted_input_never_crashes_or_leaves_partial_output(mesh, doc, suffix):
    with tempfile.TemporaryDirectory() as folder:
        mesh_path = os.path.join(folder, "m" + mesh[0])
        with open(mesh_path, "w", encoding="utf-8", errors="replace") as fh:
            fh.write(mesh[1])
        handle_path = os.path.join(folder, "h.yaml")
        with open(handle_path, "w") as fh:
            fh.write(yaml.safe_dump(doc))
        out = os.path.join(folder, "out" + suffix)
        r = CliRunner().invoke(main, ["deform", mesh_path, handle_path, "-o", out])
        event(f"exit code {r.exit_code}")
        assert r.exit_code in DOCUMENTED, r.output
        assert "Traceback" not in r.output
        assert len(r.stderr.strip().splitlines()) >= 1
        if r.exit_code in (0, 3):
            written = read_mesh(out)
            assert len(written.vertices) == len(read_mesh(mesh_path).vertices)
            assert np.isfinite(written.vertices).all()
        else:
            assert sorted(os.listdir(folder)) == sorted(["m" + mesh[0], "h.yaml"])
