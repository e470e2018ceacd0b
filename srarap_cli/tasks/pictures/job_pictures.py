"""Small pictures of one batch job for its report: the shape, its difference to the golden
mesh on the surface, its energy curve. Drawn by the worker that solved the job."""
import io
from collections.abc import Sequence
from typing import Any

import numpy as np

from ...io.handles import Constraints
from ...io.mesh.mesh import Mesh
from ..info import up_axis
from .log_axis import decades_axis
from .preview import UP
from .render import face_colors, group_colors, render_png

#: each picture's size in pixels: a report of 100 jobs stays a few megabytes
THUMBNAIL = (240, 200)
#: the difference map's, with room for its colour bar's labels
DIFFERENCE = (360, 200)


def shape_picture(rest: Mesh, deformed: Mesh, constraints: Constraints | None) -> bytes:
    """The deformed mesh, handle groups coloured, its rest shape ghosted behind: PNG bytes."""
    turn = UP[up_axis(rest)].T
    F = deformed.triangles()[0]
    groups = list(constraints.groups.values()) if constraints is not None else None
    shape = (group_colors(deformed.vertices @ turn, F, groups) if groups else
             (deformed.vertices @ turn, F, face_colors(F)))
    panel = [(rest.vertices @ turn, F, face_colors(F), 0.25), (*shape, 1.0)]
    return render_png([panel], THUMBNAIL, "iso", axes=turn)


def difference_picture(rest: Mesh, deformed: Mesh, distances: np.ndarray, tol: float,
                       scale: float) -> bytes:
    """The deformed mesh coloured by each vertex's distance to the golden mesh, the colour
    bar ending at the larger of the tolerance and the largest distance (relative to
    ``scale``): PNG bytes. ``rest`` only chooses the up axis (its vertices may differ)."""
    turn = UP[up_axis(rest)].T
    F = deformed.triangles()[0]
    d = distances[:len(deformed.vertices)] / scale
    vmax = max(float(d.max(initial=0.0)), tol, 1e-300)
    colors = face_colors(F, scalar=d, vmax=vmax)
    return render_png([[(deformed.vertices @ turn, F, colors, 1.0)]], DIFFERENCE, "iso",
                      colorbar=("distance to golden", vmax))


def energy_picture(log: Sequence[dict[str, Any]]) -> bytes:
    """Total energy against iteration (a log axis where it spans decades): PNG bytes."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(THUMBNAIL[0] / 100, THUMBNAIL[1] / 100), dpi=100)
    energy = [r["total"] for r in log]
    ax.plot([r["iteration"] for r in log], energy)
    decades_axis(ax, "y", energy, "{:.4g}")
    ax.set_xlabel("iteration", fontsize=7)
    ax.set_ylabel("energy", fontsize=7)
    ax.tick_params(labelsize=6)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()
