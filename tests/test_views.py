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
