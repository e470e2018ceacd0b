"""The one log-axis rule of srarap's pictures (``srarap plot``, the batch report)."""
import matplotlib.pyplot as plt
import pytest

from srarap_cli.tasks.pictures.log_axis import decades_axis

plt.switch_backend("Agg")


@pytest.mark.parametrize("values, log", [
    ([100.0, 1.0], True), ([20.0, 2.1], False), ([5.0, 0.0], False), ([-1.0, 100.0], False),
    ([], False), ([1e-30, 1.0], True)])
def test_log_only_where_positive_values_span_decades(values, log):
    fig, ax = plt.subplots()
    try:
        assert decades_axis(ax, "y", values) is log
        assert ax.get_yscale() == ("log" if log else "linear")
        assert ax.get_xscale() == "linear"
    finally:
        plt.close(fig)


def test_tick_labels_take_the_format():
    fig, ax = plt.subplots()
    try:
        decades_axis(ax, "x", [1.0, 1000.0], "{:.1f}s")
        assert ax.xaxis.get_major_formatter()(10.0, 0) == "10.0s"
        assert ax.xaxis.get_minor_formatter()(20.0, 0) == ""
    finally:
        plt.close(fig)
