"""A picture of a deformed mesh: rest and deformed shape, handles coloured or strain mapped."""
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from ...io.handles import Constraints
from ...io.mesh.mesh import Mesh
from ..distortion import vertex_distortion
from .render import Canvas, face_colors, group_colors, render_png

#: Proper rotations taking each axis name to +z, the renderer's up.
UP = {"z": np.eye(3), "-z": np.diag([1.0, -1, -1]),
      "y": np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]),
      "-y": np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]]),
      "x": np.array([[0.0, 0, -1], [0, 1, 0], [1, 0, 0]]),
      "-x": np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]])}


#: the distortion colour bar ends here, so that a few outliers do not wash out the rest
CLIP_PERCENTILE = 99


def preview_png(mesh: Mesh, rest: Mesh | None = None, constraints: Constraints | None = None,
                color: str = "shade", layout: str = "ghost", view: str | Sequence[str] = "iso",
                size: tuple[int, int] = (800, 600), up: str = "y",
                framed: np.ndarray | None = None, caption: str | None = None) -> bytes:
    """PNG bytes of ``mesh`` (and its ``rest`` shape), handles coloured or distortion mapped;
    ``up`` names the mesh's axis drawn upward (OBJ's convention, y, by default); ``framed``
    (p, 3): points the picture's frame holds too (model coordinates); ``caption``: a text
    before the extent at the bottom."""
    picture = preview_parts(mesh, rest, constraints, color, layout, up, caption)
    panels, note, setup = picture
    return render_png(panels, size, view, setup["colorbar"], legend=setup["legend"],
                      axes=setup["axes"], note=note, titles=setup["titles"],
                      framed=None if framed is None else framed @ setup["axes"])


def frame_canvas(setup: dict, size: tuple[int, int], view: str,
                 framed: np.ndarray | None) -> Canvas:
    """The :class:`~.render.Canvas` that draws the frames of one animation (their
    :func:`preview_parts` alike but for the meshes and the note), for :meth:`Canvas.png`."""
    return Canvas(1, size, view, setup["colorbar"], setup["legend"], setup["axes"],
                  setup["titles"], None if framed is None else framed @ setup["axes"])


def preview_parts(mesh: Mesh, rest: Mesh | None = None,
                  constraints: Constraints | None = None, color: str = "shade",
                  layout: str = "ghost", up: str = "y", caption: str | None = None
                  ) -> tuple[list, str, dict[str, Any]]:
    """What :func:`preview_png` draws: its panels, its note, and what the figure is made of
    (``colorbar``, ``legend``, ``axes``: the turn to the renderer's frame, ``titles``)."""
    turn = UP[up].T
    mesh = _turned(mesh, turn)
    rest = None if rest is None else _turned(rest, turn)
    F = mesh.triangles()[0]
    groups = list(constraints.groups.values()) if constraints is not None else None
    colorbar = None
    painted = _painter(F, groups)
    if color == "distortion":
        if rest is None:
            raise ValueError("a distortion map needs the rest shape")
        d = vertex_distortion(rest.vertices, mesh.vertices, F)
        vmax = max(float(np.percentile(d, CLIP_PERCENTILE)), 1e-12)
        current = [(mesh.vertices, F, face_colors(F, scalar=d, vmax=vmax), 1.0)]
        clipped = f", clipped at the {CLIP_PERCENTILE}th percentile (max {d.max():.3g})" \
            if d.max() > vmax else ""
        colorbar = (f"distortion (relative strain){clipped}", vmax)
    else:
        current = [painted(mesh.vertices)]
    if rest is None:
        panels = [current]
    else:
        rest_item = painted(rest.vertices)
        panels = [[rest_item], current] if layout == "side" else \
            [[(rest.vertices, F, face_colors(F), 0.25)] + current]
    lo, hi = mesh.vertices.min(axis=0) @ turn.T, mesh.vertices.max(axis=0) @ turn.T
    extent = np.abs(hi - lo)
    note = "extent " + ", ".join(f"{a} {e:.4g}" for a, e in zip("xyz", extent))
    if caption:
        note = f"{caption}; {note}"
    legend = list(constraints.groups) if constraints is not None and color != "distortion" \
        else None
    titles = ["rest", "deformed"] if len(panels) == 2 else None
    return panels, note, {"colorbar": colorbar, "legend": legend, "axes": turn,
                          "titles": titles}


def _painter(F, groups):
    """(V) -> (V, F, colors, 1.0): the mesh of ``F`` at positions V, groups painted."""
    if not groups:
        return lambda V: (V, F, face_colors(F), 1.0)
    return lambda V: (*group_colors(V, F, groups), 1.0)


def _turned(mesh, turn):
    """``mesh`` with its vertices turned, its normals left out: a picture shades by faces
    (recomputing the normals was a tenth of an animation sheet's time)."""
    return replace(mesh, vertices=mesh.vertices @ turn, normals=None, face_normals=None)
