"""The README's complete handle-file example is valid against the sample bar."""
import os
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import ROOT, run_cli

from srarap_cli.cli import main
from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh


@pytest.mark.parametrize("page, heading", [("README.md", "## Handle files"),
                                           ("docs/guides/handle-files.md", "# ")])
def test_the_complete_handle_example_is_the_shipped_one_and_runs_as_pasted(tmp_path, page,
                                                                          heading):
    text = Path(ROOT, page).read_text(encoding="utf-8")
    section = text[text.index(heading):]
    example = re.search(r"```yaml\n(.*?)```", section, re.DOTALL).group(1)
    shipped = Path(ROOT, "configs", "handles-reference.yaml").read_text(encoding="utf-8")
    assert shipped.endswith(example)  # after its header comment
    # pasted into a samples folder, beside the files it names, it runs as written
    assert CliRunner().invoke(main, ["samples", str(tmp_path / "s")]).exit_code == 0
    pasted = tmp_path / "s" / "configs" / "pasted.yaml"
    pasted.write_text(example)
    bar = str(tmp_path / "s" / "sample_meshes" / "bar.obj")
    V = read_mesh(bar).vertices
    c = load_handles(str(pasted), V, fps=24)
    assert set(c.groups) == {"base", "tip", "ears", "paw", "tail"}
    assert c.solver["alpha"] == 0.14 and c.region is not None and len(c.tracks) == 1
    # the files select what their comments say: the rings at z = 6.5 (ears) and z = 8 (paw)
    assert np.allclose(V[c.groups["ears"], 2], 6.5) and len(c.groups["ears"]) == 16
    assert np.allclose(V[c.groups["paw"], 2], 8.0) and len(c.groups["paw"]) == 16
    out = tmp_path / "out.obj"
    r = CliRunner().invoke(main, ["deform", bar, str(pasted), "-o", str(out), "--strict"])
    assert r.exit_code == 0, r.stderr  # and no warning (--strict)
    moved = read_mesh(str(out)).vertices
    assert np.allclose(moved[c.ids], c.targets, atol=1e-9)


@pytest.mark.slow
def test_the_tour_runs_as_written(tmp_path):
    """Every block of the README's tour, in order, in an empty folder (Python blocks through
    the same interpreter), must succeed."""
    import subprocess
    import sys

    text = Path(ROOT, "README.md").read_text(encoding="utf-8")
    tour = text[text.index("## A five-minute tour"):text.index("## Handle files")]
    blocks = re.findall(r"```(sh|python)\n(.*?)```", tour, re.DOTALL)
    assert len(blocks) >= 6
    script = "set -e\n" + "".join(
        body if kind == "sh" else f"python3 - <<'PYBLOCK'\n{body}PYBLOCK\n"
        for kind, body in blocks)
    bindir = os.path.dirname(sys.executable)  # python3 and srarap of this environment
    env = {**os.environ, "PATH": bindir + os.pathsep + os.environ["PATH"]}
    p = subprocess.run(["bash", "-c", script],
                       cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    assert (tmp_path / "demo" / "pushed.obj").exists() and "2 jobs: 2 ok" in p.stderr
    # the tour's own examples deserve no warning (its animation warned of keys no frame
    # showed, issue 60)
    assert "warning" not in p.stderr, p.stderr[-2000:]


def test_the_options_table_is_the_settings_table():
    from srarap_cli.cli.options import markdown_table
    assert markdown_table() in Path(ROOT, "README.md").read_text(encoding="utf-8")


def test_one_command_writes_every_generated_table_and_none_is_stale(tmp_path):
    """docs/make_tables.py --check: the README's tables and the JSON Schema are what the
    code generates; a stale copy is named (shown here on a README with a stale table)."""
    import subprocess
    import sys

    p = subprocess.run([sys.executable, os.path.join(ROOT, "docs", "make_tables.py"),
                        "--check"], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert p.returncode == 0, p.stdout
    sys.path.insert(0, os.path.join(ROOT, "docs"))
    try:
        import make_tables
    finally:
        sys.path.pop(0)
    text = Path(ROOT, "README.md").read_text(encoding="utf-8")
    stale = text.replace("| `vtu` | `.vtu` |", "| `vtu` | `.vtx` |")
    assert stale != text and make_tables.replace_table(stale, _formats_table()) == text


def test_every_exit_code_is_in_the_one_table_and_named_where_used():
    """The tables are generated from ``runtime/exit_codes.py`` (issue 62); every code it
    names is documented, and no module writes 130, 141 or 143 as a number."""
    import re

    from srarap_cli.runtime import exit_codes
    named = {v for k, v in vars(exit_codes).items() if k.isupper() and isinstance(v, int)}
    assert {c for codes, _, _ in exit_codes.TABLE for c in codes} == named
    for path in Path(ROOT, "srarap_cli").rglob("*.py"):
        if path.name == "exit_codes.py":
            continue
        code = re.sub(r"#.*|\"\"\"[\s\S]*?\"\"\"", "", path.read_text(encoding="utf-8"))
        assert not re.search(r"(exit|_exit|return|: |, )\s*\(?\s*1(30|41|43)\b", code), path


def _formats_table():
    from srarap_cli.io.mesh.meshio_formats import markdown_table
    return markdown_table()


def test_the_formats_table_is_the_format_registry():
    from srarap_cli.io.mesh.meshio_formats import markdown_table
    assert markdown_table() in Path(ROOT, "README.md").read_text(encoding="utf-8")


def test_the_docs_home_page_names_the_formats_there_are():
    """It said OBJ, PLY, OFF, STL long after the meshio formats came (issue 60)."""
    from srarap_cli.io.mesh.formats import FORMATS
    from srarap_cli.io.mesh.meshio_formats import TABLE
    home = Path(ROOT, "docs", "index.md").read_text(encoding="utf-8")
    own = [f.name.upper() for f in FORMATS.values() if f.name not in TABLE]
    assert own == ["OBJ", "OFF", "PLY", "STL"] and all(name in home for name in own)
    assert f"{len(TABLE)} simulation formats more" in home


def test_the_readme_stays_a_front_door():
    assert len(Path(ROOT, "README.md").read_bytes()) <= 25_000


def test_the_handle_file_guide_names_every_key_the_schema_knows():
    from srarap_cli.io.handles.schema import handle_schema
    guide = Path(ROOT, "docs", "guides", "handle-files.md").read_text(encoding="utf-8")
    schema = handle_schema()
    group = schema["properties"]["groups"]["additionalProperties"]["properties"]
    rotate = group["rotate"]["properties"]
    for key in [*schema["properties"], *group, *rotate]:
        assert f"`{key}`" in guide, key


def test_the_guides_manifest_example_is_a_valid_manifest(tmp_path):
    """The regression guide's manifest, in the layout it describes, loads with its gates and
    runs: its first run has no golden (exit 8), --update-goldens makes it, then it passes."""
    from srarap_cli.tasks.batch.manifest import load_manifest
    guide = Path(ROOT, "docs", "guides", "regression.md").read_text(encoding="utf-8")
    block = re.search(r"```yaml\n(.*?)```", guide, re.DOTALL).group(1)
    for folder in ("meshes", "handles"):
        (tmp_path / folder).mkdir()
    os.symlink(Path(ROOT, "sample_meshes", "bar.obj"), tmp_path / "meshes" / "bar.obj")
    os.symlink(Path(ROOT, "configs", "bar-twist.yaml"), tmp_path / "handles" / "bar-twist.yaml")
    path = tmp_path / "regression.yaml"
    path.write_text(block)
    jobs = load_manifest(str(path))
    assert [j.name for j in jobs] == ["bar-twist"] and os.path.exists(jobs[0].mesh)
    assert jobs[0].expect.energy_rtol == 1e-4 and jobs[0].expect.iterations_within == 3
    steps = [run_cli(["batch", path, "-o", tmp_path / "out", *extra], cwd=tmp_path).returncode
             for extra in ([], ["--update-goldens"], [])]
    assert steps == [8, 8, 0] and (tmp_path / "golden" / "bar-twist.obj").exists()


def test_the_guides_make_rule_builds_its_target_and_then_has_nothing_to_do(tmp_path):
    import shutil
    import subprocess
    import sys

    guide = Path(ROOT, "docs", "guides", "workflows.md").read_text(encoding="utf-8")
    rule = re.search(r"```make\n(.*?)```", guide, re.DOTALL).group(1)
    (tmp_path / "Makefile").write_text(rule)
    shutil.copy(Path(ROOT, "sample_meshes", "bar.obj"), tmp_path / "bar.obj")
    shutil.copy(Path(ROOT, "configs", "bar-twist.yaml"), tmp_path / "twist.yaml")
    env = {**os.environ, "PATH": os.path.dirname(sys.executable) + os.pathsep
           + os.environ["PATH"]}
    first = subprocess.run(["make", "twisted.obj"], cwd=tmp_path, env=env,
                           capture_output=True, text=True)
    assert first.returncode == 0, first.stderr
    assert (tmp_path / "twisted.obj").stat().st_size > 0 and (tmp_path / "twisted.csv").exists()
    again = subprocess.run(["make", "twisted.obj"], cwd=tmp_path, env=env,
                           capture_output=True, text=True)
    assert "up to date" in again.stdout


@pytest.mark.slow
def test_the_python_guide_runs_as_written(tmp_path):
    """Its blocks in order, in one interpreter, in a folder holding the samples."""
    import subprocess
    import sys

    guide = Path(ROOT, "docs", "guides", "python.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", guide, re.DOTALL)
    assert len(blocks) >= 4
    subprocess.run([os.path.join(os.path.dirname(sys.executable), "srarap"), "samples",
                    str(tmp_path), "-q"], check=True)
    p = subprocess.run([sys.executable, "-c", "".join(blocks)], cwd=tmp_path,
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    assert (tmp_path / "twisted.obj").exists() and (tmp_path / "turn_180.obj").exists()
    assert (tmp_path / "suite-out" / "summary.csv").exists()
    assert p.stdout.splitlines()[-1].startswith("True")


@pytest.mark.slow
def test_the_guides_dask_worker_command_serves_a_batch(tmp_path):
    """The worker command as written (host and port filled in) joins a scheduler, and a batch
    of the regression guide's manifest runs on it (its golden written and accepted there)."""
    import shutil
    import signal
    import socket
    import subprocess
    import sys
    import time

    guide = Path(ROOT, "docs", "guides", "workflows.md").read_text(encoding="utf-8")
    command = re.search(r"```\n(OPENBLAS_NUM_THREADS=1 dask worker .*?)```", guide,
                        re.DOTALL).group(1).strip()
    regression = Path(ROOT, "docs", "guides", "regression.md").read_text(encoding="utf-8")
    manifest = re.search(r"```yaml\n(.*?)```", regression, re.DOTALL).group(1)
    for folder in ("meshes", "handles"):
        (tmp_path / folder).mkdir()
    shutil.copy(Path(ROOT, "sample_meshes", "bar.obj"), tmp_path / "meshes")
    shutil.copy(Path(ROOT, "configs", "bar-twist.yaml"), tmp_path / "handles")
    (tmp_path / "guide.yaml").write_text(manifest)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    bindir = os.path.dirname(sys.executable)
    env = {**os.environ, "PATH": bindir + os.pathsep + os.environ["PATH"]}
    address = f"tcp://127.0.0.1:{port}"
    started = [subprocess.Popen([os.path.join(bindir, "dask"), "scheduler", "--host",
                                 "127.0.0.1", "--port", str(port), "--no-dashboard"],
                                env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True)]
    try:
        time.sleep(2)  # tasks wait for a worker anyway; this only keeps the log tidy
        started.append(subprocess.Popen(["bash", "-c", command.replace("tcp://host:8786",
                                                                       address)],
                                        env=env, cwd=tmp_path, stdout=subprocess.DEVNULL,
                                        stderr=subprocess.DEVNULL, start_new_session=True))
        p = subprocess.run([os.path.join(bindir, "srarap"), "batch", "guide.yaml",
                            "-o", "out", "--scheduler", address, "--accept-goldens"],
                           cwd=tmp_path, env=env,
                           capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr[-2000:]
        assert (tmp_path / "out" / "bar-twist.obj").exists()
        assert (tmp_path / "golden" / "bar-twist.obj").exists()
    finally:
        for proc in started:
            os.killpg(proc.pid, signal.SIGTERM)
            proc.wait(timeout=30)
