"""One fingerprint of what decides a run's outputs (issue 72): a batch job's record and an
animation's resume state hash the same things the same way."""
import os

import pytest
import yaml
from click.testing import CliRunner
from helpers import ROOT

from srarap_cli.cli import main
from srarap_cli.solver.settings import SETTINGS, resolve
from srarap_cli.tasks.deform.job import DeformJob, _key
from srarap_cli.tasks.fingerprint import NOT_DECIDING, fingerprint

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
TWIST = os.path.join(ROOT, "configs", "bar-twist.yaml")


def test_what_decides_nothing_is_a_column_of_the_settings_table():
    assert NOT_DECIDING == tuple(s.name for s in SETTINGS if not s.decides)
    assert set(NOT_DECIDING) == {"threads", "strict", "allow"}


@pytest.mark.parametrize("layer", [{"threads": 3}, {"strict": "all"}, {"allow": ["units"]},
                                   {"tol": 1e-6}, {"multires": "auto"}])
def test_a_default_written_out_or_a_setting_that_decides_nothing_keeps_it(layer):
    plain = fingerprint([b"m", b"h"], resolve(), {"output": "o.obj"})
    assert fingerprint([b"m", b"h"], resolve(layer), {"output": "o.obj"}) == plain


@pytest.mark.parametrize("change", [
    ([b"m", b"h2"], {}, {"output": "o.obj"}),
    ([b"m", b"h"], {"tol": 1e-7}, {"output": "o.obj"}),
    ([b"m", b"h"], {}, {"output": "p.obj"}),
    ([b"m", b"h"], {}, {"output": "o.obj", "distortion": True})])
def test_an_input_a_deciding_setting_or_an_output_option_changes_it(change):
    inputs, layer, outputs = change
    plain = fingerprint([b"m", b"h"], resolve(), {"output": "o.obj"})
    assert fingerprint(inputs, resolve(layer), outputs) != plain


def test_a_jobs_key_resolves_its_settings_over_the_handle_files(tmp_path):
    """Writing the default out keeps the key; writing it over a handle file's own value is
    a change (the run differs), as is an output option that changes a file."""
    handles = tmp_path / "h.yaml"
    handles.write_text(open(TWIST).read().replace("tol: 1.0e-6", "tol: 1.0e-8"))
    base = DeformJob(BAR, TWIST, str(tmp_path / "o.ply"))
    same = DeformJob(BAR, TWIST, str(tmp_path / "o.ply"), settings={"tol": 1e-6})
    assert _key(base) == _key(same)
    own = DeformJob(BAR, str(handles), str(tmp_path / "o.ply"))
    over = DeformJob(BAR, str(handles), str(tmp_path / "o.ply"), settings={"tol": 1e-6})
    assert _key(own) != _key(over)
    more = DeformJob(BAR, TWIST, str(tmp_path / "o.ply"), write_distortion=True)
    assert _key(more) != _key(base)


def test_a_batch_rerun_that_writes_a_default_out_is_up_to_date(tmp_path):
    """Issue 72: ``tol: 1.0e-6`` (the default) added to a job re-solved it."""
    def run(settings):
        path = tmp_path / "jobs.yaml"
        path.write_text(yaml.safe_dump({"jobs": [{"name": "t", "mesh": BAR, "handles": TWIST,
                                                  "output": "t.obj", **settings}]}))
        r = CliRunner().invoke(main, ["batch", str(path), "-o", str(tmp_path / "out")])
        assert r.exit_code == 0, r.stderr
        return (tmp_path / "out" / "summary.csv").read_text().splitlines()[1].split(",")[1]
    assert run({}) == "ok"
    assert run({"settings": {"tol": 1.0e-6}}) == "up-to-date"
    assert run({"settings": {"tol": 1.0e-7}}) == "ok"
