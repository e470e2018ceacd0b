"""Named views show the side they name, for y-up and z-up meshes: a cube-like box whose front
face (the side facing +z for a y-up mesh, -y for a z-up one) is a coloured handle group."""
import io

import matplotlib.image as mpimg
import numpy as np
import pytest
from click.testing import CliRunner

from srarap_cli.cli import main
from srarap_cli.io.mesh import write_mesh
from srarap_cli.io.mesh.mesh import Mesh


def _box():
    """A subdivided unit cube (quads), enough vertices for a face to be its own group."""
    n = 6
    t = np.linspace(-1, 1, n)
    V, faces, index = [], [], {}
    for axis in range(3):
        for sign in (-1.0, 1.0):
            grid = {}
            for i, a in enumerate(t):
                for j, b in enumerate(t):
                    p = [0.0, 0.0, 0.0]
                    p[axis], p[(axis + 1) % 3], p[(axis + 2) % 3] = sign, a, b
                    key = tuple(np.round(p, 9))
                    if key not in index:
                        index[key] = len(V)
                        V.append(p)
                    grid[i, j] = index[key]
            for i in range(n - 1):
                for j in range(n - 1):
                    quad = [grid[i, j], grid[i + 1, j], grid[i + 1, j + 1], grid[i, j + 1]]
                    faces.append(quad if sign > 0 else quad[::-1])
    return Mesh.from_arrays(np.array(V), faces)


def _red_share(png):
    img = mpimg.imread(io.BytesIO(png))[80:, :, :3]  # below the legend
    red = (img[..., 0] > 0.5) & (img[..., 1] < 0.45) & (img[..., 2] < 0.45)
    return red.mean()


@pytest.mark.parametrize("up, front", [("y", [0, 0, 1]), ("z", [0, -1, 0])])
def test_front_shows_the_front_and_back_does_not(tmp_path, up, front):
    write_mesh(str(tmp_path / "box.obj"), _box())
    lo = np.where(np.array(front) != 0, np.array(front) * 0.99, -2)
    hi = np.where(np.array(front) != 0, np.array(front) * 1.01, 2)
    box = {"min": np.minimum(lo, hi).tolist(), "max": np.maximum(lo, hi).tolist()}
    (tmp_path / "h.yaml").write_text(f"groups:\n  front: {{box: {box}, fixed: true}}\n")
    shares = {}
    for view in ("front", "back"):
        out = tmp_path / f"{view}.png"
        r = CliRunner().invoke(main, ["render", str(tmp_path / "box.obj"), "--handles",
                                      str(tmp_path / "h.yaml"), "--up", up, "--view", view,
                                      "-o", str(out), "--size", "320x240"])
        assert r.exit_code == 0, r.output
        shares[view] = _red_share(out.read_bytes())
    assert shares["front"] > 0.2 and shares["back"] < 0.01, shares


@pytest.mark.parametrize("far", [1e5, 1e30, 1e150])
def test_the_display_mesh_of_a_mesh_with_a_far_stray_vertex(far):
    """Issue 71 (RENDER-1): one stray vertex 1e5 away on a large mesh made the display
    mesh's grid numbers overflow ("negative dimensions are not allowed")."""
    from helpers import tube

    from srarap_cli.tasks.pictures.render import display_mesh
    V, F = tube(rings=40, segments=30)
    V = np.vstack([V, [[far, 0.0, 0.0]], [[-far, far, 0.0]]])  # in no face
    W, G, colors, normals = display_mesh(V, F, np.ones((len(F), 3)), 200)
    assert 0 < len(G) <= len(F) and np.isfinite(W).all() and G.max() < len(W)
    assert colors.shape == (len(G), 3) and normals.shape == (len(G), 3)
    tied = np.vstack([F, [[0, 1, len(V) - 1]]])  # in a face: the face is the picture
    W, G, _, _ = display_mesh(V, tied, np.ones((len(tied), 3)), 200)
    assert np.isfinite(W).all() and (G.max(initial=0) < len(W))
