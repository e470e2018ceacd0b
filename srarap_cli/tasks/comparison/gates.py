"""What a result must satisfy against its golden, quantity by quantity: positions (the largest
distance, or the fraction of vertices beyond ``tol``), the 95th and 99th percentile
distances, the energy (relative to the golden's recorded one), the iterations (at most N, or
within k of the golden's record) and the seconds (a budget). One parser for a manifest's
``expect``, ``compare``'s options and the pytest fixture's keywords, and one judge that lists
every gate that fails, not only the first."""
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from typing import Any

from ...runtime.errors import excerpt, unknown_key
from ...runtime.numbers import spelled, whole
from .compare import ALIGNMENTS, Comparison, motion_text


@dataclass(frozen=True)
class Expect:
    """The gates of one golden.

    Attributes
    ----------
    golden : str, the golden mesh's path
    tol : float >= 0, the largest distance a vertex may have (model units, or a fraction of
        the golden's bounding-box diagonal with ``relative``)
    relative : bool
    beyond_tol : float in [0, 1], the fraction of vertices allowed beyond ``tol`` (0: every
        vertex within it, the largest distance is the gate)
    p95, p99 : float or None, the most the 95th / 99th percentile distance may be (the unit
        of ``tol``)
    energy_rtol : float or None, the most the energy may differ from the golden's recorded
        energy, relative to it
    max_iterations : int or None, the most iterations the solve may take
    iterations_within : int or None, the most the iterations may differ from the golden's
        recorded count, either way
    max_seconds : float or None, a budget for the job's seconds (wall time: noisy, give it
        room)
    align : {"none", "rigid"}, move the result by the rigid motion that brings it closest to
        the golden before measuring (vertex i of one is vertex i of the other)
    """

    golden: str
    tol: float = 0.0
    relative: bool = False
    beyond_tol: float = 0.0
    p95: float | None = None
    p99: float | None = None
    energy_rtol: float | None = None
    max_iterations: int | None = None
    iterations_within: int | None = None
    max_seconds: float | None = None
    align: str = "none"

    @property
    def needs_record(self) -> bool:
        """Whether a gate compares with the golden's recorded figures."""
        return self.energy_rtol is not None or self.iterations_within is not None


#: every key ``expect`` takes, in the order the docs list them
EXPECT_KEYS = tuple(f.name for f in fields(Expect))
#: the gates' keys (all but ``golden``), as the fixture's keywords and ``compare``'s options
GATE_KEYS = EXPECT_KEYS[1:]


@dataclass(frozen=True)
class Observed:
    """What a run gives beside its mesh: ``iterations``, ``energy``, ``seconds`` (None where
    unknown: a mesh that no solve made)."""

    iterations: int | None = None
    energy: float | None = None
    seconds: float | None = None


def parse_expect(spec: Any, fail: Callable[[str], Exception], golden: str | None = None
                 ) -> Expect:
    """An :class:`Expect` from a mapping (a manifest's ``expect``, keywords): every key
    checked by name and value; ``fail(message)`` makes the exception for a bad one.
    ``golden``: the golden's path as resolved by the caller (relative to the manifest).

    Examples
    --------
    >>> parse_expect({"golden": "g.obj", "tol": 1e-6, "energy_rtol": 0.01}, ValueError)
    ... # doctest: +ELLIPSIS
    Expect(golden='g.obj', tol=1e-06, relative=False, beyond_tol=0.0, p95=None, ...)
    >>> parse_expect({"golden": "g.obj", "tol": 1, "max_iteration": 3}, ValueError)
    Traceback (most recent call last):
    ...
    ValueError: unknown key 'max_iteration' in expect; did you mean 'max_iterations'? \
(allowed: align, beyond_tol, energy_rtol, golden, iterations_within, max_iterations, \
max_seconds, p95, p99, relative, tol)
    """
    if not isinstance(spec, Mapping):
        raise fail("expect must be a mapping of golden and tolerances")
    for key in spec:
        if str(key) not in EXPECT_KEYS or not isinstance(key, str):
            raise fail(unknown_key(key, EXPECT_KEYS, "expect"))
    if "golden" not in spec or golden is None and not isinstance(spec["golden"], str):
        raise fail("expect needs a golden mesh (golden: PATH)")
    values: dict[str, Any] = {"golden": golden if golden is not None else spec["golden"]}
    for key in GATE_KEYS:
        if key in spec and spec[key] is not None:
            values[key] = _CHECKS[key](key, spec[key], fail)
    if isinstance(spec.get("tol"), str) and spec["tol"].strip().endswith("%"):
        if spec.get("relative") is False:
            raise fail("expect: tol as a percentage is of the diagonal: relative cannot be "
                       "false")
        values.update(tol=values["tol"] / 100, relative=True)
    return Expect(**values)


def _number(key, value, fail, upper=math.inf):
    if key == "tol" and isinstance(value, str) and value.strip().endswith("%"):
        value = value.strip()[:-1]  # a percentage of the diagonal (parse_expect scales it)
    value = spelled(value)  # YAML reads 1e-6 (no dot) as text
    try:
        good = not isinstance(value, bool) and isinstance(value, (int, float)) \
            and math.isfinite(value) and 0 <= value <= upper
    except OverflowError:  # an integer past a float's range
        good = False
    if not good:
        bound = f" and <= {upper:g}" if upper < math.inf else ""
        raise fail(f"expect: {key} must be a finite number >= 0{bound}, got "
                   f"{excerpt(repr(value))}")
    return float(value)


def _count(key, value, fail):
    value = whole(spelled(value))
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 2 ** 53:
        raise fail(f"expect: {key} must be a whole number >= 0, got {excerpt(repr(value))}")
    return value


def _flag(key, value, fail):
    if not isinstance(value, bool):
        raise fail(f"expect: {key} must be true or false, got {value!r}")
    return value


def _align(key, value, fail):
    if value not in ALIGNMENTS:
        raise fail(f"expect: {key} must be one of {', '.join(ALIGNMENTS)}, got {value!r}")
    return value


_CHECKS: dict[str, Callable[..., Any]] = {
    "tol": _number, "relative": _flag, "beyond_tol": lambda k, v, f: _number(k, v, f, 1.0),
    "p95": _number, "p99": _number, "energy_rtol": _number, "max_iterations": _count,
    "iterations_within": _count, "max_seconds": _number, "align": _align}


def judge(found: Comparison, expect: Expect, run: Observed,
          record: Mapping[str, Any] | None, unit: str = "",
          golden_name: str = "golden", obtained_name: str = "output") -> list[str]:
    """Every gate of ``expect`` that ``found`` (scaled as ``expect.relative`` says) and
    ``run`` fail, one phrase each with its numbers and units; empty when all pass.
    ``record``: the golden's recorded ``energy`` and ``iterations`` (None: none kept);
    ``unit``: how a relative distance is named; the names of mesh A and B in the phrases."""
    failed = []
    verdict = found.verdict(expect.tol)
    if expect.beyond_tol == 0 and not verdict.within:
        failed.append(f"max distance {found.max:.3g} > tol {expect.tol:g}{unit}"
                      f"{_where(found, golden_name, obtained_name)}; "
                      f"{100 * verdict.beyond:.3g}% of the vertices beyond tol")
    elif verdict.beyond > expect.beyond_tol:
        failed.append(f"{100 * verdict.beyond:.3g}% of the vertices beyond tol "
                      f"{expect.tol:g}{unit} > beyond_tol {100 * expect.beyond_tol:.3g}%"
                      f"{_where(found, golden_name, obtained_name)}")
    for key in ("p95", "p99"):
        limit, value = getattr(expect, key), getattr(found, key)
        if limit is not None and value > limit:
            failed.append(f"{key} distance {value:.3g} > {key} {limit:g}{unit}")
    failed += _run_gates(expect, run, record or {})
    return failed


def _where(found, golden_name, obtained_name):
    far = found.farthest
    if far is None:
        return ""
    return (f" at vertex {far['vertex']} of the "
            f"{golden_name if far['mesh'] == 'a' else obtained_name} mesh")


def _run_gates(expect, run, record):
    failed = []
    if expect.energy_rtol is not None:
        failed += _energy_gate(expect.energy_rtol, run.energy, record.get("energy"))
    if expect.max_iterations is not None:
        if run.iterations is None:
            failed.append("iterations: this result has none to gate (no solve made it)")
        elif run.iterations > expect.max_iterations:
            failed.append(f"iterations {run.iterations} > max_iterations "
                          f"{expect.max_iterations}")
    if expect.iterations_within is not None:
        failed += _iterations_gate(expect.iterations_within, run.iterations,
                                   record.get("iterations"))
    if expect.max_seconds is not None and run.seconds is not None \
            and run.seconds > expect.max_seconds:
        failed.append(f"seconds {run.seconds:.3g} > max_seconds {expect.max_seconds:g} "
                      "(wall time: noisy)")
    return failed


def _energy_gate(rtol, energy, golden):
    if energy is None:
        return ["energy: this result has none to gate (no solve made it)"]
    if golden is None:
        return ["energy: the golden has no recorded energy (--update-goldens records it)"]
    off = abs(energy - golden) / abs(golden) if golden else (0.0 if energy == 0 else math.inf)
    if off <= rtol:
        return []
    return [f"energy {energy:.6g} is {100 * off:.3g}% from the golden's {golden:.6g} > "
            f"energy_rtol {100 * rtol:.3g}%"]


def _iterations_gate(within, iterations, golden):
    if iterations is None:
        return ["iterations: this result has none to gate (no solve made it)"]
    if golden is None:
        return ["iterations: the golden has no recorded count (--update-goldens records it)"]
    if abs(iterations - golden) <= within:
        return []
    return [f"iterations {iterations}, the golden's {golden} ({iterations - golden:+d}) > "
            f"iterations_within {within}"]


def verdict_line(found: Comparison, expect: Expect, failed: list[str], unit: str = "",
                 names: tuple[str, str] = ("A", "B")) -> str:
    """The one-line verdict ``compare`` prints and the pytest fixture fails with: the
    positions within or BEYOND tol, the distances with their unit, where the farthest vertex
    is and the fraction beyond tol (when beyond), every other failing gate (``failed``, as
    :func:`judge` gives them), the one-sided distances and the alignment."""
    verdict = found.verdict(expect.tol)
    beyond = (not verdict.within if expect.beyond_tol == 0
              else verdict.beyond > expect.beyond_tol)
    text = (f"{'BEYOND' if beyond else 'within'} tol {expect.tol:g}{unit} ({found.mode}): max "
            f"{found.max:.6g}, mean {found.mean:.6g}, rms {found.rms:.6g}, p95 {found.p95:.3g}, "
            f"p99 {found.p99:.3g}{unit}")
    far = found.farthest
    if beyond and far is not None:
        at = ", ".join(f"{x:.4g}" for x in far["position"])
        who = names[0] if far["mesh"] == "a" else names[1]
        text += (f"; farthest: {who}'s vertex {far['vertex']} at ({at}); "
                 f"{100 * verdict.beyond:.3g}% of the vertices beyond tol")
    text += "".join(f"; {gate}" for gate in failed if not gate.startswith(_POSITION_GATES))
    if found.one_sided is not None:
        ab, ba = found.one_sided["a_to_b"], found.one_sided["b_to_a"]
        text += (f"; {names[0]} to {names[1]}: max {ab['max']:.3g}, {names[1]} to {names[0]}: "
                 f"max {ba['max']:.3g} (at every vertex)")
    if found.motion is not None:
        text += f"; {names[1]} aligned first: {motion_text(found.motion)}"
    return text


#: how the positions gate's phrases begin: the verdict line says them its own way
_POSITION_GATES = ("max distance ", )
