"""Write a finely subdivided capped bar (about 100k vertices) for the benchmarks.

Run: python benchmarks/make_big_bar.py OUT.obj [--rings 624] [--segments 160]
"""
import argparse
import os

from srarap_cli.tasks.samples import bar, obj_text


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--rings", type=int, default=624)
    ap.add_argument("--segments", type=int, default=160)
    args = ap.parse_args()
    V, faces, uv, tfaces = bar(rings=args.rings, segments=args.segments)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as fh:
        fh.write(obj_text(V, faces, uv, tfaces))
    print(f"wrote {args.out}: {len(V)} vertices, {len(faces)} faces")


if __name__ == "__main__":
    main()
