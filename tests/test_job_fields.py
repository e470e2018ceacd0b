"""Every task's job checks its own fields (``tasks/job_fields.py``): one ValueError or
TypeError naming the field, as ``deform`` checks its arguments (issue 71, API-6: a KeyError,
ZeroDivisionError, AttributeError or OverflowError came from deep inside a run)."""
import pytest

import srarap_cli
from srarap_cli import BenchJob, CompareJob, PlotJob, RenderJob


@pytest.mark.parametrize("make, error, words", [
    (lambda: RenderJob("m.obj", "o.png", up="w"), ValueError, "RenderJob.up must be one of"),
    (lambda: RenderJob("m.obj", "o.png", views=()), ValueError, "RenderJob.views"),
    (lambda: RenderJob("m.obj", "o.png", fps=0), ValueError, "RenderJob.fps"),
    (lambda: RenderJob("m.obj", "o.png", fps=-1), ValueError, "RenderJob.fps"),
    (lambda: RenderJob("m.obj", "o.png", size=800), TypeError, "RenderJob.size"),
    (lambda: RenderJob("m.obj", "o.png", color="red"), ValueError, "RenderJob.color"),
    (lambda: PlotJob((), "o.png"), ValueError, "PlotJob.logs"),
    (lambda: PlotJob("a.csv", "o.png"), ValueError, "PlotJob.logs"),
    (lambda: CompareJob("a", "b", tol=10 ** 400), ValueError, "CompareJob.tol"),
    (lambda: CompareJob("a", "b", tol=float("nan")), ValueError, "CompareJob.tol"),
    (lambda: CompareJob("a", "b", relative="yes"), TypeError, "CompareJob.relative"),
    (lambda: CompareJob("a", "b", beyond_tol=2), ValueError, "CompareJob.beyond_tol"),
    (lambda: CompareJob("a", "b", align="affine"), ValueError, "CompareJob.align"),
    (lambda: BenchJob("m", "h", time_budget=0), ValueError, "BenchJob.time_budget"),
    (lambda: BenchJob("m", "h", settings=[1]), TypeError, "BenchJob.settings"),
    (lambda: srarap_cli.run_render({"mesh": "m"}), TypeError, "run_render takes a RenderJob"),
    (lambda: srarap_cli.run_plot(None), TypeError, "run_plot takes a PlotJob"),
    (lambda: srarap_cli.run_compare("a"), TypeError, "run_compare takes a CompareJob"),
    (lambda: srarap_cli.run_bench(object()), TypeError, "run_bench takes a BenchJob"),
])
def test_a_bad_field_is_one_error_naming_it(make, error, words):
    with pytest.raises(error, match=words):
        make()


def test_the_jobs_the_api_page_lists_import_from_srarap_cli():
    for name in ("RenderJob", "run_render", "PlotJob", "run_plot", "BenchJob", "run_bench",
                 "CompareJob", "run_compare"):
        assert name in srarap_cli.__all__ and getattr(srarap_cli, name) is not None
