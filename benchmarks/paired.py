"""Base and head in alternating processes: a benchmark's own script run once with a git
worktree of a base revision on ``PYTHONPATH``, once with the working tree, round by round, so
that a machine that slows down midway hits both alike, and in turn first and second (ABBA:
whichever runs second in a pair ran measurably slower on this machine). Each run prints one
JSON line last."""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def alternating(script: str, argv: list[str], base: str, rounds: int) -> dict[str, list]:
    """``{"base": [...], "head": [...]}``: the JSON of ``rounds`` runs of ``script argv``
    each, base (``out/base-REV``, made if missing) and head, the first of a round the
    second of the next."""
    tree = os.path.join(ROOT, "out", f"base-{base}")
    if not os.path.isdir(tree):
        subprocess.run(["git", "-C", ROOT, "worktree", "add", "--detach", tree, base],
                       check=True, capture_output=True)
    runs: dict[str, list] = {"base": [], "head": []}
    for k in range(rounds):
        order = (("base", tree), ("head", ROOT))
        for name, path in order if k % 2 == 0 else order[::-1]:
            done = subprocess.run([sys.executable, script, *argv],
                                  env={**os.environ, "PYTHONPATH": path},
                                  capture_output=True, text=True, check=True)
            runs[name].append(json.loads(done.stdout.strip().splitlines()[-1]))
    return runs
