"""Headless previews: shaded meshes under an orthographic camera, drawn with matplotlib.

Triangles are projected, sorted back to front and drawn as one flat 2D polygon collection with
Lambert shading, which stays fast on large meshes (no 3D axes).
"""
import io
from collections.abc import Sequence
from typing import Any

import numpy as np

# Viewing directions (camera to scene) in the renderer's z-up frame, where a y-up mesh's front
# (+z, OBJ's convention) lands on -y as a z-up mesh's front does (Blender's): "front" looks
# along +y at that side. (It looked along -y before and showed the back of y-up meshes.)
VIEWS = {"front": ([0, 1, 0], [0, 0, 1]), "back": ([0, -1, 0], [0, 0, 1]),
         "left": ([1, 0, 0], [0, 0, 1]), "right": ([-1, 0, 0], [0, 0, 1]),
         "top": ([0, 0, -1], [0, 1, 0]), "iso": ([-1, 1, -0.8], [0, 0, 1])}
BASE = np.array([0.78, 0.78, 0.80])
PALETTE = np.array([[0.90, 0.30, 0.25], [0.20, 0.50, 0.90], [0.25, 0.75, 0.35],
                    [0.95, 0.65, 0.15], [0.60, 0.35, 0.80], [0.10, 0.75, 0.75]])


def camera(view: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit viewing direction and the image's up/right axes for a view name or 'x,y,z'."""
    if view in VIEWS:
        d, up = (np.asarray(v, float) for v in VIEWS[view])
    else:
        d = np.array([float(x) for x in view.split(",")])
        d = d / np.abs(d).max()  # 1e308-sized directions would overflow the norm
        up = np.array([0.0, 0, 1]) if abs(d[2]) < 0.9 * np.linalg.norm(d) else np.array([0.0, 1, 0])
    d = d / np.linalg.norm(d)
    right = np.cross(d, up)
    right /= np.linalg.norm(right)
    return d, np.cross(right, d), right


def face_shading(V: np.ndarray, F: np.ndarray, d: np.ndarray,
                 normals: np.ndarray | None = None) -> np.ndarray:
    """Two-sided Lambert intensity per face, light from the viewer's upper left; ``normals``
    (f, 3), any length, replace the faces' own (a display mesh's: those of the faces each
    stands for)."""
    n = (np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]) if normals is None
         else np.array(normals, dtype=float))
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    light = -d + 0.3 * np.cross(d, [0.0, 0, 1]) if abs(d[2]) < 0.99 else -d
    light /= np.linalg.norm(light)
    return 0.35 + 0.65 * np.abs(n @ light)


def draw(ax: Any, V: np.ndarray, F: np.ndarray, colors: np.ndarray, view: str,
         alpha: float = 1.0, normals: np.ndarray | None = None
         ) -> tuple[float, float, float, float]:
    """Draw one mesh on matplotlib axes ``ax``; returns its 2D bounding box (x0, x1, y0, y1).

    A display mesh (``normals`` given, see :func:`display_mesh`) shaded by the normals of
    the faces it stands for and, when translucent, drawn opaque in its colour blended with
    the white page: its clustered faces overlap along the cells' seams, and translucent
    overlaps drew the grid of the cells."""
    d, up, right = camera(view)
    xy = np.column_stack([V @ right, V @ up])
    depth = (V @ d)[F].mean(axis=1)
    order = np.argsort(-depth, kind="stable")  # farthest first
    shade = face_shading(V, F, d, normals)[:, None]
    rgb = np.clip(colors * shade, 0, 1)
    if normals is not None and alpha < 1.0:
        rgb, alpha = alpha * rgb + (1.0 - alpha), 1.0
    rgba = np.column_stack([rgb, np.full(len(F), alpha)])
    ax.add_artist(_flat_triangles(ax, xy[F[order]], rgba[order]))
    return xy[:, 0].min(), xy[:, 0].max(), xy[:, 1].min(), xy[:, 1].max()


def _flat_triangles(ax: Any, corners: np.ndarray, rgba: np.ndarray) -> Any:
    """An artist drawing triangles ``corners`` (t, 3, 2), in ``ax``'s data coordinates (as
    they are when the figure is drawn, after its limits are set), each in its
    colour ``rgba`` (t, 4), in that order, by one call of the renderer's Gouraud triangles
    with the same colour at the three corners: flat triangles without a matplotlib path per
    face (a PolyCollection's were most of an animation sheet's cost: 25 frames of a 12k-face
    mesh, 11.8 s, 5.3 s of it in the collection; its edges antialiased as well)."""
    from matplotlib.artist import Artist

    colors = np.repeat(rgba[:, None, :], 3, axis=1)

    class FlatTriangles(Artist):
        def draw(self, renderer):
            gc = renderer.new_gc()
            renderer.draw_gouraud_triangles(gc, corners, colors, ax.transData.frozen())
            gc.restore()

    return FlatTriangles()


#: faces a mesh is drawn with at most, per pixel of its panel: more than that cannot show
#: (a triangle of two by two pixels is flat-shaded like the pixels it covers), and
#: matplotlib's time grows with every polygon (738k-vertex Spot, 1.5M faces: 153 s for two
#: views with its rest shape)
FACES_PER_PIXEL = 0.25


def display_mesh(V: np.ndarray, F: np.ndarray, colors: np.ndarray, budget: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """A mesh of about ``budget`` faces or fewer that looks like ``(V, F)`` at the size of a
    picture: vertices clustered on a grid whose cells hold about two faces' worth of the
    surface, each cluster at its vertices' mean, faces between three clusters kept once,
    each with the mean colour and the summed normal of the faces it stands for (its shading:
    a clustered face can fold against its neighbours). ``(V, F, colors, None)`` when ``F``
    has no more than ``budget`` faces.

    Parameters
    ----------
    V : (n, 3) float array; F : (f, 3) int array; colors : (f, 3) float array, per face
    budget : int, the most faces worth drawing

    Returns
    -------
    V : (m, 3) float array; F : (g, 3) int array; colors : (g, 3) float array;
    normals : (g, 3) float array (area-weighted), or None for the mesh itself

    Examples
    --------
    >>> import igl
    >>> from srarap_cli.solver.multires.simplify import _octahedron
    >>> V, F = igl.loop(*igl.loop(*igl.loop(*_octahedron())))
    >>> W, G, c, normals = display_mesh(V, F, np.ones((len(F), 3)), 100)
    >>> len(F), 0 < len(G) <= 2 * 100, c.shape[1], normals.shape == G.shape
    (512, True, 3, True)
    """
    if len(F) <= budget:
        return V, F, colors, None
    a, b, c = (np.take(V, F[:, k], axis=0) for k in range(3))
    normals = np.cross(b - a, c - a)
    area = 0.5 * float(np.linalg.norm(normals, axis=1).sum())
    used = np.zeros(len(V), dtype=bool)
    used[F.ravel()] = True
    drawn = V[used]  # a vertex in no face (a stray one far away) is not drawn
    lo = drawn.min(axis=0)
    cell = max(np.sqrt(2.0 * area / max(budget, 1)),
               1e-12 * float(np.ptp(drawn, axis=0).max()), 1e-300)
    # a stray vertex far away (or coordinates near a float's range) makes a grid whose cell
    # numbers pass 64 bits: clamped, and the cells told apart by rows, not one number
    steps = np.nan_to_num((V - lo) / cell, nan=0.0, posinf=2.0 ** 53)
    cells = np.floor(np.clip(steps, 0, 2.0 ** 53)).astype(np.int64)
    span = [int(x) + 1 for x in cells.max(axis=0)]
    grid = span[0] * span[1] * span[2]  # Python's integers: no overflow
    if grid <= 8 * len(V):  # the cells' numbers by a pass over the grid, not a sort
        key = (cells[:, 0] * span[1] + cells[:, 1]) * span[2] + cells[:, 2]
        used = np.zeros(grid, dtype=bool)
        used[key] = True
        label = (np.cumsum(used) - 1)[key]
    elif grid < 2 ** 63:
        key = (cells[:, 0] * span[1] + cells[:, 1]) * span[2] + cells[:, 2]
        label = np.unique(key, return_inverse=True)[1].ravel()
    else:
        label = np.unique(cells, axis=0, return_inverse=True)[1].ravel()
    m = int(label.max()) + 1
    counts = np.bincount(label, minlength=m)
    W = np.column_stack([np.bincount(label, weights=V[:, k], minlength=m)
                         for k in range(3)]) / counts[:, None]
    G = label[F]
    whole = (G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 0] != G[:, 2])
    G, colors, normals = G[whole], np.asarray(colors, dtype=float)[whole], normals[whole]
    ordered = np.sort(G, axis=1)
    if m < 1 << 21:  # one int64 key per face: several times faster than unique rows
        ordered = (ordered[:, 0] * m + ordered[:, 1]) * m + ordered[:, 2]
    _, first, which = np.unique(ordered, axis=0, return_index=True, return_inverse=True)
    which = which.ravel()
    size = np.bincount(which)
    mean = np.column_stack([np.bincount(which, weights=colors[:, k]) / size
                            for k in range(colors.shape[1])])
    # a face's normal turned to agree with its representative's winding, then summed
    G, sign = G[first], np.sign(np.einsum("ij,ij->i", normals, normals[first][which]))
    summed = np.column_stack([np.bincount(which, weights=sign * normals[:, k])
                              for k in range(3)])
    return W, G, mean, summed


def _frame(axes, boxes):
    """The same limits on every axes of a view, around all its meshes, with a margin."""
    x0, x1 = min(b[0] for b in boxes), max(b[1] for b in boxes)
    y0, y1 = min(b[2] for b in boxes), max(b[3] for b in boxes)
    # a mesh flat in the view, or one point, far from the origin: a margin that still
    # separates the limits in floating point (1e-12 beside 1e8 vanished)
    pad = max(0.05 * max(x1 - x0, y1 - y0), 1e-9 * max(abs(x0), abs(x1), abs(y0), abs(y1)),
              1e-12)
    for ax in axes:
        ax.set_xlim(x0 - pad, x1 + pad)
        ax.set_ylim(y0 - pad, y1 + pad)
        ax.set_aspect("equal", adjustable="box")


def _triad(fig, left, view, model_axes):
    """Arrows for the model's x, y, z as the view sees them, in a corner of the view."""
    _, up, right = camera(view)
    ax = fig.add_axes([left + 0.01, 0.04, 0.09, 0.12])
    ax.set_axis_off()
    ax.set_xlim(-1.3, 1.3)
    ax.set_ylim(-1.3, 1.3)
    ax.set_aspect("equal")
    for k, (label, color) in enumerate(zip("xyz", ("#d62728", "#2ca02c", "#1f77b4"))):
        x, y = model_axes[k] @ right, model_axes[k] @ up
        if np.hypot(x, y) < 0.15:  # pointing at or away from the viewer: a dot
            ax.plot(0, 0, "o", color=color, ms=3)
        else:
            ax.annotate("", (x, y), (0, 0), arrowprops={"arrowstyle": "->", "color": color})
        ax.text(1.15 * x, 1.15 * y, label, color=color, fontsize=7, ha="center", va="center")


def face_colors(F: np.ndarray, scalar: np.ndarray | None = None,
                vmax: float | None = None) -> np.ndarray:
    """Per-face RGB (f, 3): base grey, or viridis of the per-vertex ``scalar`` (n,) averaged
    over each face, over ``[0, vmax]`` (default: the scalar's maximum)."""
    if scalar is None:
        return np.tile(BASE, (len(F), 1))
    from matplotlib import colormaps
    values = scalar[F].mean(axis=1) / (vmax if vmax else max(scalar.max(), 1e-300))
    return colormaps["viridis"](np.clip(values, 0, 1))[:, :3]


def group_colors(V: np.ndarray, F: np.ndarray, vertex_groups: Sequence[np.ndarray]
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mesh with each handle group painted where its vertices are: a face whose corners
    all belong to one group (or none) takes its colour; a face between groups is cut at its
    edges' midpoints into four, each corner triangle in its corner's colour and the middle
    one in the colour two corners share (grey if none). So a selection is drawn out to half
    its edges, as the interpolated membership reads it: a long CAD triangle with one
    selected corner shows a quarter of it coloured, not all of it, and a selected ring seen
    edge on still shows a band. A vertex in several groups takes the last one's colour.

    Parameters
    ----------
    V : (n, 3) float array; F : (f, 3) int array
    vertex_groups : sequence of int arrays, vertex ids per group (palette colours in order)

    Returns
    -------
    V : (n + 3k, 3) float array, the midpoints of the k cut faces appended;
    F : (f + 3k, 3) int array; colors : (f + 3k, 3) float array, per face

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [4, 0, 0], [0, 4, 0]])
    >>> W, G, c = group_colors(V, np.array([[0, 1, 2]]), [np.array([0])])
    >>> len(G), (c == PALETTE[0]).all(axis=1).tolist()
    (4, [True, False, False, False])
    """
    label = np.full(len(V), -1, dtype=np.int64)
    for k, ids in enumerate(vertex_groups):
        ids = np.asarray(ids, dtype=np.int64)
        label[ids[(ids >= 0) & (ids < len(V))]] = k
    corner = label[F]
    cut = (corner != corner[:, :1]).any(axis=1)
    kept, C, L = F[~cut], F[cut], corner[cut]
    k = len(C)
    mid = np.arange(3 * k).reshape(k, 3) + len(V)  # midpoints of edges 01, 12, 20
    W = np.vstack([V, (V[C] + V[C[:, [1, 2, 0]]]).reshape(-1, 3) / 2])
    pieces = np.concatenate([np.column_stack([C[:, 0], mid[:, 0], mid[:, 2]]),
                             np.column_stack([mid[:, 0], C[:, 1], mid[:, 1]]),
                             np.column_stack([mid[:, 2], mid[:, 1], C[:, 2]]),
                             mid])
    shared = np.where(L[:, 1] == L[:, 2], L[:, 1], np.where(L[:, 0] == L[:, 1], L[:, 0],
                                                             np.where(L[:, 0] == L[:, 2],
                                                                      L[:, 0], -1)))
    labels = np.concatenate([label[kept[:, 0]], L[:, 0], L[:, 1], L[:, 2], shared])
    palette = np.vstack([PALETTE, BASE])  # label -1 reads the last row
    colors = palette[np.where(labels < 0, len(PALETTE), labels % len(PALETTE))]
    return W, np.vstack([kept, pieces]), colors


def render_png(panels: list, size: tuple[int, int] = (800, 600),
               view: str | Sequence[str] = "iso", colorbar: Any = None,
               legend: Any = None, axes: Any = None, note: str | None = None,
               titles: Sequence[str] | None = None,
               framed: np.ndarray | None = None) -> bytes:
    """PNG bytes of one or more panels side by side, for one or more views.

    Parameters
    ----------
    panels : list of list of (V, F, colors, alpha): meshes per panel, drawn in order
    size : (width, height) in pixels
    view : a VIEWS name or 'x,y,z' viewing direction, or a list of them: every view gets its
        own columns (one per panel), framed alike within the view
    colorbar : (label, vmax) to add a viridis colour bar, optional
    legend : list of str, optional, the names of the palette's colours in order (groups)
    axes : (3, 3) float array, optional, the model's x, y, z axes in the renderer's frame:
        a triad in the lower left corner of each view shows them
    note : str, optional, a line of text at the bottom (e.g. the mesh's extent)
    titles : list of str, optional, one per panel ("rest", "deformed"); with several views
        each column's label also names its view
    framed : (p, 3) float array, optional, points the view's frame also holds (the frames of
        an animation framed alike: every frame's extent)
    """
    canvas = Canvas(len(panels), size, view, colorbar, legend, axes, titles, framed)
    try:
        return canvas.png(panels, note)
    finally:
        canvas.close()


class Canvas:
    """The figure of :func:`render_png` without its meshes and note, to draw again and again
    (an animation's frames: the axes, triad, legend and colour bar made once, which was half
    of a frame's drawing). :meth:`png` draws the panels' meshes and the note, saves, and
    takes them off again; the bytes are those :func:`render_png` gives."""

    def __init__(self, n_panels: int, size: tuple[int, int] = (800, 600),
                 view: str | Sequence[str] = "iso", colorbar: Any = None,
                 legend: Any = None, axes: Any = None, titles: Sequence[str] | None = None,
                 framed: np.ndarray | None = None) -> None:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.cm import ScalarMappable
        from matplotlib.colors import Normalize

        self.dpi = 100
        self.fig = fig = plt.figure(figsize=(size[0] / self.dpi, size[1] / self.dpi),
                                    dpi=self.dpi)
        # the colour bar and its labels take about 90 pixels, whatever the picture's width
        width = 1.0 - min(0.4, 90 / size[0]) if colorbar else 1.0
        self.views = views = [view] if isinstance(view, str) else list(view)
        columns = len(views) * n_panels
        labelled = bool(titles) or len(views) > 1
        top = 0.92 if labelled else 1.0  # room above the panels for their labels
        self.budget = int(FACES_PER_PIXEL * size[0] * width / columns * size[1] * top)
        self.framed = framed
        self.axes: list[list[Any]] = []
        for v, name in enumerate(views):
            row = []
            for k in range(n_panels):
                col = v * n_panels + k
                ax = fig.add_axes((col * width / columns, 0, width / columns, top))
                ax.set_axis_off()
                row.append(ax)
                label = ", ".join(([titles[k]] if titles else [])
                                  + ([name] if len(views) > 1 else []))
                if label:
                    fig.text((col + 0.5) * width / columns, 0.965, label, ha="center",
                             va="top", fontsize=9, color="0.2")
            self.axes.append(row)
            if axes is not None:
                _triad(fig, v * n_panels * width / columns, name, axes)
        if colorbar:
            cax = fig.add_axes((width + 0.1 * (1 - width), 0.12, 0.022 * 800 / size[0], 0.76))
            bar = fig.colorbar(ScalarMappable(Normalize(0, colorbar[1]), "viridis"), cax=cax)
            bar.set_label(colorbar[0], fontsize=7, labelpad=2)
            bar.ax.tick_params(labelsize=7)
            from matplotlib.ticker import FuncFormatter
            bar.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.2g}"))
            bar.ax.yaxis.get_offset_text().set_visible(False)
        if legend:
            from matplotlib.patches import Patch
            fig.legend(handles=[Patch(color=PALETTE[k % len(PALETTE)], label=text)
                                for k, text in enumerate(legend)], loc="upper left",
                       fontsize=8, frameon=False)

    def png(self, panels: list, note: str | None = None) -> bytes:
        """PNG bytes of ``panels`` (see :func:`render_png`) with ``note`` at the bottom."""
        # every mesh once, reduced to what its panel's pixels can show
        shown = [[(display_mesh(V, F, c, self.budget), a) for V, F, c, a in meshes]
                 for meshes in panels]
        drawn = []
        for name, row in zip(self.views, self.axes):
            boxes = []
            for ax, meshes in zip(row, shown):
                boxes += [draw(ax, V, F, c, name, a, normals)
                          for (V, F, c, normals), a in meshes]
                drawn += list(ax.artists)
            if self.framed is not None:
                _, up, right = camera(name)
                x, y = self.framed @ right, self.framed @ up
                boxes.append((x.min(), x.max(), y.min(), y.max()))
            _frame(row, boxes)
        if note:
            drawn.append(self.fig.text(0.01, 0.01, note, fontsize=7, color="0.3"))
        buf = io.BytesIO()
        self.fig.savefig(buf, format="png", dpi=self.dpi, metadata={"Software": None})
        for artist in drawn:
            artist.remove()
        return buf.getvalue()

    def close(self) -> None:
        import matplotlib.pyplot as plt
        plt.close(self.fig)
