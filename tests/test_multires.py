"""Multiresolution: subset simplification, rotor transfer, the full path, cache and CLI."""
import os

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import ROOT, SHARED, needs_shared, random_rotation, torus, tube

from srarap_cli.cli import main
from srarap_cli.io.handles import load_handles
from srarap_cli.io.mesh import read_mesh
from srarap_cli.runtime import memory
from srarap_cli.solver.group_rotations import group_rotors
from srarap_cli.solver.multires import (
    MultiresDeformer,
    coarse_size,
    parse_size,
    simplify_to_subset,
)
from srarap_cli.solver.multires.cache import coarse_mesh
from srarap_cli.solver.multires.dirichlet import DirichletSolver
from srarap_cli.solver.multires.topology import topology_summary
from srarap_cli.solver.multires.transfer import spread_rotors
from srarap_cli.solver.operators import cell_graph, mesh_area
from srarap_cli.solver.quaternion import rotate, to_matrix
from srarap_cli.tasks.pipeline import problem

SPOT = os.path.join(ROOT, "sample_meshes", "spot.obj")
NOD = os.path.join(ROOT, "configs", "spot-nod.yaml")


@pytest.fixture(scope="module")
def spot():
    mesh = read_mesh(SPOT)
    return mesh.vertices, mesh.triangles()[0]


def test_coarse_vertices_are_fine_vertices_and_span_the_same_surface(spot):
    V, F = spot
    c = simplify_to_subset(V, F, 800)
    assert 700 <= len(c.vertices) <= 900
    assert np.all(np.diff(c.vertices) > 0) and c.vertices[0] >= 0 and c.vertices[-1] < len(V)
    assert c.faces.min() >= 0 and c.faces.max() == len(c.vertices) - 1
    coarse_V = V[c.vertices]
    # a triangulation of those very points: same area within a few percent, no collapsed face
    assert abs(mesh_area(coarse_V, c.faces) / mesh_area(V, F) - 1) < 0.05
    assert np.all(np.ptp(c.faces, axis=1) > 0)
    assert c.warnings == []


def open_tube():
    V, F = tube(rings=30, segments=16)
    caps = np.flatnonzero((V[:, 2] < 1e-9) | (V[:, 2] > 6 - 1e-9))
    # drop the cap triangles (those touching a cap centre): two boundary loops remain
    centres = caps[np.hypot(V[caps, 0], V[caps, 1]) < 1e-9]
    return V, F[~np.isin(F, centres).any(axis=1)]


def check_topology_kept(V, F, genus_euler, loops):
    c = simplify_to_subset(V, F, len(np.unique(F)) // 8)
    fine, coarse = topology_summary(F, len(V)), topology_summary(c.faces, len(c.vertices))
    assert fine["euler"] == coarse["euler"] == genus_euler
    assert fine["boundary_loops"] == coarse["boundary_loops"] == loops
    assert coarse["edge_manifold"] and coarse["components"] == 1
    assert len(c.vertices) < len(np.unique(F)) // 4
    assert c.warnings == []


@pytest.mark.parametrize("make, genus_euler, loops", [(torus, 0, 0), (open_tube, 0, 2)])
def test_simplification_keeps_manifoldness_genus_and_boundaries(make, genus_euler, loops):
    check_topology_kept(*make(), genus_euler, loops)


@needs_shared
@pytest.mark.parametrize("name, genus_euler, loops", [("torus.obj", 0, 0),
                                                     ("hand_lowres.obj", 1, 1)])
def test_simplification_keeps_the_topology_of_real_meshes(name, genus_euler, loops):
    mesh = read_mesh(os.path.join(SHARED, name))
    check_topology_kept(mesh.vertices, mesh.triangles()[0], genus_euler, loops)


def test_every_handle_group_keeps_a_coarse_vertex(spot):
    V, F = spot
    rng = np.random.default_rng(3)
    groups = [np.array([i]) for i in rng.choice(len(V), 12, replace=False)]
    plain = simplify_to_subset(V, F, 300)
    dropped = sum(not np.isin(g, plain.vertices).any() for g in groups)
    assert dropped >= 6  # so the protected second pass is what keeps them
    c = simplify_to_subset(V, F, 300, groups)
    assert all(np.isin(g, c.vertices).any() for g in groups)
    assert len(c.vertices) < 600
    assert topology_summary(c.faces, len(c.vertices))["euler"] == 2


def test_harmonic_transfer_reproduces_a_constant_rotor_field_exactly(spot):
    V, F = spot
    graph = cell_graph(V, F)
    known = simplify_to_subset(V, F, 500).vertices
    q = np.array([0.5, -0.5, 0.5, 0.5])
    R = spread_rotors(DirichletSolver(graph.laplacian, known), np.tile(q, (len(known), 1)))
    assert np.abs(R - q).max() < 1e-12


def test_harmonic_transfer_is_the_laplace_solution_between_known_rotors(spot):
    V, F = spot
    graph = cell_graph(V, F)
    known = simplify_to_subset(V, F, 500).vertices
    rng = np.random.default_rng(0)
    values = np.abs(rng.normal(size=(len(known), 4))) + 0.1
    raw = DirichletSolver(graph.laplacian, known).solve(values)
    free = np.setdiff1d(np.arange(len(V)), known)
    assert np.abs((graph.laplacian @ raw)[free]).max() < 1e-10 * np.abs(values).max()
    assert np.array_equal(raw[known], values)


def test_group_rotors_recover_each_groups_rotation_and_flag_collinear_groups():
    rng = np.random.default_rng(1)
    rest = rng.normal(size=(12, 3))
    rest[8:] = np.outer(np.arange(4.0), [1, 2, 3])  # a collinear group
    labels = np.repeat([0, 1, 2], 4)
    q = np.array([random_rotation(rng) for _ in range(3)])
    moved = rotate(q[labels], rest) + rng.normal(size=3)
    R, ok = group_rotors(rest, moved, labels, 3)
    sign = np.sign(np.sum(R * q[labels], axis=1, keepdims=True))
    assert np.abs(R * sign - q[labels])[:8].max() < 1e-12
    assert ok.tolist() == [True] * 8 + [False] * 4


@pytest.mark.slow
def test_rigid_motion_of_all_handles_is_reproduced_exactly_through_multires(spot):
    V = spot[0]
    c = load_handles(NOD, V)
    p = problem(read_mesh(SPOT), c)
    q = np.array([0.8, 0.2, -0.4, 0.4]) / np.linalg.norm([0.8, 0.2, -0.4, 0.4])
    t = np.array([0.3, -2.0, 1.5])
    d = MultiresDeformer(p.V, p.F, p.ids, p.labels, size=250)
    assert d.n_groups == 2 and all(np.isin(g, d.coarse.vertices).any()
                                   for g in (c.groups["hooves"], c.groups["head"]))
    r = d.solve(p.V[p.ids] @ to_matrix(q[None])[0].T + t, max_iter=200)
    expect = V @ to_matrix(q[None])[0].T + t
    diag = np.linalg.norm(np.ptp(V, axis=0))
    assert np.abs(r.positions - expect).max() < 1e-8 * diag
    assert np.abs(np.abs(r.rotors @ q) - 1).max() < 1e-9
    assert r.multires.full_energy["total"] < 1e-12


def test_multires_solve_follows_the_handles_and_logs_its_stages(spot):
    V = spot[0]
    c = load_handles(NOD, V)
    p = problem(read_mesh(SPOT), c)
    d = MultiresDeformer(p.V, p.F, p.ids, p.labels, size=1500, multires_mode="transfer")
    r = d.solve(p.targets, max_iter=400)
    assert np.array_equal(r.positions[p.ids], p.targets)
    assert set(r.multires.stages) == {"simplify", "coarse_precompute", "factor", "coarse_solve",
                             "transfer", "fine_solve"}
    assert np.allclose(np.linalg.norm(r.rotors, axis=1), 1)
    # the coarse solution is kept exactly at the coarse vertices
    coarse_positions = d.coarse_deformer.solve(p.targets[d._coarse_slots], max_iter=400).positions
    assert np.array_equal(r.positions[d.coarse.vertices], coarse_positions)


def test_cache_is_keyed_by_mesh_and_constraint_set_and_survives_corruption(spot, tmp_path):
    V, F = spot
    groups = [np.array([0, 1, 2])]
    first, hit, notes = coarse_mesh(V, F, 400, groups, str(tmp_path))
    assert not hit and notes == [] and len(os.listdir(tmp_path)) == 1
    again, hit, _ = coarse_mesh(V, F, 400, groups, str(tmp_path))
    assert hit and np.array_equal(again.vertices, first.vertices)
    assert np.array_equal(again.faces, first.faces)
    _, hit, _ = coarse_mesh(V, F, 400, [np.array([0, 1, 5])], str(tmp_path))
    assert not hit and len(os.listdir(tmp_path)) == 2
    (entry,) = [f for f in os.listdir(tmp_path) if f.endswith(".npz")][:1]
    for name in os.listdir(tmp_path):
        (tmp_path / name).write_bytes(b"not a cache entry")
    fresh, hit, notes = coarse_mesh(V, F, 400, groups, str(tmp_path))
    assert not hit and "unreadable cache entry" in notes[0]
    assert np.array_equal(fresh.vertices, first.vertices)
    assert entry


def test_multires_settings_parse_and_pick_the_direct_solve_for_small_meshes():
    assert parse_size("2%") == 0.02 and parse_size(5000) == 5000 and parse_size("OFF") == "off"
    for bad in ("0%", "100%", "3", "many", True, "-5"):
        with pytest.raises(ValueError):
            parse_size(bad)
    assert coarse_size("auto", 19_999) is None and coarse_size("auto", 800_000) == 100_000
    assert coarse_size("auto", 20_000) == 5_000 and coarse_size("auto", 40_000) == 5_000
    assert coarse_size("auto", 160_000) == 20_000
    assert coarse_size(0.02, 100_000) == 2000 and coarse_size(5000, 4000) is None
    assert coarse_size("off", 10**7) is None


def test_cli_multires_runs_caches_and_gives_identical_files(tmp_path):
    runner = CliRunner()
    args = ["deform", SPOT, NOD, "--multires", "1000", "--cache", str(tmp_path / "cache"),
            "--max-iter", "40", "--multires-mode", "transfer", "-v"]
    one = runner.invoke(main, args + ["-o", str(tmp_path / "a.obj")])
    assert one.exit_code in (0, 3), one.output
    assert "srarap: multires: " in one.output and "approximate (multires transfer" in one.output
    assert "full-resolution energy" in one.output and "at the start" in one.output
    if memory._high_water() is not None:  # -v gives each stage's peak resident memory
        assert "peak memory per stage: setup " in one.output and "transfer " in one.output
        assert "srarap: peak memory: read " in one.output and " write " in one.output
    two = runner.invoke(main, args + ["-o", str(tmp_path / "b.obj")])
    assert "coarse mesh from cache" in two.output
    assert (tmp_path / "a.obj").read_bytes() == (tmp_path / "b.obj").read_bytes()


def test_a_long_simplification_points_at_the_cache_unless_it_is_used(tmp_path, monkeypatch):
    from srarap_cli.tasks.deform import advice as deform_summary

    monkeypatch.setattr(deform_summary, "SLOW_SIMPLIFY", 0.0)  # every simplification is long here
    args = ["deform", SPOT, NOD, "--multires", "1000", "--max-iter", "2", "--keep-unconverged",
            "-v", "-o", str(tmp_path / "a.obj")]
    hint = "--cache DIR keeps the coarse mesh"
    assert hint in CliRunner().invoke(main, args).output
    cached = CliRunner().invoke(main, args + ["--cache", str(tmp_path / "c")])
    assert "srarap: multires: " in cached.output and hint not in cached.output
    quiet = CliRunner().invoke(main, args[:-3] + ["-o", str(tmp_path / "b.obj")])
    assert hint not in quiet.output  # -v only: the default output stays one summary line


def test_cli_rejects_a_bad_multires_value_in_options_and_in_the_handle_file(tmp_path):
    runner = CliRunner()
    out = runner.invoke(main, ["deform", SPOT, NOD, "--multires", "2", "-o",
                               str(tmp_path / "a.obj")])
    assert out.exit_code == 2 and "at least 4" in out.output
    handles = tmp_path / "h.yaml"
    handles.write_text("solver: {multires: lots}\ngroups: {a: {indices: [0], fixed: true}}\n")
    out = runner.invoke(main, ["deform", SPOT, str(handles), "-o", str(tmp_path / "a.obj")])
    assert out.exit_code == 4 and "multires must be off" in out.output
    assert not (tmp_path / "a.obj").exists()


@pytest.mark.parametrize("multires", ["off", "400"])
def test_region_of_interest_moves_every_handle_vertex_and_nothing_outside(tmp_path, multires):
    """Head vertices whose triangles touch no movable vertex are outside the solve; they must
    still reach their targets (they once stayed at rest)."""
    doc = tmp_path / "h.yaml"
    doc.write_text(
        "region: {sphere: {center: [0, 0.4, -0.5], radius: 0.6}}\n"
        "groups:\n"
        "  head: {sphere: {center: [0, 0.55, -0.5], radius: 0.3}, translate: [0, 0.1, 0]}\n")
    out = tmp_path / "out.obj"
    r = CliRunner().invoke(main, ["deform", SPOT, str(doc), "-o", str(out), "--multires", multires,
                                  "--max-iter", "100"])
    assert r.exit_code in (0, 3), r.output
    rest, moved = read_mesh(SPOT).vertices, read_mesh(str(out)).vertices
    c = load_handles(str(doc), rest)
    outside = np.setdiff1d(np.arange(len(rest)), c.region)
    assert np.array_equal(moved[outside], rest[outside])
    assert np.abs(moved[c.ids] - c.targets).max() < 1e-12
    assert np.abs(moved[c.region] - rest[c.region]).max() > 0.05


@pytest.mark.parametrize("method", ["sr-linear", "sr-linear-sym", "sr-relax", "arap"])
def test_every_method_runs_through_multires_and_keeps_a_translation_exact(method):
    import igl

    from srarap_cli.solver.multires.simplify import _octahedron
    V, F = igl.loop(*igl.loop(*_octahedron()))
    d = MultiresDeformer(V, F, np.arange(6), size=30, method=method)
    r = d.solve(V[:6] + [0.5, -1.0, 2.0], max_iter=20)
    assert np.abs(r.positions - (V + [0.5, -1.0, 2.0])).max() < 1e-9
    assert d.coarse_deformer.settings.method == method


def test_parts_without_handles_stay_at_rest_with_the_same_warning_as_a_direct_solve():
    import igl

    from srarap_cli.solver.multires.simplify import _octahedron
    V, F = igl.loop(*igl.loop(*igl.loop(*_octahedron())))
    n = len(V)
    V2, F2 = np.vstack([V, V + [5, 0, 0]]), np.vstack([F, F + n])
    d = MultiresDeformer(V2, F2, np.array([0, 1]), np.array([0, 1]), size=100)
    assert np.isin(np.arange(n, 2 * n), d.coarse.vertices).any()  # coarse vertices there too
    r = d.solve(V2[[0, 1]] + [[0, 0, 0], [0, 0, 0.5]], max_iter=30)
    assert np.array_equal(r.positions[n:], V2[n:])
    assert any("without a constrained vertex (258 vertices)" in w for w in d.warnings)


@pytest.mark.parametrize("mode, factorizations", [("transfer", 1), ("refine", 0)])
def test_one_fine_factorization_serves_transfer_and_final_solve_for_every_pose(
        monkeypatch, mode, factorizations):
    """transfer: one Dirichlet factorization for all poses; refine starts the fine Deformer
    (its own factorizations) from the prolonged coarse result and needs none."""
    import igl

    from srarap_cli.solver.multires import deformer as module
    from srarap_cli.solver.multires.simplify import _octahedron
    built = []
    real = module.DirichletSolver
    monkeypatch.setattr(module, "DirichletSolver", lambda *a: built.append(1) or real(*a))
    V, F = igl.loop(*igl.loop(*_octahedron()))
    d = MultiresDeformer(V, F, np.arange(6), size=30, multires_mode=mode)
    for shift in (0.5, 1.0, 1.5):
        d.solve(V[:6] + shift, max_iter=5)
    assert len(built) == factorizations


@pytest.mark.slow
def test_the_summary_counts_what_the_log_holds_and_reports_wall_seconds(tmp_path):
    """Full-resolution and coarse iterations apart, each equal to the log's rows of its kind;
    the seconds are the wall time of the solve (stages overlap and are not added)."""
    import time

    from srarap_cli.io.handles import load_handles
    from srarap_cli.io.mesh import read_mesh
    from srarap_cli.solver.settings import resolve
    from srarap_cli.tasks.pipeline import deform_mesh

    mesh = read_mesh(SPOT)
    start = time.perf_counter()
    handles = load_handles(NOD, mesh.vertices)
    _, result, _ = deform_mesh(mesh, handles, resolve(handles.solver, {"multires": 2000}))
    wall = time.perf_counter() - start
    steps = [row["step"] for row in result.log]
    coarse_rows = sum(s.startswith("coarse-") and not s.endswith("start") for s in steps)
    fine_rows = sum(not s.startswith("coarse-") and not s.endswith("start") for s in steps)
    assert result.iterations == fine_rows and result.coarse_iterations == coarse_rows
    assert result.seconds <= wall
    r = CliRunner().invoke(main, ["deform", SPOT, NOD, "--multires", "2000", "-o",
                                  str(tmp_path / "a.obj")])
    assert (f"converged in {result.iterations} full-resolution iterations "
            f"(+ {result.coarse_iterations} coarse)") in r.stderr


def test_a_mesh_that_does_not_simplify_is_solved_directly_with_a_warning():
    """A triangle soup cannot be simplified: multires must say so and give the direct solve."""
    from helpers import ends, twist

    from srarap_cli.solver.deformer import Deformer
    from srarap_cli.solver.oneshot import make_deformer
    V, F = tube()
    ids = ends(V)
    targets = twist(V, ids, 6.0, 60)
    Vs, Fs = V[F.ravel()], np.arange(F.size).reshape(-1, 3)
    held = np.flatnonzero(np.isin(F.ravel(), ids))
    moved = targets[np.searchsorted(ids, F.ravel()[held])]
    multi = make_deformer(Vs, Fs, held, multires=20)
    assert type(multi) is Deformer
    assert any("simplifies only to" in w for w in multi.warnings)
    direct = make_deformer(Vs, Fs, held, multires="off")
    assert np.array_equal(multi.solve(moved, tol=1e-8).positions,
                          direct.solve(moved, tol=1e-8).positions)


def test_a_warm_solve_calls_on_the_coarse_mesh_only_when_it_needs_many_iterations():
    """A warm start near the answer converges without a coarse step (none is even built);
    one far from it gets coarse-grid corrections once WARM_UNCORRECTED iterations passed,
    and both end where a cold solve ends."""
    from helpers import diagonal, ends, twist

    from srarap_cli.solver.multires import deformer as mr

    V, F = tube(length=6.0, rings=40, segments=16)
    ids = ends(V)
    d = MultiresDeformer(V, F, ids, size=120)
    T = twist(V, ids, 6.0, 60)
    cold = d.solve(T, tol=1e-9)
    built = []
    real = d.coarse_correction
    d.coarse_correction = lambda *a: built.append(1) or real(*a)
    near = d.solve(T, initial=(cold.positions, cold.rotors), tol=1e-9)
    assert near.converged and near.iterations <= mr.WARM_UNCORRECTED and not built
    far = d.solve(T, initial=(V, np.tile([1.0, 0, 0, 0], (len(V), 1))), tol=1e-9)
    steps = [row["step"] for row in far.log]
    assert far.converged and built and "corrected" in steps
    assert "corrected" not in steps[:mr.WARM_UNCORRECTED + 1]
    for r in (near, far):
        assert np.abs(r.positions - cold.positions).max() < 1e-4 * diagonal(V)


def _slow_full_resolution_prepare(monkeypatch, n, before):
    """Make the full-resolution Deformer's factorization (``n`` vertices) run ``before()``."""
    from srarap_cli.solver.deformer import Deformer
    real = Deformer.prepare

    def prepare(self):
        if len(self.V) == n and self._poisson is None:
            before()
        return real(self)

    monkeypatch.setattr(Deformer, "prepare", prepare)


@pytest.mark.slow
def test_the_coarse_solve_runs_while_the_full_resolution_factorization_finishes(spot,
                                                                                monkeypatch):
    import threading
    p = problem(read_mesh(SPOT), load_handles(NOD, spot[0]))
    coarse_started, waited = threading.Event(), []
    # the factorization ends only once the coarse solve has begun (or after 30 s)
    _slow_full_resolution_prepare(monkeypatch, len(p.V),
                                  lambda: waited.append(coarse_started.wait(30)))
    d = MultiresDeformer(p.V, p.F, p.ids, p.labels, size=1500)
    coarse_solve = d.coarse_deformer.solve

    def solve(*args, **kwargs):
        coarse_started.set()
        return coarse_solve(*args, **kwargs)

    d.coarse_deformer.solve = solve
    r = d.solve(p.targets)
    assert waited == [True]
    assert r.multires.stages["factor"] > 0
    monkeypatch.undo()
    # the same answer as a solver whose setup had ended before its solve began
    ref = MultiresDeformer(p.V, p.F, p.ids, p.labels, size=1500)
    assert ref.fine.poisson is not None
    assert np.array_equal(r.positions, ref.solve(p.targets).positions)


def test_a_failed_full_resolution_factorization_is_raised_by_the_solve(spot, monkeypatch):
    from srarap_cli.runtime.errors import NumericalError
    p = problem(read_mesh(SPOT), load_handles(NOD, spot[0]))

    def fail():
        raise NumericalError("the Poisson matrix is singular")

    _slow_full_resolution_prepare(monkeypatch, len(p.V), fail)
    d = MultiresDeformer(p.V, p.F, p.ids, p.labels, size=1500)
    with pytest.raises(NumericalError, match="singular"):
        d.solve(p.targets)


@pytest.mark.slow
def test_a_failed_coarse_solve_leaves_no_factorization_running(spot, monkeypatch):
    # a batch worker's next job must not share its core with the last one's leftovers
    import time

    from srarap_cli.runtime.errors import NumericalError
    p = problem(read_mesh(SPOT), load_handles(NOD, spot[0]))
    factored = []
    _slow_full_resolution_prepare(monkeypatch, len(p.V),
                                  lambda: (time.sleep(1.0), factored.append(True)))
    d = MultiresDeformer(p.V, p.F, p.ids, p.labels, size=1500)

    def fail(*args, **kwargs):
        raise NumericalError("the coarse solve produced non-finite values")

    d.coarse_deformer.solve = fail
    with pytest.raises(NumericalError, match="non-finite"):
        d.solve(p.targets)
    assert factored == [True]
