"""Keyframed sequences: one deformation per frame, each warm-started from the one before.

The deformer is built once. Frame ``f`` starts from the two frames before it, carried on at
their pace (positions extrapolated linearly, rotors by the same rotation again: ``R_f =
R_{f-1} R_{f-2}^{-1} R_{f-1}``), then the handles' remaining change is spread as in any warm
start (:mod:`srarap_cli.solver.starts.warm`). On a tube twisted 3 degrees a frame that took
a median of 3 iterations per frame to the stop, against 9 from the previous frame alone and
10 before the warm start spread the handles' change. The feedback term pulls every rotor
toward its previous value (paper section 6.3), and rotors are kept on the hemisphere of
their previous value.
"""
import io
import json
import time
import zipfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...io.documents import document_bytes
from ...io.handles import Constraints
from ...io.mesh.mesh import Mesh
from ...runtime.errors import InputError, excerpt
from ...runtime.warning_codes import note
from ...solver.quaternion import align_hemisphere, multiply, normalize
from ...solver.result import DeformResult
from ...solver.settings import Settings
from ..pipeline import command_solver, problem, scatter

FRAME_FIELDS = ("frame", "iterations", "membrane", "bending", "total", "converged",
                "min_rotor_dot", "seconds", "stop")


@dataclass
class FrameState:
    """What a sequence needs to continue after ``frame``: enough to resume bit for bit."""

    frame: int
    positions: np.ndarray
    rotors: np.ndarray
    rows: list = field(default_factory=list)
    fingerprint: str = ""
    #: the frame before ``frame`` (empty arrays when there is none): the next start
    #: extrapolates from both
    before: tuple = (np.zeros((0, 3)), np.zeros((0, 4)))

    def to_bytes(self) -> bytes:
        buf = io.BytesIO()
        np.savez(buf, frame=self.frame, positions=self.positions, rotors=self.rotors,
                 rows=json.dumps(self.rows), fingerprint=self.fingerprint,
                 before_positions=self.before[0], before_rotors=self.before[1])
        return buf.getvalue()

    @classmethod
    def from_file(cls, path: str) -> "FrameState":
        try:
            with np.load(path) as z:
                return cls(int(z["frame"]), z["positions"], z["rotors"],
                           json.loads(str(z["rows"])), str(z["fingerprint"]),
                           (z["before_positions"], z["before_rotors"]))
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
            raise InputError(f"{path}: unreadable resume state ({excerpt(exc, 80)}); delete it "
                             "or run without --resume") from None


class Animator:
    """Precompute once for a mesh and its (keyframed) constraints; run frames.

    Parameters
    ----------
    mesh : Mesh
    constraints : Constraints, with ``tracks`` for the keyframed groups
    opts : Settings, resolved solver settings (see :func:`srarap_cli.solver.settings.resolve`)
    cache : str, optional, folder for multiresolution coarse meshes
    name : str, the mesh's file, for error messages
    known : list of str, warnings known already (the frames' format's, keys no frame shows),
        checked and said with the mesh's and the handles'
    on_warnings : callable(list of str), optional, hears the warnings as they are known
    """

    def __init__(self, mesh: Mesh, constraints: Constraints, opts: Settings, cache: str | None = None,
                 name: str = "mesh", known: Sequence[str] = (),
                 on_warnings: Callable[[list[str]], None] | None = None) -> None:
        self.mesh = mesh
        self.constraints = constraints
        self.problem = problem(mesh, constraints, name)
        #: warnings: what the mesh checks and the solver found (e.g. mesh problems)
        self.deformer, self.warnings = command_solver(mesh, self.problem, opts, cache,
                                                      [*known, *constraints.warnings],
                                                      constraints, on_warnings, still=False)
        self.last_result: DeformResult | None = None

    def run(self, frames: int, *, max_iter: int | None = None, stop_unconverged: bool = False,
            state: FrameState | None = None,
            on_frame: Callable[[int, np.ndarray, FrameState], None] | None = None,
            fingerprint: str = "") -> FrameState | None:
        """Solve frames ``state.frame + 1`` (or 0) to ``frames - 1``, each with the solve
        settings the Animator was built with (``tol``, ``max_iter``, ``time_limit``,
        ``accel``, ``start``: the limits hold per frame); ``max_iter`` replaces the setting
        (a fixed budget per frame).

        ``on_frame(frame, positions, state)`` receives the full-mesh positions (n, 3) and the
        FrameState after each frame. With ``stop_unconverged`` the run stops at the first
        frame that did not converge, before handing it on (``stopped_at`` names it). Returns
        the last FrameState handed on (or ``state`` if none); ``last_result`` keeps the last
        frame's solver result.
        """
        self.stopped_at = None
        rows, first, before = [], 0, None
        P = R = None
        if state is not None:
            P, R, rows, first = state.positions, state.rotors, list(state.rows), state.frame + 1
            before = state.before if len(state.before[0]) else None
        for f in range(first, frames):
            start = time.perf_counter()
            frame_targets = self.constraints.targets_at(float(f))
            targets = self.problem.targets_for(frame_targets)
            options: dict[str, Any] = {}
            if P is not None:
                # the carried frames follow the targets to first order already
                options.update(start="extrapolated", initial=_carried(P, R, before))
            result = self.deformer.solve(targets, max_iter=max_iter, **options)
            self.last_result = result
            # the solver's own rotors against the previous frame's: negative means a sign flip
            dot = 1.0 if R is None else float(np.einsum("ij,ij->i", result.rotors, R).min())
            energy = result.energies()
            row = {"frame": f, "iterations": result.iterations,
                   "membrane": energy["membrane"], "bending": energy["bending"],
                   "total": energy["total"], "converged": result.converged,
                   "min_rotor_dot": dot, "seconds": time.perf_counter() - start,
                   "stop": result.stop_reason.value}
            if stop_unconverged and not result.converged:
                self.stopped_at, self.stopped_row = f, row
                break
            before = None if P is None else (P, R)
            R = result.rotors if R is None else align_hemisphere(result.rotors, R)
            P = result.positions
            rows.append(row)
            state = FrameState(f, P, R, list(rows), fingerprint,
                               before if before is not None else FrameState.before)
            if on_frame is not None:
                on_frame(f, scatter(self.mesh, self.problem, P, self.constraints, frame_targets),
                         state)
        return state


def _carried(P, R, before):
    """The start of the next frame: the last one carried on at the pace of the two last."""
    if before is None:
        return P, R
    P0, R0 = before
    step = multiply(R, R0 * _CONJUGATE)  # the rotation from the frame before to the last
    return 2 * P - P0, normalize(multiply(step, R), R)


_CONJUGATE = np.array([1.0, -1.0, -1.0, -1.0])


def run_inputs(mesh: Mesh, paths: Sequence[str]) -> list[bytes]:
    """What an animation's fingerprint (:func:`~..fingerprint.fingerprint`) hashes of its
    inputs: the mesh as read (a pipe cannot be read twice) and the files ``paths`` (a handle
    file from a pipe too: its bytes as read)."""
    arrays = (mesh.vertices, mesh.face_sizes, mesh.face_vertices)
    return ([np.ascontiguousarray(a).tobytes() for a in arrays]
            + [document_bytes(path) for path in paths])


def unreached_keys(constraints: Constraints, n_frames: int, fps: float | None,
                   path: str = "<handles>") -> list[str]:
    """A warning per keyframed group with keys after the last frame of an animation of
    ``n_frames`` frames (frames 0 .. n_frames - 1): no frame shows those poses (keys given
    in seconds at a high ``fps`` that all fall before frame 1, or ``--frames`` too few)."""
    out: list[str] = []
    names = {tuple(constraints.ids[slots]): None for slots, _, _ in constraints.tracks}
    for name, ids in constraints.groups.items():
        key = tuple(np.sort(np.asarray(ids)))
        if key in names:
            names[key] = name
    for slots, _, track in constraints.tracks:
        late = track.frames[track.frames > n_frames - 1]
        if late.size:
            name = names[tuple(constraints.ids[slots])]
            rate = f" at --fps {fps:g}" if fps else ""
            out.append(note("unreached-keys", f"{path}: group {name!r}: {late.size} keyframe(s) "
                            f"at frame(s) {', '.join(f'{f:.4g}' for f in late[:4])}{rate} come "
                            f"after the last frame, {n_frames - 1}: no frame shows them (raise "
                            "--frames, or check the keys' times and --fps)"))
    return out
