"""``srarap bench`` on a tiny mesh: it runs and its numbers agree with its own curves."""
import csv
import json

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from helpers import tube_mesh

from srarap_cli.cli import main
from srarap_cli.io.mesh import write_mesh


@pytest.mark.slow
def test_bench_runs_and_its_summary_is_consistent_with_its_curves(tmp_path):
    write_mesh(str(tmp_path / "t.obj"), tube_mesh(rings=5, segments=6))
    (tmp_path / "h.yaml").write_text(yaml.safe_dump({"groups": {
        "base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True},
        "tip": {"box": {"min": [-2, -2, 5.99], "max": [2, 2, 6.01]},
                "rotate": {"axis": [0, 1, 0], "angle": 45}}}}))
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["bench", str(tmp_path / "t.obj"), str(tmp_path / "h.yaml"),
                                  "--time-budget", "2", "-o", str(out)])
    assert r.exit_code == 0, r.output
    summary = json.loads((out / "summary.json").read_text())
    with open(out / "curves.csv") as fh:
        rows = list(csv.DictReader(fh))
    names = [m["method"] for m in summary["methods"]]
    assert names == ["sr-linear", "sr-linear-sym", "sr-relax", "sr-linear-sym+anderson", "arap",
                     "arap+anderson", "libigl-arap"]
    sr = [row for row in rows if row["method"].startswith("sr-")]
    best = min(float(row["total"]) for row in sr)
    for m in summary["methods"]:
        mine = [row for row in rows if row["method"] == m["method"]]
        assert m["iterations"] == len(mine) - 1
        assert m["final_energy"] == float(mine[-1]["total"])
        assert m["max_constraint_error"] < 1e-12
        if m["method"].startswith("sr-") and m["iterations_to_0.1%"] is not None:
            hit = next(row for row in mine if float(row["total"]) <= best * 1.001)
            assert m["iterations_to_0.1%"] == int(hit["iteration"])
            assert m["seconds_to_0.1%"] == float(hit["seconds"])
    # the method that reached the best energy reaches 1% and 0.1% of it
    winner = min((m for m in summary["methods"] if m["method"].startswith("sr-")),
                 key=lambda m: min(float(row["total"]) for row in rows
                                   if row["method"] == m["method"]))
    assert winner["iterations_to_0.1%"] is not None
    assert (out / "energy.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "libigl ARAP / our arap" in r.output
    peer = summary["methods"][-1]
    assert np.isfinite(peer["ratio_to_arap"]) and peer["max_distance_to_arap"] >= 0
