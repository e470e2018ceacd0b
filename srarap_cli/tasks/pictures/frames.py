"""An animation's frames as one picture: an animated GIF, or a contact sheet of thumbnails."""
import io
import math
import os
from collections.abc import Sequence

import numpy as np

from ...io.handles import Constraints
from ...io.mesh.mesh import Mesh
from ...runtime.bounded import map_forked
from .preview import frame_canvas, preview_parts
from .render import Canvas

#: a contact sheet shows at most this many frames (evenly spread, first and last included)
SHEET_FRAMES = 24
#: seconds a frame's picture may take in a drawing process (about 0.15 s for 12k faces)
DRAW_SECONDS = 60.0


def frame_pictures(meshes: Sequence[Mesh], numbers: Sequence[int],
                   constraints: Constraints | None = None, view: str = "iso",
                   size: tuple[int, int] = (480, 360), up: str = "y",
                   parts: int = 1) -> list[bytes]:
    """One PNG per mesh of an animation, all framed alike (around every frame's extent) so
    the mesh moves and the camera does not; each captioned with its frame number.

    Parameters
    ----------
    meshes : list of Mesh, the frames (same vertices and faces)
    numbers : list of int, their frame numbers
    constraints : Constraints, optional, handle groups to colour (selected on frame 0)
    parts : int, processes drawing them side by side (:func:`~srarap_cli.runtime.bounded.
        map_forked`: a figure holds the GIL), the same pictures at any count
    """
    corners = np.array([[m.vertices.min(axis=0), m.vertices.max(axis=0)] for m in meshes])
    lo, hi = corners[:, 0].min(axis=0), corners[:, 1].max(axis=0)
    box = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                    for z in (lo[2], hi[2])])
    canvases: dict[int, Canvas] = {}  # one a process (a part is forked before it draws)

    def picture(k):
        panels, note, setup = preview_parts(meshes[k], None, constraints, up=up,
                                            caption=f"frame {numbers[k]}")
        canvas = canvases.get(os.getpid())
        if canvas is None:
            canvas = canvases[os.getpid()] = frame_canvas(setup, size, view, box)
        return canvas.png(panels, note)
    try:
        return map_forked(picture, list(range(len(meshes))), parts,
                          DRAW_SECONDS * len(meshes))
    finally:
        for canvas in canvases.values():
            canvas.close()


def animated_gif(pictures: Sequence[bytes], fps: float = 12.0) -> bytes:
    """The pictures (PNG bytes) as a looping GIF at ``fps`` frames per second."""
    from PIL import Image

    frames = [Image.open(io.BytesIO(p)).convert("RGB") for p in pictures]
    out = io.BytesIO()
    frames[0].save(out, format="GIF", save_all=True, append_images=frames[1:], loop=0,
                   duration=max(int(round(1000 / fps)), 20), optimize=False)
    return out.getvalue()


def sheet_choice(count: int, most: int = SHEET_FRAMES) -> list[int]:
    """Which of ``count`` frames a contact sheet shows: all, or ``most`` evenly spread."""
    if count <= most:
        return list(range(count))
    return sorted({int(round(i * (count - 1) / (most - 1))) for i in range(most)})


def contact_sheet(pictures: Sequence[bytes]) -> bytes:
    """The pictures (PNG bytes, one size) in a grid, row by row: one PNG."""
    from PIL import Image

    tiles = [Image.open(io.BytesIO(p)).convert("RGB") for p in pictures]
    columns = math.ceil(math.sqrt(len(tiles)))
    rows = math.ceil(len(tiles) / columns)
    w, h = tiles[0].size
    sheet = Image.new("RGB", (columns * w, rows * h), "white")
    for k, tile in enumerate(tiles):
        sheet.paste(tile, ((k % columns) * w, (k // columns) * h))
    out = io.BytesIO()
    sheet.save(out, format="PNG")
    return out.getvalue()
