"""Write a finely subdivided capped bar (about 100k vertices) for the benchmarks.

Run: python benchmarks/make_big_bar.py OUT.obj [--rings 624] [--segments 160]
"""
import argparse
import importlib.util
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def load_make_bar():
    """The sample generator ``sample_meshes/make_bar.py`` as a module (it is a script)."""
    spec = importlib.util.spec_from_file_location(
        "make_bar", os.path.join(ROOT, "sample_meshes", "make_bar.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--rings", type=int, default=624)
    ap.add_argument("--segments", type=int, default=160)
    args = ap.parse_args()
    make_bar = load_make_bar()
    V, faces, uv, tfaces = make_bar.bar(rings=args.rings, segments=args.segments)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as fh:
        fh.write(make_bar.obj_text(V, faces, uv, tfaces))
    print(f"wrote {args.out}: {len(V)} vertices, {len(faces)} faces")


if __name__ == "__main__":
    main()
