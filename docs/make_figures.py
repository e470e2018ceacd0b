"""Every picture of the documentation and the README, drawn by srarap itself, so that they
show what the commands draw today.

Run from the repository root:

    python docs/make_figures.py [--out DIR]

(``--out``: write there instead of ``docs/images``; tests/test_docs_site.py does, and
compares the bytes with the committed figures, so a change to what srarap draws shows up as
figures to regenerate.)

It copies the samples into a temporary folder (``srarap samples``), runs ``deform``,
``render`` and ``plot`` there, and writes ``docs/images/*.png``. Each figure and the page it
belongs to are listed in FIGURES.
"""
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
IMAGES = os.path.join(HERE, "images")

#: figure -> the pages that show it (checked by tests/test_docs_site.py)
FIGURES = {
    "bar-bend.png": ["index.md", "../README.md"],
    "select-box.png": ["guides/handle-files.md"],
    "select-sphere.png": ["guides/handle-files.md"],
    "select-sel.png": ["guides/handle-files.md"],
    "bar-twist-side.png": ["guides/workflows.md"],
    "bar-bend-distortion.png": ["guides/workflows.md"],
    "energy.png": ["guides/workflows.md"],
}

SELECTIONS = {
    "select-box.png": "box: {min: [0, -2, 6], max: [2, 2, 9]}",
    "select-sphere.png": "sphere: {center: [1, 0, 4], radius: 1.5}",
    "select-sel.png": "sel: {file: ../configs/shape.sel, status: handle}",
}


def srarap(*args, cwd):
    subprocess.run([sys.executable, "-m", "srarap_cli", *args, "-q"] if args[0] in (
        "deform",) else [sys.executable, "-m", "srarap_cli", *args], cwd=cwd, check=True)


def main():
    images = IMAGES
    if sys.argv[1:2] == ["--out"]:
        images = os.path.abspath(sys.argv[2])
    with tempfile.TemporaryDirectory() as tmp:
        srarap("samples", "s", cwd=tmp)
        work = os.path.join(tmp, "s")
        bar, bend = "sample_meshes/bar.obj", "configs/bar-bend.yaml"
        srarap("deform", bar, bend, "-o", "bent.obj", "--log", "bend.csv", cwd=work)
        srarap("deform", bar, "configs/bar-twist.yaml", "-o", "twisted.obj", "--log",
               "twist.csv", cwd=work)
        out = {name: os.path.join(images, name) for name in FIGURES}
        for name in FIGURES:
            if os.path.exists(out[name]):
                os.remove(out[name])  # srarap does not overwrite what it was not asked to
        srarap("render", "bent.obj", "--rest", bar, "--handles", bend, "-o",
               out["bar-bend.png"], cwd=work)
        srarap("render", "bent.obj", "--rest", bar, "--color", "distortion", "-o",
               out["bar-bend-distortion.png"], cwd=work)
        srarap("render", "twisted.obj", "--rest", bar, "--handles", "configs/bar-twist.yaml",
               "--layout", "side", "--size", "900x500", "-o", out["bar-twist-side.png"],
               cwd=work)
        srarap("plot", "bend.csv", "twist.csv", "-o", out["energy.png"], cwd=work)
        os.makedirs(os.path.join(work, "sel"))
        for name, selector in SELECTIONS.items():
            handles = os.path.join(work, "sel", name.replace(".png", ".yaml"))
            with open(handles, "w") as fh:
                fh.write(f"groups:\n  selected:\n    {selector}\n    fixed: true\n")
            srarap("render", bar, "--handles", handles, "--size", "400x500", "-o", out[name],
                   cwd=work)
    for name in FIGURES:
        print(f"wrote {os.path.relpath(out[name])}")


if __name__ == "__main__":
    main()
