"""The README's complete handle-file example is valid against the sample bar."""
import os
import re
from pathlib import Path

import numpy as np
from helpers import ROOT

from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh


def test_readme_handle_example_loads(tmp_path):
    text = Path(ROOT, "README.md").read_text(encoding="utf-8")
    section = text[text.index("## Handle files"):]
    example = re.search(r"```yaml\n(.*?)```", section, re.DOTALL).group(1)
    (tmp_path / "handles.yaml").write_text(example)
    V = read_mesh(os.path.join(ROOT, "sample_meshes", "bar.obj")).vertices
    z = V[:, 2]
    groups = np.where((z > 2.4) & (z < 2.6), 2, -1)  # a ring for the 'ears' group
    (tmp_path / "selection.dmat").write_text(f"1 {len(V)}\n" + "\n".join(map(str, groups)))
    status = np.where((z > 7.4) & (z < 7.6), 2, 1)  # a ring for the 'paw' group
    (tmp_path / "shape.sel").write_text("# status\n# per vertex\n" + "\n".join(map(str, status)))
    (tmp_path / "shape.def").write_text("# move\n1 0 0 5\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    c = load_handles(str(tmp_path / "handles.yaml"), V, fps=24)
    assert set(c.groups) == {"base", "tip", "ears", "paw", "tail"}
    assert c.solver["alpha"] == 0.14 and c.region is not None and len(c.tracks) == 1
    assert all(len(ids) for ids in c.groups.values())
