"""Previews, distortion maps and energy plots."""
import os
import warnings

import meshio
import numpy as np
import pytest
from click.testing import CliRunner
from helpers import ROOT, tube_mesh
from matplotlib.image import imread

from srarap_cli.cli import main
from srarap_cli.io.mesh import write_mesh
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix
from srarap_cli.tasks.distortion import vertex_distortion
from srarap_cli.tasks.pictures.render import PALETTE

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
BEND = os.path.join(ROOT, "configs", "bar-bend.yaml")


def invoke(*args):
    return CliRunner().invoke(main, [*map(str, args)])


def picture(path):
    """The rendered image with its decorations (legend top left, axes triad and extent line
    bottom left) painted white: what remains is the meshes."""
    img = imread(str(path)).copy()
    h, w = img.shape[:2]
    img[:20 * 3 + 10, :140, :3] = 1.0                          # legend, up to 3 groups
    img[int(0.80 * h):, :, :3][:, :max(int(0.12 * w), 140)] = 1.0  # triad and extent note
    img[h - 14:, :, :3] = 1.0
    for col in range(1, 4):  # a triad in the corner of each further view
        left = int(col * w / 2) if col < 2 else w
        img[int(0.80 * h):, left:left + int(0.12 * w), :3] = 1.0
    return img


def near(img, rgb, tol=0.12):
    return (np.abs(img[..., :3] - rgb).max(axis=-1) < tol)


def test_render_has_the_size_asked_and_colours_handles_where_they_project(tmp_path):
    out = tmp_path / "p.png"
    r = invoke("render", BAR, "--handles", BEND, "--view", "front", "--size", "300x600",
               "--up", "z", "-o", out)
    assert r.exit_code == 0, r.output
    img = picture(out)
    assert img.shape[:2] == (600, 300)
    assert img[..., :3].std() > 0.05  # not blank
    # front view, z up: the tip group (second, blue) at the top, the base (first, red) at the
    # bottom; neither colour in the middle of the bar
    rows = np.arange(600)
    blue, red = near(img, PALETTE[1], 0.35), near(img, PALETTE[0], 0.35)
    assert blue.any() and red.any()
    assert rows[blue.any(axis=1)].max() < 120 and rows[red.any(axis=1)].min() > 480
    assert not (blue | red)[250:350].any()


def test_distortion_is_zero_for_rigid_motion_and_measures_stretch():
    m = tube_mesh(rings=6, segments=8)
    V, F = m.vertices, m.triangles()[0]
    R = to_matrix(from_axis_angle([1, 2, 3], 130))
    assert vertex_distortion(V, V @ R.T + [4, 5, 6], F).max() < 1e-12
    stretched = vertex_distortion(V, 1.1 * V, F)
    assert np.allclose(stretched[stretched > 0], 0.1, atol=1e-9)


def test_distortion_render_needs_rest_and_draws_a_colour_bar(tmp_path):
    m = tube_mesh(rings=6, segments=8)
    write_mesh(str(tmp_path / "rest.obj"), m)
    write_mesh(str(tmp_path / "big.obj"), m.with_vertices(1.2 * m.vertices))
    assert invoke("render", tmp_path / "big.obj", "--color", "distortion", "-o",
                  tmp_path / "d.png").exit_code == 2
    r = invoke("render", tmp_path / "big.obj", "--rest", tmp_path / "rest.obj", "--color",
               "distortion", "--layout", "ghost", "-o", tmp_path / "d.png", "--size", "400x300")
    assert r.exit_code == 0, r.output
    assert imread(str(tmp_path / "d.png")).shape[:2] == (300, 400)


@pytest.mark.parametrize("args", [["--size", "10x10"], ["--view", "0,0,0"], ["--size", "big"]])
def test_bad_render_options_are_usage_errors(tmp_path, args):
    assert invoke("render", BAR, "-o", tmp_path / "p.png", *args).exit_code == 2


def test_deform_preview_distortion_ply_and_plot(tmp_path):
    ply, png, log = tmp_path / "o.ply", tmp_path / "prev.png", tmp_path / "log.csv"
    r = invoke("deform", BAR, BEND, "-o", ply, "--preview", png, "--write-distortion",
               "--log", log, "-q")
    assert r.exit_code == 0, r.output
    d = meshio.read(str(ply)).point_data["distortion"]
    assert np.isfinite(d).all() and d.max() > 0
    assert imread(str(png)).shape[:2] == (600, 800)
    r = invoke("plot", log, log, "-o", tmp_path / "e.png", "--size", "500x300")
    assert r.exit_code == 0 and imread(str(tmp_path / "e.png")).shape[:2] == (300, 500)
    assert invoke("plot", ply, "-o", tmp_path / "x.png").exit_code == 4


def test_several_views_are_drawn_side_by_side(tmp_path):
    out = tmp_path / "v.png"
    r = invoke("render", BAR, "--handles", BEND, "--view", "front", "--view", "top",
               "--size", "600x300", "-o", out, "--up", "y")
    assert r.exit_code == 0, r.output
    img = picture(out)
    left, right = img[:, :300, :3], img[:, 300:, :3]
    assert left.std() > 0.05 and right.std() > 0.05
    # y up: the bar's long axis z points at a front view, which sees the tip cap (blue) as
    # a disc; from the top only a band of it shows
    blue = near(img, PALETTE[1], 0.35)
    assert blue[:, :300].sum() > 3 * blue[:, 300:].sum()


@pytest.mark.parametrize("up, tall", [("y", True), ("z", False), ("-y", True), ("x", False)])
def test_the_up_axis_is_drawn_upward(tmp_path, up, tall):
    # a box 1 x 4 x 1: tall on screen exactly when its long axis (y) is the one drawn upward
    V = np.array([[x, y, z] for x in (0, 1) for y in (0, 4) for z in (0, 1)], dtype=float)
    F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    path = tmp_path / "box.obj"
    path.write_text("".join(f"v {a} {b} {c}\n" for a, b, c in V)
                    + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F))
    out = tmp_path / "p.png"
    assert invoke("render", path, "--view", "front", "--up", up, "--size", "400x400",
                  "-o", out).exit_code == 0
    img = picture(out)[..., :3]
    ink = np.flatnonzero((img < 0.95).any(axis=2).any(axis=1)), \
        np.flatnonzero((img < 0.95).any(axis=2).any(axis=0))
    height, width = np.ptp(ink[0]), np.ptp(ink[1])
    assert (height > 2 * width) == tall  # otherwise the long axis points at the camera


def test_the_default_up_axis_stands_the_sample_bar_on_its_base(tmp_path):
    # --up auto is info's guess: z for the bar (ten times as long as wide), so the front
    # view shows it upright, taller than wide, its tip (blue) above its base (red)
    out = tmp_path / "a.png"
    r = invoke("render", BAR, "--handles", BEND, "--view", "front", "-o", out)
    assert r.exit_code == 0, r.output
    img = picture(out)
    blue, red = near(img, PALETTE[1], 0.35), near(img, PALETTE[0], 0.35)
    tip, base = np.argwhere(blue).mean(axis=0), np.argwhere(red).mean(axis=0)  # (row, col)
    assert base[0] - tip[0] > 0.6 * img.shape[0]  # tip far above the base: upright
    assert abs(base[1] - tip[1]) < 0.05 * img.shape[1]  # one above the other


def test_plot_of_a_log_that_reaches_zero_energy_draws_it_without_warnings(tmp_path):
    """An exact solve (a rigid motion of the handles) ends at energy 0: a log axis would
    drop those points, and matplotlib warned on stderr."""
    log = tmp_path / "exact.csv"
    log.write_text("iteration,membrane,bending,total,rel_change,max_move,seconds,step,stop\n"
                   "0,1e-3,0,1e-3,,0,0.01,start,\n1,0,0,0,1,0.1,0.02,plain,converged\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = invoke("plot", log, "-o", tmp_path / "e.png")
    assert r.exit_code == 0 and r.stderr == "", r.stderr
    picture = imread(str(tmp_path / "e.png"))[..., :3]
    # the line across both panels (about 1,200 pixels; a log axis kept about 530 of them)
    assert (np.abs(picture - [0.12, 0.47, 0.71]).max(axis=-1) < 0.05).sum() > 900


def _dense_tube(rings=200, segments=100):
    m = tube_mesh(length=6.0, rings=rings, segments=segments)
    return m.vertices, m.triangles()[0]


def test_a_mesh_larger_than_its_pixels_is_drawn_reduced_with_its_colours():
    from srarap_cli.tasks.pictures.render import display_mesh

    V, F = _dense_tube()
    top = V[F].mean(axis=1)[:, 2] > 3.0
    colors = np.where(top[:, None], PALETTE[1], PALETTE[0])  # blue top half, red bottom
    W, G, c, normals = display_mesh(V, F, colors, 5_000)
    assert len(G) <= 2 * 5_000 < len(F) and G.max() < len(W)
    assert (W.min(axis=0) >= V.min(axis=0) - 1e-12).all()
    assert (W.max(axis=0) <= V.max(axis=0) + 1e-12).all()
    centre = W[G].mean(axis=1)[:, 2]
    # each face's colour is the mean of those it stands for: pure away from the seam
    assert np.allclose(c[centre > 3.5], PALETTE[1]) and np.allclose(c[centre < 2.5], PALETTE[0])
    # the summed normals of the faces each stands for point out of the tube, as its own
    radial = W[G].mean(axis=1)[:, :2]
    side = (centre > 0.5) & (centre < 5.5)
    assert (np.einsum("ij,ij->i", normals[side, :2], radial[side]) > 0).mean() > 0.99
    assert display_mesh(V, F, colors, len(F))[1] is F  # within the budget: untouched


def test_the_reduced_picture_looks_like_the_full_one(tmp_path, monkeypatch):
    """What the eye compares: the same silhouette and shading, pixel by pixel, with and
    without the reduction; and matplotlib gets no more faces than the pixels can show."""
    from srarap_cli.tasks.pictures import render

    V, F = _dense_tube(rings=240, segments=120)
    V, F, colors = render.group_colors(V, F, [np.flatnonzero(V[:, 2] < 0.5)])
    drawn = []
    real = render.draw
    monkeypatch.setattr(render, "draw", lambda ax, V, F, *a: drawn.append(len(F)) or
                        real(ax, V, F, *a))
    size = (240, 240)
    reduced = render.render_png([[(V, F, colors, 1.0)]], size, "iso")
    assert drawn and max(drawn) <= 2 * render.FACES_PER_PIXEL * size[0] * size[1] < len(F)
    monkeypatch.setattr(render, "FACES_PER_PIXEL", 10.0)
    full = render.render_png([[(V, F, colors, 1.0)]], size, "iso")
    assert drawn[-1] == len(F)
    (tmp_path / "reduced.png").write_bytes(reduced)
    (tmp_path / "full.png").write_bytes(full)
    a, b = imread(str(tmp_path / "reduced.png"))[..., :3], imread(str(tmp_path / "full.png"))[..., :3]
    shape_a, shape_b = a.min(axis=-1) < 0.99, b.min(axis=-1) < 0.99
    assert (shape_a != shape_b).mean() < 0.01  # the silhouettes agree but for a few pixels
    assert np.abs(a - b)[shape_a & shape_b].mean() < 0.03  # and the shading inside them


def test_render_is_quiet_with_q_and_says_where_a_gif_comes_from(tmp_path):
    """Issue 70: render had no -q, and -o x.gif for one mesh said only '.png'."""
    lying = tmp_path / "lying.obj"  # a y-up guess in doubt says its note
    write_mesh(str(lying), tube_mesh())
    loud = CliRunner().invoke(main, ["render", str(lying), "-o", str(tmp_path / "a.png")])
    quiet = CliRunner().invoke(main, ["render", str(lying), "-o", str(tmp_path / "b.png"), "-q"])
    assert loud.exit_code == quiet.exit_code == 0 and quiet.stderr == ""
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
    r = CliRunner().invoke(main, ["render", BAR, "-o", str(tmp_path / "x.gif")])
    assert r.exit_code == 2 and "frame pattern" in r.stderr and ".png" in r.stderr


def _painted_area(V, F, colors, rgb):
    W = V
    area = 0.5 * np.linalg.norm(np.cross(W[F[:, 1]] - W[F[:, 0]], W[F[:, 2]] - W[F[:, 0]]),
                                axis=1)
    return area[(colors == rgb).all(axis=1)].sum() / area.sum()


@pytest.mark.parametrize("selected, painted", [([0], 0.25), ([0, 1], 0.75), ([0, 1, 2], 1.0),
                                               ([], 0.0)])
def test_a_group_is_painted_where_its_interpolated_membership_reaches_one_half(selected,
                                                                              painted):
    """Issue 70: a face with any selected corner was painted whole, so a long CAD triangle
    with one selected corner showed a selection far larger than it is. The region where the
    linear interpolation of a group's membership is at least 1/2 covers a quarter of a
    triangle with one member corner and three quarters with two."""
    from srarap_cli.tasks.pictures.render import BASE, group_colors
    V = np.array([[0.0, 0, 0], [40, 1, 0], [3, 9, 0]])  # any shape: areas scale alike
    W, G, c = group_colors(V, np.array([[0, 1, 2]]), [np.array(selected, dtype=int)])
    assert np.isclose(_painted_area(W, G, c, PALETTE[0]), painted)
    assert np.isclose(_painted_area(W, G, c, BASE), 1 - painted)
    n = np.cross(W[G[:, 1]] - W[G[:, 0]], W[G[:, 2]] - W[G[:, 0]])
    assert (n[:, 2] > 0).all()  # the pieces keep the face's orientation (its shading)


def test_three_groups_meeting_in_a_face_paint_its_corners_and_leave_its_middle_grey():
    from srarap_cli.tasks.pictures.render import BASE, group_colors
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    F = np.array([[0, 1, 2], [1, 3, 2]])
    groups = [np.array([0]), np.array([1, 3]), np.array([2, 3])]  # 3 in two: the last wins
    W, G, c = group_colors(V, F, groups)
    # face 0: corners 0, 1, 2 in groups 0, 1, 2, middle grey; face 1: corners 1 (group 1),
    # 3 and 2 (group 2): corner 1 and the middle (two corners in group 2) coloured
    assert np.isclose(_painted_area(W, G, c, PALETTE[0]), 0.125)
    assert np.isclose(_painted_area(W, G, c, PALETTE[1]), 0.25)
    assert np.isclose(_painted_area(W, G, c, PALETTE[2]), 0.125 + 0.375)
    assert np.isclose(_painted_area(W, G, c, BASE), 0.125)


def test_a_selected_corner_of_long_triangles_is_drawn_as_small_as_it_is(tmp_path):
    """The picture, seen from above: a 10 x 10 square of two triangles, one corner selected,
    coloured over a quarter of the square (before: half of it, a whole triangle)."""
    square = tmp_path / "square.obj"
    square.write_text("v 0 0 0\nv 10 0 0\nv 10 10 0\nv 0 10 0\nf 1 2 3\nf 1 3 4\n")
    handles = tmp_path / "corner.yaml"
    handles.write_text("groups:\n  corner: {indices: [0], fixed: true}\n"
                       "  far: {indices: [2], translate: [0, 0, 0.001]}\n")
    out = tmp_path / "p.png"
    r = invoke("render", square, "--handles", handles, "--view", "top", "--up", "z",
               "--size", "400x400", "-o", out)
    assert r.exit_code == 0, r.output
    img = picture(out)
    shape = img[..., :3].min(axis=-1) < 0.99
    red, blue = near(img, PALETTE[0], 0.3) & shape, near(img, PALETTE[1], 0.3) & shape
    assert 0.2 < red.sum() / shape.sum() < 0.3 and 0.2 < blue.sum() / shape.sum() < 0.3


@pytest.mark.parametrize("corners", ["1e8 1e8 1e8|1e8 1e8 1e8|1e8 1e8 1e8",
                                     "1e16 0 0|1e16 1e-3 0|1e16 0 1e-3", "5 5 5|5 5 5|5 5 5"])
def test_a_point_or_a_mesh_flat_in_the_view_far_out_draws_without_a_librarys_words(tmp_path,
                                                                                     corners):
    """Issue 71 (MSG-6): the frame's margin vanished beside coordinates of 1e8, and
    matplotlib's identical-limits warning reached stderr with its source line."""
    mesh = tmp_path / "m.obj"
    mesh.write_text("".join(f"v {c}\n" for c in corners.split("|")) + "f 1 2 3\n")
    for view in ("front", "iso"):
        r = CliRunner().invoke(main, ["--debug", "render", str(mesh), "-o",
                                      str(tmp_path / "p.png"), "--up", "z", "--view", view])
        assert r.exit_code == 0 and r.stderr == "", r.stderr


def test_no_librarys_warning_reaches_stderr(tmp_path, monkeypatch):
    """What matters is said by srarap; a library's warning (its text and its source line)
    is shown with --debug only."""
    from srarap_cli.tasks.pictures import render

    real = render.render_png

    def warning(*args, **kwargs):
        warnings.warn("a library's own words", UserWarning, stacklevel=2)
        return real(*args, **kwargs)
    monkeypatch.setattr(render, "render_png", warning)
    monkeypatch.setattr("srarap_cli.tasks.pictures.preview.render_png", warning)
    args = ["render", BAR, "-o", str(tmp_path / "p.png"), "--up", "z"]
    quiet = CliRunner().invoke(main, args)
    assert quiet.exit_code == 0 and quiet.stderr == "", quiet.stderr
    with pytest.warns(UserWarning, match="a library's own words"):  # not swallowed there
        loud = CliRunner().invoke(main, ["--debug", *args])
    assert loud.exit_code == 0


def test_the_rest_shape_may_come_from_standard_input(tmp_path):
    """Issue 71 (MSG-5): ``--rest -`` said "No such file or directory"."""
    shown = tmp_path / "bent.obj"
    write_mesh(str(shown), tube_mesh())
    rest = tube_mesh()
    rest_file = tmp_path / "rest.obj"
    write_mesh(str(rest_file), rest.with_vertices(rest.vertices * [1, 1, 1.1]))
    by_file, by_stdin = tmp_path / "a.png", tmp_path / "b.png"
    assert invoke("render", shown, "--rest", rest_file, "-o", by_file, "--up", "z"
                  ).exit_code == 0
    r = CliRunner().invoke(main, ["render", str(shown), "--rest", "-", "-o", str(by_stdin),
                                  "--up", "z"], input=rest_file.read_bytes())
    assert r.exit_code == 0, r.stderr
    assert by_stdin.read_bytes() == by_file.read_bytes()
    both = CliRunner().invoke(main, ["render", "-", "--rest", "-", "-o", str(by_stdin)],
                              input=rest_file.read_bytes())
    assert both.exit_code == 2 and "both be standard input" in both.stderr


def test_a_reduced_face_takes_the_mean_colour_of_the_faces_it_stands_for():
    """Issue 72: a mutation that gave each clustered face one of its faces' colours passed
    the quick loop (the tests' colours were uniform away from a seam). Every face twice, a
    red copy and a blue one: each reduced face stands for both, and is their mix."""
    from srarap_cli.tasks.pictures.render import display_mesh

    V, F = _dense_tube()
    twice = np.vstack([F, F])
    colors = np.repeat(PALETTE[:2], len(F), axis=0)
    W, G, c, normals = display_mesh(V, twice, colors, 2_000)
    assert len(G) < len(F) / 4
    assert np.allclose(c, (PALETTE[0] + PALETTE[1]) / 2)
