"""One case of each edge the generators of test_edges.py do not cover: stale frames, frame
patterns never enumerated, info's cost and empty groups, the API's argument errors, bad
options and nesting, ASCII STL variants, samples' folder, what PLY output cannot keep."""
import os

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from helpers import ROOT, tube_mesh

import srarap_cli
from srarap_cli.cli import main
from srarap_cli.io.mesh import format_mesh

BAR = f"{ROOT}/sample_meshes/bar.obj"
ANIMATED = f"{ROOT}/configs/bar-twist-animated.yaml"


def _run(*args, **kwargs):
    return CliRunner().invoke(main, list(args), **kwargs)


def test_an_animation_that_stops_removes_the_later_frames_of_an_earlier_run(tmp_path):
    pattern = str(tmp_path / "f_{:03d}.obj")
    assert _run("animate", BAR, ANIMATED, "-o", pattern, "--frames", "6", "-q").exit_code == 0
    (tmp_path / "unrelated_007.obj").write_text("keep")
    r = _run("animate", BAR, ANIMATED, "-o", pattern, "--frames", "6", "--max-iter", "2")
    assert r.exit_code == 3
    left = sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith("."))
    stopped = int(r.output.split("STOPPED at frame ")[1].split(":")[0])
    assert left == [f"f_{k:03d}.obj" for k in range(stopped)] + ["unrelated_007.obj"]
    assert f"removed {6 - stopped} later frame(s) of an earlier run" in r.output


def test_a_hundred_million_frames_are_never_enumerated(tmp_path, monkeypatch):
    """The folder is listed, the frames' names never made one by one: counted."""
    from srarap_cli.tasks.animate import job as animate_job

    named = []
    real = animate_job.frames_on_disk
    monkeypatch.setattr(animate_job, "frames_on_disk",
                        lambda pattern: named.append(pattern) or real(pattern))
    r = _run("animate", BAR, ANIMATED, "-o", str(tmp_path / "f_{:09d}.obj"),
             "--frames", "100000000", "--max-frames", "1000000000", "--max-iter", "2")
    assert r.exit_code == 3 and len(named) <= 2
    assert len(list(tmp_path.iterdir())) <= 2


def test_an_input_named_by_the_frame_pattern_is_still_refused(tmp_path):
    mesh = tmp_path / "f_003.obj"
    mesh.write_bytes(open(BAR, "rb").read())
    r = _run("animate", str(mesh), ANIMATED, "-o", str(tmp_path / "f_{:03d}.obj"),
             "--frames", "5")
    assert r.exit_code == 4 and "refusing to overwrite" in r.output


def _calls(func):
    """``(result, Python and C function calls func made)``: a measure of work, not time."""
    import sys

    count = [0]

    def profile(frame, event, arg):
        if event in ("call", "c_call"):
            count[0] += 1

    sys.setprofile(profile)
    try:
        result = func()
    finally:
        sys.setprofile(None)
    return result, count[0]


def test_info_of_thousands_of_groups_costs_what_deform_costs(tmp_path):
    """Overlaps from a sparse product: doubling the groups doubles the work (pair by pair it
    quadrupled: 2,000 one-vertex groups took 39 s)."""
    from srarap_cli.io.handles import parse_handles
    from srarap_cli.tasks.info import handles_info

    mesh = tube_mesh(rings=100, segments=24)
    work = []
    for count in (1000, 2000):
        groups = {f"g{i}": {"indices": [i], "fixed": True} for i in range(count)}
        groups["g0"]["indices"] = [0, 1]
        constraints = parse_handles({"groups": groups}, mesh.vertices)
        info, calls = _calls(lambda c=constraints: handles_info(mesh, c, "m.obj"))
        work.append(calls)
        assert {"groups": ["g0", "g1"], "vertices": 1} in info["overlaps"]
    assert work[1] < 3 * work[0], work


@pytest.mark.parametrize("status", [0, 2])
def test_a_sel_whose_vertices_all_have_one_status_is_described(tmp_path, status):
    mesh = tube_mesh(rings=3, segments=4)
    (tmp_path / "m.obj").write_bytes(format_mesh(mesh, ".obj")[0])
    np.savetxt(tmp_path / "h.sel", np.full(len(mesh.vertices), status), fmt="%d")
    np.savetxt(tmp_path / "h.def", np.eye(4))
    info = _run("info", str(tmp_path / "m.obj"), str(tmp_path / "h.sel"))
    deform = _run("deform", str(tmp_path / "m.obj"), str(tmp_path / "h.sel"), "-o",
                  str(tmp_path / "o.obj"))
    assert info.exit_code == deform.exit_code == 0, info.output + deform.output
    assert "selects no vertex" in info.output


@pytest.mark.parametrize("mesh, message", [
    (([[0, 0, 0], [1, 0, 0], [0, 1j, 0]], [[0, 1, 2]]), "V must hold real numbers"),
    (([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2], [0, 1]]), "F must be a rectangular"),
    (([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.array([[0, 1, 2**64 - 1]], dtype=np.uint64)),
     "F: vertex index 18446744073709551615 out of range"),
])
def test_the_api_names_the_wrong_argument(mesh, message):
    with pytest.raises(ValueError, match=message):
        srarap_cli.deform(mesh, ([0], [[0.0, 0.0, 0.0]]))


def test_a_nan_in_a_mesh_object_is_the_meshs_error_not_a_handles():
    mesh = srarap_cli.Mesh.from_arrays([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    mesh.vertices[0, 0] = np.nan
    handles = {"groups": {"a": {"box": {"min": [-1, -1, -1], "max": [2, 2, 2]},
                                "fixed": True}}}
    with pytest.raises(ValueError, match="V has NaN"):
        srarap_cli.deform(mesh, handles)


def test_bad_scheduler_deep_logs_and_deep_cache_paths_are_one_line(tmp_path):
    r = _run("batch", f"{ROOT}/configs/example-jobs.yaml", "-o", str(tmp_path / "o"),
             "--scheduler", "garbage")
    assert r.exit_code == 2 and "--scheduler" in r.output
    (tmp_path / "deep.jsonl").write_text("[" * 100000 + "]" * 100000 + "\n")
    r = _run("plot", str(tmp_path / "deep.jsonl"), "-o", str(tmp_path / "p.png"))
    assert r.exit_code == 4 and "nested too deeply" in r.output
    r = _run("deform", BAR, f"{ROOT}/configs/bar-twist.yaml", "-o", str(tmp_path / "c.obj"),
             "--multires", "100", "--cache", str(tmp_path) + "/a" * 20000)
    assert r.exit_code == 0 and "cannot write the cache (too many folder levels)" in r.output


FACET = ("facet normal 0 0 1\n outer loop\n  vertex {a}\n  vertex {b}\n  vertex {c}\n"
         " endloop\nendfacet\n")


@pytest.mark.parametrize("text", [
    "solid a\n" + FACET.format(a="0 0 0", b="1 0 0", c="0 1 0") + "endsolid a\nsolid b\n"
    + FACET.format(a="1 0 0", b="1 1 0", c="0 1 0") + "endsolid b\n",
    "solid facet\n" + FACET.format(a="0 0 0", b="1 0 0", c="0 1 0") + "endsolid facet\n",
    "SOLID X\n" + FACET.format(a="0 0 0", b="1 0 0", c="0 1 0").upper() + "ENDSOLID X\n",
])
def test_legal_ascii_stl_variants_are_read(tmp_path, text):
    (tmp_path / "m.stl").write_text(text)
    r = _run("info", str(tmp_path / "m.stl"))
    assert r.exit_code == 0, r.output


def test_samples_refuses_an_empty_name_and_a_file_in_the_way(tmp_path):
    r = _run("samples", "")
    assert r.exit_code == 2 and "FOLDER is empty" in r.output
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "configs").write_text("a file")
    r = _run("samples", str(tmp_path / "d"))
    assert r.exit_code == 6 and "exists and is not a folder" in r.output
    assert sorted(os.listdir(tmp_path / "d")) == ["configs"]


def test_ply_output_says_what_the_input_held_that_it_cannot_keep(tmp_path):
    ply = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
           "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
           "property uchar red\nelement edge 1\nproperty int vertex1\nproperty int vertex2\n"
           "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 255\n0 1\n")
    (tmp_path / "m.ply").write_text(ply)
    (tmp_path / "h.yaml").write_text(yaml.safe_dump(
        {"groups": {"a": {"indices": [0], "fixed": True},
                    "b": {"indices": [1], "translate": [0.1, 0, 0]}}}))
    r = _run("deform", str(tmp_path / "m.ply"), str(tmp_path / "h.yaml"), "-o",
             str(tmp_path / "o.ply"))
    assert r.exit_code == 0
    assert "not written: face properties red; element 'edge' (1)" in r.output
