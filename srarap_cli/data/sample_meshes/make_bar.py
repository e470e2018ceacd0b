"""Generate sample_meshes/bar.obj: a capped tube (radius 1, length 10) of quads with
triangle-fan caps and seamed UVs; the generator itself is ``srarap_cli.tasks.samples``.

Run: python sample_meshes/make_bar.py
"""
import os

from srarap_cli.tasks.samples import bar, obj_text

if __name__ == "__main__":
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bar.obj")
    with open(out, "w") as fh:
        fh.write(obj_text(*bar()))
    print(f"wrote {out}")
