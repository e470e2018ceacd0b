"""Every solver setting, in every value form it documents, reaches the solver whole and the
same through each of the four entry points: the command line, a handle file's ``solver``
block, a batch manifest's ``settings`` and the Python API's keywords. The same bytes come
out whichever way it came in, and the Settings the solver is built with holds the parsed
value (a spy on the one place solvers are made)."""
import json

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from helpers import tube

import srarap_cli
from srarap_cli.cli import main
from srarap_cli.io.mesh import Mesh, read_mesh, write_mesh
from srarap_cli.solver.multires.size import parse_size
from srarap_cli.solver.settings import BY_NAME, DEFAULT_SETTINGS, SETTINGS, resolve
from srarap_cli.tasks import pipeline

LENGTH = 6.0
#: name -> every documented form of a value, as a Python caller or a YAML file gives it
#: (the command line gets each as text)
FORMS = {
    "alpha": [0.3, 1],
    "feedback": [0.5, 0],
    "weights": ["cotan", "uniform", "cotan-clamped"],
    "method": ["sr-linear", "sr-relax", "arap", "sr-linear-sym"],
    "handle_rotors": ["lagged", "boundary"],
    "sweeps": [3],
    "max_iter": [4, 0],
    "tol": [1e-3, 0],
    "time_limit": [100, 2.5],
    "accel": ["none", "anderson"],
    "start": ["laplacian", "harmonic"],
    "multires": ["off", "auto", 60, "60", "30%", 0.3, "0.3"],
    "multires_mode": ["transfer", "refine"],
    "strict": ["request", "all", "off", True, False],  # the problem has no warning: the same
    # bytes either way
    "allow": [["needles", "units"], "duplicate-faces"],
    "threads": [2, 1],  # any count gives the same bytes
}
#: forms that need a companion setting to make a difference (``tol`` 0 runs every iteration
#: allowed: a few are enough to compare the bytes)
WITH = {"sweeps": {"method": "sr-relax"}, "multires_mode": {"multires": 60},
        "tol": {"max_iter": 30}}
CASES = [(name, value) for name, values in FORMS.items() for value in values]
#: the quick loop solves each setting's first form through every entry point; the other
#: forms run in the whole suite
ENTRY_CASES = [pytest.param(name, value, marks=[pytest.mark.slow] if k else [])
               for name, values in FORMS.items() for k, value in enumerate(values)]


def test_the_forms_cover_every_setting_and_every_choice():
    assert set(FORMS) == set(BY_NAME)
    for s in SETTINGS:
        if s.choices:
            assert set(s.choices) <= set(FORMS[s.name]), s.name
    sizes = FORMS["multires"]
    assert {"off", "auto"} <= set(sizes) and any(isinstance(v, int) for v in sizes)
    assert any(str(v).endswith("%") for v in sizes) and any(isinstance(v, float) for v in sizes)


@pytest.mark.parametrize("name, value", CASES)
def test_parsing_is_idempotent(name, value):
    parsed = BY_NAME[name].parse(value, ValueError)
    assert BY_NAME[name].parse(parsed, ValueError) == parsed
    s = resolve({name: value})
    assert resolve(s.as_dict()) == s and resolve(s) == s and s.replace() == s


@pytest.fixture(scope="module")
def problem(tmp_path_factory):
    folder = tmp_path_factory.mktemp("entry")
    V, F = tube(length=LENGTH, rings=14, segments=10)
    write_mesh(str(folder / "m.obj"), Mesh.from_arrays(V, F))
    return folder


def _handles(folder, solver):
    doc = {"groups": {"base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]},
                               "fixed": True},
                      "top": {"box": {"min": [-2, -2, LENGTH - 0.01],
                                      "max": [2, 2, LENGTH + 0.01]},
                              "rotate": {"axis": [1, 0, 0], "angle_deg": 50},
                              "translate": [0.5, 0, -0.5]}}}
    if solver:
        doc["solver"] = solver
    path = folder / f"h{len(list(folder.glob('h*.yaml')))}.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


@pytest.fixture
def spy(monkeypatch):
    seen = []
    real = pipeline.make_deformer

    def recording(*args, settings, **kwargs):
        seen.append(settings)
        return real(*args, settings=settings, **kwargs)

    monkeypatch.setattr(pipeline, "make_deformer", recording)
    return seen


def _cli(folder, given, plain):
    out = folder / "cli.obj"
    args = ["deform", str(folder / "m.obj"), str(plain), "-o", str(out), "-q",
            "--keep-unconverged"]
    for name, value in given.items():
        flag = BY_NAME[name].flag
        if BY_NAME[name].kind == "level":  # --strict alone is request; false is not giving it
            args += {True: [flag], False: []}.get(value, [f"{flag}={value}"])
        elif BY_NAME[name].kind == "codes":
            args += [a for code in ([value] if isinstance(value, str) else value)
                     for a in (flag, code)]
        else:
            args += [flag, str(value)]
    r = CliRunner().invoke(main, args)
    assert r.exit_code in (0, 3), r.output
    return out.read_bytes()


def _handle_file(folder, given):
    out = folder / "file.obj"
    r = CliRunner().invoke(main, ["deform", str(folder / "m.obj"), str(_handles(folder, given)),
                                  "-o", str(out), "-q", "--keep-unconverged"])
    assert r.exit_code in (0, 3), r.output
    return out.read_bytes()


def _manifest(folder, given, plain):
    manifest = folder / "jobs.yaml"
    manifest.write_text(yaml.safe_dump({"jobs": [{"mesh": "m.obj", "handles": plain.name,
                                                  "output": "batch.obj", "settings": given}]}))
    out = folder / "batch"
    r = CliRunner().invoke(main, ["batch", str(manifest), "-o", str(out), "-q",
                                  "--keep-unconverged"])
    assert r.exit_code in (0, 3), r.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary[0]["status"] in ("ok", "not-converged"), summary
    data = (out / "batch.obj").read_bytes()
    for path in out.iterdir():  # the next case must solve again, not find it up to date
        path.unlink()
    return data


def _api(folder, given, plain):
    mesh = read_mesh(str(folder / "m.obj"))
    result = srarap_cli.deform(mesh, str(plain), **given)
    write_mesh(str(folder / "api.obj"), mesh.with_vertices(result.positions))
    return (folder / "api.obj").read_bytes()


@pytest.mark.parametrize("name, value", ENTRY_CASES)
def test_a_setting_gives_the_same_bytes_from_every_entry_point(problem, spy, name, value):
    given = {**WITH.get(name, {}), name: value}
    plain = _handles(problem, None)
    outputs = {"command line": _cli(problem, given, plain),
               "handle file": _handle_file(problem, given),
               "manifest": _manifest(problem, given, plain),
               "python": _api(problem, given, plain)}
    assert len(set(outputs.values())) == 1, {k: len(v) for k, v in outputs.items()}
    assert len(spy) == 4 and all(s == spy[0] for s in spy)
    expected = BY_NAME[name].parse(value, ValueError)
    assert getattr(spy[0], name) == expected
    untouched = set(BY_NAME) - set(given)
    assert all(getattr(spy[0], n) == getattr(DEFAULT_SETTINGS, n) for n in untouched)


def test_a_setting_changes_the_output_where_it_should(problem):
    """The bytes-equality above would hold for a setting every entry point dropped: these
    settings must change the shape, so they did reach the solver."""
    plain = _handles(problem, None)
    base = _api(problem, {}, plain)
    for given in ({"alpha": 0.3}, {"weights": "uniform"}, {"method": "sr-linear"},
                  {"max_iter": 4}, {"multires": "30%"}, {"multires": 60,
                                                         "multires_mode": "transfer"},
                  {"tol": 1e-3}, {"handle_rotors": "lagged"}, {"start": "laplacian"}):
        assert _api(problem, given, plain) != base, given


def test_the_readmes_multires_example_runs_from_the_command_line(tmp_path):
    """``--multires 2%`` on the sample bar: a documented value of a documented option."""
    from helpers import ROOT
    out = tmp_path / "o.obj"
    r = CliRunner().invoke(main, ["deform", f"{ROOT}/sample_meshes/bar.obj",
                                  f"{ROOT}/configs/bar-bend.yaml", "-o", str(out),
                                  "--multires", "2%", "-v"])
    assert r.exit_code == 0, r.output
    assert "multires:" in r.output and out.stat().st_size > 0
    assert parse_size("2%") == 0.02


def test_a_handle_files_time_limit_reaches_animate(problem, spy, monkeypatch):
    """``animate`` takes every solve setting from the same object: a handle file's
    ``time_limit`` holds per frame (it used to be dropped)."""
    doc = yaml.safe_load(_handles(problem, None).read_text())
    doc["groups"]["top"] = {"box": doc["groups"]["top"]["box"],
                            "keyframes": [{"frame": 0},
                                          {"frame": 2, "rotate": {"axis": [1, 0, 0],
                                                                  "angle_deg": 40}}]}
    doc["solver"] = {"time_limit": 1e-9, "max_iter": 50}
    path = problem / "anim.yaml"
    path.write_text(yaml.safe_dump(doc))
    r = CliRunner().invoke(main, ["animate", str(problem / "m.obj"), str(path), "-o",
                                  str(problem / "f_{:02d}.obj"), "--log",
                                  str(problem / "frames.csv")])
    assert spy[0].time_limit == 1e-9
    assert r.exit_code == 3 and "time limit" in r.output
    rows = (problem / "frames.csv").read_text().splitlines()
    assert rows[0].endswith(",stop") and rows[-1].endswith(",time limit")


def test_settings_parsed_twice_are_the_same(problem):
    """A Settings handed to the API is not re-parsed into something else."""
    s = resolve({"multires": "30%", "tol": 1e-4})
    again = srarap_cli.deform(read_mesh(str(problem / "m.obj")), str(_handles(problem, None)),
                              settings=s)
    once = srarap_cli.deform(read_mesh(str(problem / "m.obj")), str(_handles(problem, None)),
                             multires=0.3, tol=1e-4)
    assert np.array_equal(again.positions, once.positions)
