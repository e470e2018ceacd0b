"""Packaging a user can trust: one version, the Python it needs, the samples in the package."""
import os
import re
import tomllib
from importlib.metadata import version

import pytest
from click.testing import CliRunner
from helpers import ROOT

import srarap_cli
from srarap_cli.cli import main

PYPROJECT = tomllib.load(open(os.path.join(ROOT, "pyproject.toml"), "rb"))


def test_one_version_everywhere():
    assert srarap_cli.__version__ == version("srarap-cli") == PYPROJECT["project"]["version"]
    cff = open(os.path.join(ROOT, "CITATION.cff")).read()
    assert f"version: {srarap_cli.__version__}" in cff


def test_requires_python_is_what_the_pinned_dependencies_need():
    assert PYPROJECT["project"]["requires-python"] == ">=3.11"
    assert os.path.exists(os.path.join(ROOT, "srarap_cli", "py.typed"))


@pytest.mark.slow
def test_samples_copies_the_package_data_and_refuses_to_overwrite(tmp_path):
    runner = CliRunner()
    r = runner.invoke(main, ["samples", str(tmp_path / "demo")])
    assert r.exit_code == 0, r.output
    for sub in ("sample_meshes", "configs", "golden"):
        # what the package ships: not the scripts that made the data, nor the bytecode that
        # collecting their doctests leaves beside them where bytecode is written
        shipped = sorted(f for f in os.listdir(os.path.join(ROOT, "srarap_cli", "data", sub))
                         if not f.endswith(".py") and f != "__pycache__")
        assert sorted(os.listdir(tmp_path / "demo" / sub)) == shipped
    again = runner.invoke(main, ["samples", str(tmp_path / "demo")])
    assert again.exit_code == 6 and "--force" in again.stderr
    assert runner.invoke(main, ["samples", str(tmp_path / "demo"), "--force"]).exit_code == 0
    demo = tmp_path / "demo"
    r = runner.invoke(main, ["batch", str(demo / "configs" / "example-jobs.yaml"), "-o",
                             str(tmp_path / "out")])
    assert r.exit_code == 0, r.output  # the copied manifest finds its meshes and goldens


def test_the_changelog_keeps_a_changelog():
    text = open(os.path.join(ROOT, "CHANGELOG.md")).read()
    assert re.search(r"^## \[Unreleased\]$", text, re.M) and "### Fixed" in text
