"""``render`` of an animation's frame pattern: an animated GIF or a contact sheet, every
frame framed alike (what holds still in the animation holds still in the picture)."""
import os

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import ROOT
from PIL import Image

from srarap_cli.cli import main
from srarap_cli.tasks.pictures.frames import sheet_choice
from srarap_cli.tasks.pictures.render import PALETTE

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
TWIST = os.path.join(ROOT, "configs", "bar-twist-animated.yaml")


@pytest.fixture(scope="module")
def frames(tmp_path_factory):
    folder = tmp_path_factory.mktemp("frames")
    pattern = str(folder / "f_{:02d}.obj")
    r = CliRunner().invoke(main, ["animate", BAR, TWIST, "-o", pattern, "--frames", "5",
                                  "-q"])
    assert r.exit_code == 0, r.stderr
    return pattern


def render(*args):
    return CliRunner().invoke(main, ["render", *map(str, args)])


def red_pixels(img):
    rgb = np.asarray(img.convert("RGB"), dtype=float) / 255
    return np.abs(rgb - np.array(PALETTE[0][:3])).max(axis=2) < 0.3


@pytest.mark.slow
def test_a_gif_holds_every_frame_framed_alike_and_is_reproducible(frames, tmp_path):
    a, b = tmp_path / "a.gif", tmp_path / "b.gif"
    assert render(frames, "--handles", TWIST, "-o", a, "--size", "200x300").exit_code == 0
    assert render(frames, "--handles", TWIST, "-o", b, "--size", "200x300").exit_code == 0
    assert a.read_bytes() == b.read_bytes()
    gif = Image.open(a)
    assert gif.n_frames == 5 and gif.size == (200, 300)
    # the fixed base (red) stays on the same pixels from the first frame to the last
    gif.seek(0)
    first = red_pixels(gif)
    gif.seek(4)
    last = red_pixels(gif)
    assert first.sum() > 50 and (first & last).sum() > 0.8 * first.sum()


def test_a_contact_sheet_is_a_grid_of_the_frames(frames, tmp_path):
    out = tmp_path / "s.png"
    r = render(frames, "-o", out, "--size", "100x120")
    assert r.exit_code == 0, r.stderr
    assert Image.open(out).size == (3 * 100, 2 * 120)  # 5 frames: 3 columns, 2 rows


def test_sheet_choice_keeps_first_and_last_and_spreads_the_rest():
    assert sheet_choice(5) == [0, 1, 2, 3, 4]
    chosen = sheet_choice(1000, 24)
    assert len(chosen) == 24 and chosen[0] == 0 and chosen[-1] == 999
    assert np.ptp(np.diff(chosen)) <= 1


def test_a_pattern_without_frame_0_or_with_options_it_cannot_take_is_one_line(frames, tmp_path):
    r = render(str(tmp_path / "none_{:02d}.obj"), "-o", tmp_path / "x.gif")
    assert r.exit_code == 4 and "no frame 0" in r.stderr
    r = render(frames, "--rest", BAR, "-o", tmp_path / "x.gif")
    assert r.exit_code == 2 and "frame pattern" in r.stderr
    r = render(frames, "-o", tmp_path / "x.jpg")
    assert r.exit_code == 2


def test_render_takes_every_frame_animate_may_write(tmp_path):
    """``animate`` writes up to 100,000 frames and ``render`` refused more than 10,000 (two
    limits for one concept, issue 62): a sheet of 10,001 frames is drawn (24 of them read),
    and only a GIF, which holds every frame, says how many it takes."""
    tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
    for k in range(10_001):
        (tmp_path / f"f_{k:05d}.obj").write_text(tri)
    pattern = str(tmp_path / "f_{:05d}.obj")
    r = CliRunner().invoke(main, ["render", pattern, "-o", str(tmp_path / "sheet.png")])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(main, ["render", pattern, "-o", str(tmp_path / "a.gif")])
    assert r.exit_code == 4 and "10001 frames, more than a GIF takes (10000)" in r.output


def test_a_sheet_drawn_by_several_processes_is_the_one_drawn_by_one(frames, tmp_path,
                                                                     monkeypatch):
    """The frames are read and drawn in as many processes as there are CPUs (a parse and a
    figure hold the GIL): the same bytes with one process or three."""
    from srarap_cli.tasks.pictures import jobs
    sheets = []
    for cpus in (1, 3):
        monkeypatch.setattr(jobs, "available_cpus", lambda cpus=cpus: cpus)
        out = tmp_path / f"s{cpus}.png"
        r = render(frames, "--handles", TWIST, "-o", out, "--size", "100x120")
        assert r.exit_code == 0, r.stderr
        sheets.append(out.read_bytes())
    assert sheets[0] == sheets[1]


def test_a_frame_that_cannot_be_read_in_a_drawing_process_is_one_line(frames, tmp_path,
                                                                       monkeypatch):
    from srarap_cli.tasks.pictures import jobs
    monkeypatch.setattr(jobs, "available_cpus", lambda: 3)
    broken = tmp_path / "f_{:02d}.obj"
    for k in range(5):
        text = open(frames.format(k)).read()
        (tmp_path / f"f_{k:02d}.obj").write_text("v 1 2\n" if k == 1 else text)
    r = render(broken, "-o", tmp_path / "s.png")
    assert r.exit_code == 4 and len(r.stderr.splitlines()) == 1, r.stderr
    assert "f_01.obj" in r.stderr and not (tmp_path / "s.png").exists()


def test_frames_read_by_their_positions_are_the_meshes_read_whole(frames, tmp_path):
    """read_frames parses a later OBJ frame's positions alone when its face lines are the
    first's; what it gives is what read_mesh gives (normals aside), and a frame with other
    faces, or a bad position, is read and checked whole."""
    from srarap_cli.io.mesh import read_frames, read_mesh
    paths = [frames.format(k) for k in range(5)]
    for parts in (1, 2):
        for fast, whole in zip(read_frames(paths, parts), map(read_mesh, paths)):
            assert np.array_equal(fast.vertices, whole.vertices)
            assert np.array_equal(fast.face_vertices, whole.face_vertices)
            assert np.array_equal(fast.face_sizes, whole.face_sizes)
    other = tmp_path / "f_01.obj"  # the same positions, one face turned the other way
    text = open(paths[1]).read()
    first_face = next(line for line in text.splitlines() if line.startswith("f "))
    corners = first_face.split()[1:]
    other.write_text(text.replace(first_face, "f " + " ".join(reversed(corners)), 1))
    got = read_frames([paths[0], str(other)])[1]
    assert np.array_equal(got.face_vertices, read_mesh(str(other)).face_vertices)
    bad = tmp_path / "f_02.obj"
    lines = text.splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("v "))
    lines[k] = "v nan 0 0"
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(Exception, match="f_02.obj: vertex 0 has a NaN"):
        read_frames([paths[0], str(bad)], 2)
