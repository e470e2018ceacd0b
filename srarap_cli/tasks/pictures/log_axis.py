"""The one rule for a picture's axis of energies or seconds: logarithmic where the values
span decades, linear otherwise."""
from collections.abc import Sequence
from typing import Any


def decades_axis(ax: Any, which: str, values: Sequence[float], fmt: str = "{:g}") -> bool:
    """Put matplotlib axes ``ax``'s ``which`` axis (``"x"`` or ``"y"``) on a log scale when
    ``values`` are all positive and span more than a decade, labelled at its powers of ten
    only (minor ticks' labels ran into each other); leave it linear otherwise (a log axis
    drops zeros and negative values: a log of an exact solve, whose energy reaches 0, was
    drawn empty with a warning). Tick labels use ``fmt``. Returns whether the axis is log.

    Examples
    --------
    >>> import matplotlib
    >>> _ = matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots()
    >>> decades_axis(ax, "y", [100.0, 1.0]), decades_axis(ax, "x", [0.0, 5.0])
    (True, False)
    >>> plt.close(fig)
    """
    from matplotlib.ticker import FuncFormatter, NullFormatter

    axis = ax.xaxis if which == "x" else ax.yaxis
    log = bool(values) and min(values) > 0 and max(values) > 10 * min(values)
    if log:
        (ax.set_xscale if which == "x" else ax.set_yscale)("log")
        axis.set_minor_formatter(NullFormatter())
    axis.set_major_formatter(FuncFormatter(lambda v, _: fmt.format(v)))
    return log
