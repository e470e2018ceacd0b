"""One stop reason, decided by the monitor, read by every consumer: the API's result, the
log's last row, the summary line, a batch's summary and sidecar. And one solver interface
that both solvers satisfy."""
import inspect
import json

import pytest
import yaml
from click.testing import CliRunner
from helpers import ends, tube

from srarap_cli import Deformer
from srarap_cli.cli import main
from srarap_cli.io.mesh import Mesh, write_mesh
from srarap_cli.runtime.errors import NumericalError
from srarap_cli.solver.interface import Solver
from srarap_cli.solver.multires import MultiresDeformer
from srarap_cli.solver.oneshot import make_deformer
from srarap_cli.solver.stop import StopReason
from srarap_cli.tasks.batch import run as batch
from srarap_cli.tasks.batch.manifest_job import ManifestJob
from srarap_cli.tasks.deform import job as job_runner


@pytest.fixture(scope="module")
def bent():
    V, F = tube(length=6.0, rings=14, segments=10)
    ids = ends(V, 6.0)
    T = V[ids].copy()
    T[T[:, 2] > 3] += [1.5, 0, -0.5]
    return V, F, ids, T


@pytest.mark.parametrize("options, reason, complete", [
    ({}, StopReason.CONVERGED, True),
    ({"tol": 0, "max_iter": 3}, StopReason.ITERATIONS_RUN, True),
    ({"max_iter": 2}, StopReason.ITERATION_LIMIT, False),
    ({"max_iter": 0}, StopReason.ITERATION_LIMIT, False),
    ({"tol": 0, "max_iter": 10**6, "time_limit": 0.2}, StopReason.TIME_LIMIT, False),
])
def test_the_result_and_the_log_say_why_the_solve_stopped(bent, options, reason, complete):
    V, F, ids, T = bent
    r = Deformer(V, F, ids).solve(T, **options)
    assert r.stop_reason is reason and r.complete is complete
    assert r.converged is (reason is StopReason.CONVERGED)
    assert [row["stop"] for row in r.log] == [""] * (len(r.log) - 1) + [reason.value]
    if reason is StopReason.ITERATION_LIMIT and r.iterations:
        assert "> tol" in r.stop_detail or "steps the energy test averages" in r.stop_detail


def test_the_papers_transfer_is_complete_when_its_coarse_solve_is(bent):
    V, F, ids, T = bent
    d = MultiresDeformer(V, F, ids, size=60, multires_mode="transfer")
    r = d.solve(T)
    assert r.stop_reason is StopReason.TRANSFER and r.approximate
    assert r.multires.stop_reason is StopReason.CONVERGED and r.complete
    short = d.solve(T, max_iter=1)
    assert short.multires.stop_reason is StopReason.ITERATION_LIMIT and not short.complete


def test_both_solvers_satisfy_the_one_interface(bent):
    V, F, ids, _ = bent
    direct, multi = make_deformer(V, F, ids), make_deformer(V, F, ids, multires=60)
    assert isinstance(direct, Deformer) and isinstance(multi, MultiresDeformer)
    wanted = inspect.signature(Solver.solve).parameters
    for solver in (direct, multi):
        assert isinstance(solver, Solver)
        have = inspect.signature(type(solver).solve).parameters
        for name, p in wanted.items():
            assert name in have, (type(solver).__name__, name)
            assert (have[name].kind, have[name].default) == (p.kind, p.default), name


def test_a_solve_with_settings_of_another_setup_is_refused(bent):
    V, F, ids, T = bent
    d = Deformer(V, F, ids)
    with pytest.raises(ValueError, match="alpha"):
        d.solve(T, settings=d.settings.replace(alpha=0.5))
    assert d.solve(T, settings=d.settings.replace(max_iter=1)).iterations == 1
    with pytest.raises(TypeError, match="unexpected keyword 'alpha'"):
        d.solve(T, alpha=0.5)


def test_summary_log_batch_and_sidecar_read_the_same_reason(bent, tmp_path):
    V, F, ids, _ = bent
    write_mesh(str(tmp_path / "m.obj"), Mesh.from_arrays(V, F))
    handles = {"groups": {"base": {"indices": ids[V[ids, 2] < 3].tolist(), "fixed": True},
                          "top": {"indices": ids[V[ids, 2] > 3].tolist(),
                                  "translate": [1.5, 0, -0.5]}},
               "solver": {"max_iter": 2}}
    (tmp_path / "h.yaml").write_text(yaml.safe_dump(handles))
    r = CliRunner().invoke(main, ["deform", str(tmp_path / "m.obj"), str(tmp_path / "h.yaml"),
                                  "-o", str(tmp_path / "o.obj"), "--log",
                                  str(tmp_path / "log.jsonl")])
    assert r.exit_code == 3 and "(iteration limit: relative change" in r.output
    last = json.loads((tmp_path / "log.jsonl").read_text().splitlines()[-1])
    assert last["stop"] == "iteration limit"
    (tmp_path / "jobs.yaml").write_text(yaml.safe_dump(
        {"jobs": [{"mesh": "m.obj", "handles": "h.yaml", "output": "o.obj"}]}))
    r = CliRunner().invoke(main, ["batch", str(tmp_path / "jobs.yaml"), "-o",
                                  str(tmp_path / "out")])
    assert r.exit_code == 3
    row = json.loads((tmp_path / "out" / "summary.json").read_text())[0]
    sidecar = json.loads((tmp_path / "out" / "o.obj.srarap.json").read_text())
    assert row["stop"] == sidecar["stop"] == "iteration limit"
    assert row["status"] == sidecar["status"] == "not-converged"
    assert "stop" in (tmp_path / "out" / "summary.csv").read_text().splitlines()[0]


def test_a_batch_job_that_went_non_finite_says_so(bent, tmp_path, monkeypatch):
    V, F, ids, _ = bent
    write_mesh(str(tmp_path / "m.obj"), Mesh.from_arrays(V, F))
    (tmp_path / "h.yaml").write_text(yaml.safe_dump(
        {"groups": {"all": {"indices": ids.tolist(), "fixed": True}}}))

    def blow_up(*args, **kwargs):
        raise NumericalError("energy became non-finite at iteration 3")

    monkeypatch.setattr(job_runner, "deform_mesh", blow_up)
    job = ManifestJob("j", str(tmp_path / "m.obj"), str(tmp_path / "h.yaml"), "o.obj")
    row = batch.run_job(job, str(tmp_path)).row()
    assert row["status"] == "failed" and row["stop"] == "non-finite"
