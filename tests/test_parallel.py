"""Threads for one solve (runtime.parallel): how many a process may use, the ordered map over
mesh-cut blocks, and the contract that matters: any thread count writes the same bytes."""
import os
import subprocess
import sys

import numpy as np
import pytest
from helpers import ROOT, ends, run_cli, tube, tube_handles, twist

from srarap_cli.io.mesh import Mesh, write_mesh
from srarap_cli.runtime import parallel
from srarap_cli.runtime.errors import InputError
from srarap_cli.runtime.parallel import (
    Plan,
    at_most,
    blocks,
    cut,
    map_blocks,
    ordered_sum,
    using_threads,
    worker_share,
)
from srarap_cli.solver import linalg, one_triangle
from srarap_cli.solver.multires.simplify import simplify_to_subset
from srarap_cli.solver.oneshot import make_deformer
from srarap_cli.solver.operators import cell_graph
from srarap_cli.solver.settings import resolve
from srarap_cli.tasks.fingerprint import fingerprint


def _cgroup(tmp_path, membership, files):
    """A fake cgroup tree: ``/proc/self/cgroup`` lines and files under the root."""
    root = tmp_path / "cg"
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)
    proc = tmp_path / "proc-cgroup"
    proc.write_text(membership)
    return str(root), str(proc)


@pytest.mark.parametrize("membership, files, cap", [
    ("0::/job\n", {"job/cpu.max": "150000 100000\n"}, 2),  # 1.5 CPUs run 2 threads
    ("0::/job\n", {"job/cpu.max": "max 100000\n"}, None),  # no quota
    ("0::/a/b\n", {"a/cpu.max": "100000 100000\n", "a/b/cpu.max": "max 100000\n"}, 1),
    ("3:cpu,cpuacct:/docker/x\n", {"cpu,cpuacct/docker/x/cpu.cfs_quota_us": "200000\n",
                                   "cpu,cpuacct/docker/x/cpu.cfs_period_us": "100000\n"}, 2),
    ("3:cpu,cpuacct:/docker/x\n", {"cpu,cpuacct/docker/x/cpu.cfs_quota_us": "-1\n",
                                   "cpu,cpuacct/docker/x/cpu.cfs_period_us": "100000\n"}, None),
    ("garbage\n", {"cpu.max": "not numbers\n"}, None),
])
def test_the_cpus_a_process_may_use_follow_its_cgroup_quota(tmp_path, membership, files, cap):
    root, proc = _cgroup(tmp_path, membership, files)
    mask = len(os.sched_getaffinity(0))
    assert parallel.available_cpus(root, proc) == (mask if cap is None else min(mask, cap))


def test_the_affinity_mask_bounds_the_count(tmp_path, monkeypatch):
    root, proc = _cgroup(tmp_path, "0::/\n", {"cpu.max": "6400000 100000\n"})  # 64 CPUs
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1, 2})
    parallel.available_cpus.cache_clear()
    assert parallel.available_cpus(root, proc) == 3
    parallel.available_cpus.cache_clear()


def test_srarap_threads_sets_the_default_and_a_bad_value_is_named(monkeypatch):
    monkeypatch.setenv(parallel.ENV, "3")
    assert parallel.current_threads() == min(3, parallel.available_cpus())  # capped: below
    with using_threads(None) as count:
        assert count == min(3, parallel.available_cpus())
    for bad in ("0", "-2", "two", "1.5", "1_0", "\u0662"):
        monkeypatch.setenv(parallel.ENV, bad)
        with pytest.raises(InputError, match=parallel.ENV):
            parallel.current_threads()
    monkeypatch.delenv(parallel.ENV)
    assert parallel.current_threads() == parallel.available_cpus()


def test_a_bad_srarap_threads_is_one_line_and_exit_4(tmp_path):
    env = {**os.environ, parallel.ENV: "many"}
    done = subprocess.run([sys.executable, "-m", "srarap_cli", "deform",
                           os.path.join(ROOT, "sample_meshes", "bar.obj"),
                           os.path.join(ROOT, "configs", "bar-twist.yaml"), "-o", "o.obj"],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 4, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "SRARAP_THREADS='many'" in done.stderr
    assert not (tmp_path / "o.obj").exists()


@pytest.mark.parametrize("args", [["info", "{bar}"], ["render", "{bar}", "-o", "p.png"],
                                  ["compare", "{bar}", "{bar}"], ["samples", "s"],
                                  ["bench", "{bar}", "{twist}"]])
def test_every_command_refuses_a_bad_srarap_threads_alike(tmp_path, monkeypatch, args):
    """Issue 71: render, info and compare ignored the variable that deform refused."""
    from click.testing import CliRunner

    from srarap_cli.cli import main
    monkeypatch.setenv(parallel.ENV, "1_0")
    files = {"bar": os.path.join(ROOT, "sample_meshes", "bar.obj"),
             "twist": os.path.join(ROOT, "configs", "bar-twist.yaml")}
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(main, [a.format(**files) for a in args])
    assert r.exit_code == 4 and r.stderr == "srarap: error: SRARAP_THREADS='1_0': expected " \
        "a positive whole number of threads\n"
    assert not os.listdir(tmp_path)


def test_threads_zero_is_a_usage_error(tmp_path):
    ran = run_cli(["deform", os.path.join(ROOT, "sample_meshes", "bar.obj"),
                   os.path.join(ROOT, "configs", "bar-twist.yaml"), "-o", "o.obj",
                   "--threads", "0"], cwd=tmp_path)
    assert ran.returncode == 2 and "--threads" in ran.stderr


def test_blocks_come_back_in_order_whatever_order_they_finish_in():
    import time

    def slow_first(k):
        time.sleep(0.02 if k == 0 else 0.0)
        return k

    with using_threads(3):
        assert map_blocks(slow_first, range(7)) == list(range(7))
    assert cut(0, 4) == [] and cut(5, 2) == [slice(0, 1), slice(1, 3), slice(3, 5)]
    assert [b.stop - b.start for b in blocks(19_200)] == [9_600, 9_600]
    assert [b.stop - b.start for b in blocks(600_000, "edges")] == [262_144, 262_144, 75_712]


def test_small_work_runs_on_the_calling_thread_and_sums_alike():
    """Issue 72: below a plan's ``alone_below`` the blocks run in turn on the calling thread
    (a 19.2k-vertex coarse step was slower on two threads than on one), cut as ever, so the
    ordered sum is the same bits either way."""
    import threading

    seen = set()

    def part(rows):
        seen.add(threading.get_ident())
        return float(np.sin(np.arange(rows.start, rows.stop) * 0.37).sum())

    small, large = blocks(40_000), blocks(400_000)
    assert small.alone and not large.alone and len(small) == 3
    with using_threads(3):
        alone = ordered_sum(part, small)
        assert seen == {threading.get_ident()}
        shared = ordered_sum(part, large)
    reference = 0.0
    for rows in small:
        reference += part(rows)
    assert alone == reference
    reference = 0.0
    for rows in large:
        reference += part(rows)
    assert shared == reference


def test_a_block_that_fails_raises_in_the_caller():
    def fail(k):
        if k == 2:
            raise ValueError("block 2")
        return k

    with using_threads(2), pytest.raises(ValueError, match="block 2"):
        map_blocks(fail, range(4))


def test_a_map_inside_a_block_runs_in_that_block():
    with using_threads(2):  # a nested pool could wait on itself: it runs in turn instead
        out = map_blocks(lambda k: map_blocks(lambda j: (k, j), range(3)), range(4))
    assert out == [[(k, j) for j in range(3)] for k in range(4)]


def test_a_ceiling_caps_what_a_solve_asks_for():
    with at_most(2):
        with using_threads(8):
            assert parallel.current_threads() == 2
        with using_threads(1):
            assert parallel.current_threads() == 1


def test_a_batch_divides_the_cpus_among_its_workers(monkeypatch):
    monkeypatch.delenv(parallel.ENV, raising=False)
    monkeypatch.setattr("srarap_cli.runtime.parallel.available_cpus", lambda: 16)
    assert worker_share(1) == 16 and worker_share(4) == 4 and worker_share(32) == 1
    assert worker_share(4, asked=8) == 4 and worker_share(4, asked=2) == 2
    monkeypatch.setenv(parallel.ENV, "3")
    assert worker_share(2) == 3 and worker_share(8) == 2
    monkeypatch.setattr("srarap_cli.runtime.parallel.available_cpus", lambda: 1)
    assert worker_share(2, asked=4) == 1


def test_the_thread_count_is_not_part_of_a_jobs_fingerprint(tmp_path):
    keys = {fingerprint([b"mesh"], resolve({"tol": 1e-6, "threads": t}), {"output": "o.obj"})
            for t in (1, 2, 7)}
    assert len(keys) == 1
    assert fingerprint([b"mesh"], resolve({"tol": 1e-7}), {"output": "o.obj"}) not in keys


@pytest.fixture
def every_threshold(monkeypatch):
    """Every size threshold of the parallel code crossed by a 2,000-vertex mesh: blocks of
    96 rows, edge blocks of 500 edges, none run alone, rslab for every symmetric matrix (its
    threads). The plans are one table: a kind added there must be added here."""
    small = {"vertices": Plan(96), "values": Plan(384), "edges": Plan(500, even=False),
             "collapses": Plan(24)}
    assert small.keys() == parallel.PLANS.keys()
    monkeypatch.setattr(parallel, "PLANS", small)
    monkeypatch.setenv(one_triangle.ENV, "rslab")
    monkeypatch.setattr(linalg, "ONE_TRIANGLE_FROM", 0)


def test_the_simplification_is_the_same_at_any_thread_count(every_threshold):
    """Its collapse costs and shape checks run in blocks (of 96 edges and 24 collapses
    here): the coarse mesh must not depend on how many threads took them."""
    V, F = tube(length=8.0, rings=60, segments=32)
    coarse = []
    for threads in (1, 2, 3):
        with using_threads(threads):
            coarse.append(simplify_to_subset(V, F, 300))
    assert 250 <= len(coarse[0].vertices) <= 450
    for other in coarse[1:]:
        assert np.array_equal(other.vertices, coarse[0].vertices)
        assert np.array_equal(other.faces, coarse[0].faces)


def _solve(V, F, ids, T, threads, **options):
    with using_threads(threads):
        solver = make_deformer(V, F, ids, **options)
        return solver.solve(T)


@pytest.mark.parametrize("multires", ["off", 300])
def test_one_two_and_three_threads_give_the_same_bits(every_threshold, multires):
    length = 8.0
    V, F = tube(length=length, rings=60, segments=32)
    ids = ends(V, length)
    T = twist(V, ids, length, 100)
    T[T[:, 2] > 1] += [1.5, 0.0, -1.0]
    runs = [_solve(V, F, ids, T, k, multires=multires, tol=1e-7) for k in (1, 2, 3)]
    first = runs[0]
    assert first.converged and len(V) > 20 * parallel.PLANS["vertices"].size
    if multires != "off":
        assert first.multires is not None and first.coarse_iterations > 0
    for other in runs[1:]:
        assert other.positions.tobytes() == first.positions.tobytes()
        assert other.rotors.tobytes() == first.rotors.tobytes()
        assert [r["total"] for r in other.log] == [r["total"] for r in first.log]
        assert [r["step"] for r in other.log] == [r["step"] for r in first.log]


def test_rslab_factors_and_solves_the_same_bits_at_any_thread_count(monkeypatch):
    import scipy.sparse as sp

    monkeypatch.setenv(one_triangle.ENV, "rslab")
    n = 120  # 14,400 rows: rslab's solves run on its pool from about 1M entries times columns
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    A = (sp.kron(T, sp.identity(n)) + sp.kron(sp.identity(n), T)
         + 1e-3 * sp.identity(n * n)).tocsr()
    B = np.random.default_rng(0).normal(size=(n * n, 4))
    answers = {}
    for approximate in (False, True):
        for threads in (1, 2, 3):
            with using_threads(threads):
                answers[approximate, threads] = linalg.factor(A, symmetric=True,
                                                              approximate=approximate)(B)
        for threads in (2, 3):
            assert answers[approximate, threads].tobytes() == answers[approximate, 1].tobytes()


def _big_tube(tmp_path, length=10.0):
    """A 50k-vertex tube (above the block size, the edge block and multires's threshold) and
    a handle file twisting its top."""
    V, F = tube(length=length, rings=420, segments=120)
    assert len(V) > max(2 * parallel.PLANS["vertices"].size, 20_000)
    assert cell_graph(V, F).I.size > parallel.PLANS["edges"].size
    write_mesh(str(tmp_path / "tube.obj"), Mesh.from_arrays(V, F))
    (tmp_path / "h.yaml").write_text(tube_handles("rotate: {axis: [0, 0, 1], angle_deg: 90}",
                                                  length))


def _srarap(tmp_path, *args, env=None):
    done = subprocess.run([sys.executable, "-m", "srarap_cli", *args], cwd=tmp_path,
                          env={**os.environ, **(env or {})}, capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr


@pytest.mark.slow
def test_a_batch_of_two_workers_writes_what_deform_writes_at_any_count(tmp_path):
    """Each worker of ``batch --workers 2`` runs its share of the CPUs (and with
    ``--threads 3``, at most that share): the files are deform's at 1 and at 3 threads."""
    _big_tube(tmp_path)
    (tmp_path / "jobs.yaml").write_text(
        "jobs:\n"
        "  - {name: a, mesh: tube.obj, handles: h.yaml, output: a.obj}\n"
        "  - {name: b, mesh: tube.obj, handles: h.yaml, output: b.obj,"
        " settings: {threads: 3}}\n")
    _srarap(tmp_path, "batch", "jobs.yaml", "-o", "res", "--workers", "2", "--threads", "3")
    for threads in ("1", "3"):
        _srarap(tmp_path, "deform", "tube.obj", "h.yaml", "-o", f"t{threads}.obj", "--threads",
                threads)
    expected = (tmp_path / "t1.obj").read_bytes()
    assert (tmp_path / "t3.obj").read_bytes() == expected
    assert (tmp_path / "res" / "a.obj").read_bytes() == expected
    assert (tmp_path / "res" / "b.obj").read_bytes() == expected


@pytest.mark.slow
def test_the_command_writes_the_same_bytes_at_one_two_and_three_threads(tmp_path):
    """Real thresholds, no patching: a 50k-vertex tube is above the block size, the edge
    block and multires's threshold (two levels and corrections); rslab is asked for every
    matrix (its pool), as CI's factorization pass does."""
    _big_tube(tmp_path)
    for threads in ("1", "2", "3"):
        _srarap(tmp_path, "deform", "tube.obj", "h.yaml", "-o", f"t{threads}.ply", "--threads",
                threads, env={one_triangle.ENV: "rslab"})
    outputs = [(tmp_path / f"t{k}.ply").read_bytes() for k in (1, 2, 3)]
    assert outputs[0] == outputs[1] == outputs[2]


def test_a_thread_that_cannot_start_leaves_the_blocks_to_the_caller(monkeypatch):
    """Under ``ulimit -v`` a thread may get no stack: the blocks run on the calling thread,
    with the same answers (issue 61: "can't start new thread" was an internal error)."""
    from concurrent.futures import ThreadPoolExecutor

    def refuse(self, *args, **kwargs):
        raise RuntimeError("can't start new thread")

    with using_threads(3):
        expected = map_blocks(lambda k: k * k, range(9))
        monkeypatch.setattr(ThreadPoolExecutor, "submit", refuse)
        assert map_blocks(lambda k: k * k, range(9)) == expected


def test_a_background_stage_that_cannot_get_a_thread_runs_in_turn(monkeypatch):
    import threading

    from srarap_cli.runtime.threads import background

    def refuse(self):
        raise RuntimeError("can't start new thread")

    monkeypatch.setattr(threading.Thread, "start", refuse)
    assert background(lambda: 6 * 7)() == 42


@pytest.mark.parametrize("exc, code", [
    (RuntimeError("can't start new thread"), 4),
    (RuntimeError("Resource temporarily unavailable"), 4),  # libigl's pthread_create
    (RuntimeError("SuperLU malloc failed"), 4),
    (OSError(12, "Cannot allocate memory"), 4),
    (ImportError("libx.so: failed to map segment from shared object"), 4),  # ulimit -v
    (MemoryError(), 4),
    (BlockingIOError(11, "Resource temporarily unavailable"), 6),  # a busy pipe: not memory
])
def test_every_failure_to_get_memory_or_a_thread_is_exit_4(exc, code):
    from srarap_cli.runtime.failures import classify

    got, line = classify(exc)
    assert got == code and "\n" not in line
    if code == 4:
        assert line.startswith("out of memory")


BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
TWIST = os.path.join(ROOT, "configs", "bar-twist.yaml")


@pytest.mark.parametrize("how", ["option", "variable", "setting"])
def test_a_thread_count_past_the_cpus_is_capped_and_writes_the_same_bytes(tmp_path, how):
    """Issue 71 (THREADS-1, -2): --threads 100000 reached rslab, which started that many
    threads; a count rslab refused fell back to SuperLU with other bytes. Every count is
    capped at the CPUs where it is resolved."""
    with using_threads(10 ** 15):
        assert parallel.current_threads() == parallel.available_cpus()
    import yaml
    doc = yaml.safe_load(open(TWIST))
    if how == "setting":
        doc.setdefault("solver", {})["threads"] = 100000
    h = tmp_path / "h.yaml"
    h.write_text(yaml.safe_dump(doc))
    extra = ["--threads", "100000"] if how == "option" else []
    forced = {"SRARAP_FACTOR": "rslab"}  # rslab starts the threads it is given
    env = {**forced, parallel.ENV: "1000000000000000000"} if how == "variable" else forced
    _srarap(tmp_path, "deform", BAR, str(h), "-o", "big.obj", *extra, env=env)
    _srarap(tmp_path, "deform", BAR, TWIST, "-o", "one.obj", "--threads", "1", env=forced)
    assert (tmp_path / "big.obj").read_bytes() == (tmp_path / "one.obj").read_bytes()


@pytest.mark.parametrize("value", ["1_0", "\u0662", "1.5", "0"])
def test_one_reading_of_a_thread_count_for_the_option_the_variable_and_the_key(tmp_path, value):
    from srarap_cli.solver.settings import resolve
    r = run_cli(["deform", BAR, TWIST, "-o", tmp_path / "o.obj", "--threads", value])
    assert r.returncode == 2 and "positive whole number" in r.stderr
    with pytest.raises(ValueError, match="positive whole number"):
        resolve({"threads": value})


def test_a_capped_thread_count_is_said_once_with_v(tmp_path):
    """Issue 71: a count past the CPUs is a documented cap, said once with -v."""
    args = ["deform", os.path.join(ROOT, "sample_meshes", "bar.obj"),
            os.path.join(ROOT, "configs", "bar-twist.yaml"), "-o", "o.obj", "-v"]
    capped = run_cli([*args, "--threads", "1000000"], cwd=tmp_path)
    assert capped.returncode == 0, capped.stderr
    said = [line for line in capped.stderr.splitlines() if line.startswith("srarap: threads:")]
    assert said == [f"srarap: threads: 1000000 asked, {parallel.available_cpus()} used (the "
                    "CPUs this process may use: a count is capped there, and the results do "
                    "not depend on it)"]
    plain = run_cli([*args, "--threads", "1"], cwd=tmp_path)
    assert "srarap: threads:" not in plain.stderr
