"""Every solver setting, defined once: name, type, default, allowed values, help.

The handle file's ``solver`` section, a batch manifest's ``settings``, the command line's options
(built from it in ``cli.options``) and the Python API's keywords are all derived from
:data:`SETTINGS`, and all resolve through :func:`resolve` into one frozen :class:`Settings`
that the solver reads. Adding a setting means one entry here, one field of ``Settings`` and the
code that uses it.

``stage`` says when the setting can change: ``setup`` is fixed when a solver is built (once per
mesh and constraint set), ``solve`` may change with each ``solve`` call, ``build`` chooses the
solver itself (direct or multiresolution); ``run`` settings are not the solver's but the
run's around it (commands and the one-call API), so solver classes do not take them.
"""
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from ..runtime.errors import excerpt, unknown_key
from ..runtime.numbers import spelled, whole
from ..runtime.parallel import thread_count
from ..runtime.warning_codes import parse_codes, parse_level
from .drivers import ACCEL_DRIVERS
from .local_step import METHODS
from .multires.size import AUTO_RATIO, AUTO_SIZE, AUTO_THRESHOLD, parse_size
from .operators import WEIGHT_KINDS
from .starts import STARTS, WARM_STARTS

#: How the one-solve local steps get the rotors of constrained vertices (Deformer.handle_rotors).
HANDLE_ROTORS = ("boundary", "lagged")
#: the largest integer setting (iterations, threads): past it, numpy's integers overflow
MAX_INT = 2 ** 53
#: the largest weight (alpha, feedback): at 1e308 the systems' products overflow to infinity
MAX_WEIGHT = 1e12


@dataclass(frozen=True)
class Setting:
    """One solver setting.

    Attributes
    ----------
    name : str, the Python keyword and handle-file key (the CLI flag uses dashes)
    kind : {"float", "int", "choice", "size", "level", "codes"}; ``level`` is ``strict``'s
        (true, false, off, request, all), ``codes`` a list of warning codes
    default : the value when nobody gives one (None: no limit)
    help : str, one sentence for ``--help`` and the README
    stage : {"setup", "solve", "build", "run"}
    minimum : float or int, optional lower bound; ``strict`` excludes it
    maximum : float or int, optional upper bound (included); an int setting is at most
        :data:`MAX_INT` in any case
    choices : tuple of str, for ``choice``
    method : str, optional; the local step the setting belongs to (it is ignored by others)
    metavar : str, optional, shown in ``--help``
    default_text : str, optional, what ``--help`` and the README say of a default that
        depends on the machine (``threads``)
    """

    name: str
    kind: str
    default: object
    help: str
    stage: str
    minimum: float | None = None
    maximum: float | None = None
    strict: bool = False
    choices: tuple = ()
    method: str | None = None
    metavar: str | None = None
    default_text: str | None = None
    #: whether the setting changes what a run writes (the thread count does not: the bytes
    #: are the same at any count; nor ``strict``/``allow``, which judge its warnings): what a
    #: fingerprint hashes (:mod:`srarap_cli.tasks.fingerprint`)
    decides: bool = True

    @property
    def flag(self) -> str:
        return "--" + self.name.replace("_", "-")

    def parse(self, value: Any, error: Callable[[str], Exception]) -> Any:
        """``value`` checked and converted; ``error(message)`` makes the exception to raise."""
        if self.kind == "choice":
            if value not in self.choices:
                raise error(f"{self.name} must be one of {', '.join(self.choices)}")
            return value
        if self.kind in ("level", "codes"):
            try:
                return parse_level(value) if self.kind == "level" else parse_codes(value)
            except ValueError as exc:
                raise error(f"{self.name} {exc}") from None
        if self.kind == "size":
            try:
                return parse_size(value)
            except ValueError as exc:
                raise error(f"{self.name} {exc}") from None
        if self.kind == "count":  # one reading for the option, the variable, the key
            count = thread_count(value)
            if count is None:
                raise error(f"{self.name} must be a positive whole number (digits), got "
                            f"{excerpt(repr(value))}")
            return count
        out: float
        value = spelled(value)
        if self.kind == "int":
            value = whole(value)
            if isinstance(value, bool) or not isinstance(value, int):
                raise error(f"{self.name} must be an integer")
            out = value
        else:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise error(f"{self.name} must be a number")
            try:  # an integer past 64 bits reached numpy as an object it cannot take
                finite = math.isfinite(float(value))
            except OverflowError:
                finite = False
            if not finite:
                raise error(f"{self.name} must be finite")
            out = value if isinstance(value, float) else float(value)
        if self.minimum is not None and (out <= self.minimum if self.strict
                                         else out < self.minimum):
            raise error(f"{self.name} must be {'>' if self.strict else '>='} {self.minimum:g}")
        top = MAX_INT if self.kind == "int" and self.maximum is None else self.maximum
        if top is not None and out > top:
            raise error(f"{self.name} must be <= {top:g}" if isinstance(top, float)
                        else f"{self.name} must be <= {top}")
        return out


SETTINGS = (
    Setting("alpha", "float", 0.14, "Bending weight (energy uses alpha * total area).",
            "setup", minimum=0, strict=True, maximum=MAX_WEIGHT),
    Setting("feedback", "float", 0.2,
            "Pull of each rotor toward its previous value (paper's eps).", "setup", minimum=0,
            maximum=MAX_WEIGHT),
    Setting("weights", "choice", "cotan-clamped", "Edge weights.", "setup",
            choices=WEIGHT_KINDS),
    Setting("method", "choice", "sr-linear-sym",
            "Local step: sr-linear-sym (the symmetric form of the paper's one-solve system), "
            "sr-linear (the paper's system), sr-relax (per-cell relaxation), arap (classic "
            "ARAP, no bending).", "setup",
            choices=tuple(METHODS)),
    Setting("handle_rotors", "choice", "boundary",
            "Rotors of constrained vertices: only a handle's boundary cells take theirs from "
            "their own 4x4 rows, the handle's interior joins the one sparse solve (boundary); "
            "or every constrained cell from its own row (lagged: the paper's section 6.2).",
            "setup", choices=HANDLE_ROTORS),
    Setting("sweeps", "int", 2, "Relaxation sweeps per iteration for sr-relax.", "setup",
            minimum=1, method="sr-relax"),
    Setting("max_iter", "int", 1000, "Local/global iterations at most.", "solve", minimum=0),
    Setting("tol", "float", 1e-6,
            "Stop when the relative energy change, averaged over the last 3 steps, is at most "
            "this (and the last step moved no vertex by more than sqrt(tol) of the "
            "bounding-box diagonal), or when 3 steps in a row moved no vertex beyond "
            "rounding; 0 runs max_iter steps.", "solve", minimum=0),
    Setting("time_limit", "float", None,
            "Stop (not converged) once the solve has run this many seconds.", "solve",
            minimum=0, strict=True, metavar="SECONDS"),
    Setting("accel", "choice", "anderson",
            "Outer iteration: Anderson acceleration with an energy safeguard, or none (plain "
            "local/global fixed-point iteration).", "solve", choices=tuple(ACCEL_DRIVERS)),
    Setting("start", "choice", "harmonic",
            "First iterate: the handles' rotations spread harmonically (harmonic) or identity "
            "rotors (laplacian editing).", "solve",
            choices=tuple(k for k in STARTS if k not in WARM_STARTS)),
    Setting("threads", "count", None,
            "Threads for one solve; any count gives byte-identical results (batch divides "
            "the CPUs among its workers).", "solve", minimum=1, metavar="N",
            default_text="$SRARAP_THREADS, else the CPUs this process may use",
            decides=False),
    Setting("multires", "size", "auto",
            "Solve on a simplified mesh of N vertices (or P% of them, or a fraction like 0.02) "
            "and carry the result to "
            f"the full mesh; auto = off below {AUTO_THRESHOLD} vertices, else {AUTO_SIZE} or "
            f"1/{AUTO_RATIO} of them, whichever is more (coarse meshes of {AUTO_THRESHOLD} or "
            "more vertices are solved through a coarser one again).",
            "build", metavar="N|P%|F|off|auto"),
    Setting("multires_mode", "choice", "refine",
            "With multires: refine = the transferred result starts full-resolution iterations "
            "run to tol; transfer = stop after the transfer (the paper's approximation).",
            "build", choices=("refine", "transfer")),
    Setting("strict", "level", "off",
            "Treat the warnings about the request (an implausible motion, a part moved "
            "rigidly or left at rest, data the output format drops) as errors: exit 4 "
            "listing them; all: the notes on the mesh too (needles, duplicate faces...).",
            "run", choices=("off", "request", "all"), decides=False),
    Setting("allow", "codes", (),
            "A warning code that strict accepts (repeatable; see the warning codes).",
            "run", metavar="CODE", decides=False),
)
BY_NAME = {s.name: s for s in SETTINGS}
DEFAULTS: dict[str, Any] = {s.name: s.default for s in SETTINGS}
NAMES = tuple(BY_NAME)


@dataclass(frozen=True)
class Settings:
    """Every solver setting, resolved and validated once (see :func:`resolve`), then carried
    whole from the command line, a handle file, a manifest or the Python API to the solver,
    which reads its fields (no keyword dicts in between).

    The fields are the names of :data:`SETTINGS` (checked when this module loads); their
    defaults, bounds and help live in that one table. Construction validates every field;
    parsing is idempotent (a parsed value parses to itself), so a ``Settings`` rebuilt from
    its own values, or resolved again over another layer, is unchanged.

    Examples
    --------
    >>> s = resolve({"tol": 1e-8}, {"max_iter": 50, "alpha": None}, {"multires": "2%"})
    >>> s.tol, s.max_iter, s.alpha, s.multires
    (1e-08, 50, 0.14, 0.02)
    >>> resolve(s.as_dict()) == s
    True
    """

    alpha: float
    feedback: float
    weights: str
    method: str
    handle_rotors: str
    sweeps: int
    max_iter: int
    tol: float
    time_limit: float | None
    accel: str
    start: str
    threads: int | None
    multires: int | float | str
    multires_mode: str
    strict: str
    allow: tuple[str, ...]

    def __post_init__(self) -> None:
        for name in NAMES:
            value = getattr(self, name)
            if value is not None or BY_NAME[name].default is not None:
                object.__setattr__(self, name, BY_NAME[name].parse(value, ValueError))

    def as_dict(self) -> dict[str, Any]:
        """Every setting by name (JSON-serializable: fingerprints hash it)."""
        return {name: getattr(self, name) for name in NAMES}

    def replace(self, **changes: Any) -> "Settings":
        """A copy with ``changes`` (validated; None keeps the current value)."""
        return with_keywords(self, changes, STAGES, "Settings.replace")

    def method_options(self) -> dict[str, Any]:
        """The settings that belong to this local step (the table's ``method``), by name:
        what its constructor takes besides the shared arguments."""
        return {s.name: getattr(self, s.name) for s in SETTINGS if s.method == self.method}

    def fixed_at_setup(self, other: "Settings") -> list[str]:
        """The setup and build settings in which ``other`` differs from this one: what a
        solver built with this one cannot change per solve."""
        return [s.name for s in SETTINGS if s.stage in ("setup", "build")
                and getattr(self, s.name) != getattr(other, s.name)]


STAGES = ("setup", "solve", "build", "run")


def resolve(*layers: "Mapping[str, Any] | Settings") -> Settings:
    """The one way settings are made: the defaults, then each layer in turn (later layers
    win; a None value means "not given"; the warning codes ``allow`` accepts add up). A
    layer is a mapping of setting names (a handle file's ``solver`` section, a manifest's
    ``settings``, the command line's options, the Python API's keywords, each checked by its
    reader) or a :class:`Settings`.

    Raises ValueError naming the setting for a bad value, KeyError for an unknown name.
    """
    layered = overlay(DEFAULTS, *(layer.as_dict() if isinstance(layer, Settings) else layer
                                  for layer in layers))
    return Settings(**{**DEFAULTS, **layered})  # the defaults that are None stay so


def overlay(*layers: Mapping[str, Any]) -> dict[str, Any]:
    """Setting mappings laid one over the other as :func:`resolve` lays them (later layers
    win, None is "not given", ``allow``'s codes add up), without the defaults: a manifest's
    ``defaults`` under a job's ``settings`` under the command line's options.

    Raises KeyError for an unknown name.

    Examples
    --------
    >>> overlay({"tol": 1e-6, "allow": ["needles"]}, {"tol": 1e-8, "allow": "units"})
    {'tol': 1e-08, 'allow': ('needles', 'units')}
    """
    merged: dict[str, Any] = {}
    for layer in layers:
        for name, value in layer.items():
            if name not in BY_NAME:
                raise KeyError(f"unknown setting {name!r}")
            if value is not None and BY_NAME[name].kind == "codes":  # accepted by any layer
                merged[name] = (*parse_codes(merged.get(name, ())), *parse_codes(value))
            elif value is not None:
                merged[name] = value
    return merged


def keywords(options: Mapping[str, Any], stages: tuple[str, ...],
             where: str) -> dict[str, Any]:
    """A Python caller's setting keywords, parsed: TypeError naming a keyword that is not a
    setting taken at ``stages``, ValueError naming a bad value; None values are dropped
    ("not given")."""
    for name in options:
        if name not in BY_NAME or BY_NAME[name].stage not in stages:
            allowed = sorted(s.name for s in SETTINGS if s.stage in stages)
            raise TypeError(f"{where}() got an unexpected keyword {name!r} "
                            f"(solver settings: {', '.join(allowed)})")
    return {name: BY_NAME[name].parse(value, ValueError) for name, value in options.items()
            if value is not None}


def with_keywords(base: Settings | None, options: Mapping[str, Any],
                  stages: tuple[str, ...], where: str) -> Settings:
    """``base`` (default: the defaults) with a Python caller's keywords over it (see
    :func:`keywords`), as the API's functions and classes take them; ``base`` itself, not a
    copy, where no keyword is given (one Settings carries a solve from the command line to
    the solver: it was rebuilt, and validated, five times)."""
    given = keywords(options, stages, where)
    return (base or DEFAULT_SETTINGS) if not given else resolve(base or DEFAULT_SETTINGS, given)


DEFAULT_SETTINGS = Settings(**DEFAULTS)


def parse_mapping(spec: Any, name: str, error: Callable[[str], Exception]) -> dict[str, Any]:
    """Validated settings from the mapping ``name`` (a handle file's ``solver``, a manifest's
    ``settings``); ``error(message)`` makes the exception raised for a bad key or value, so
    the message names the file and section. The values are parsed (and parse to themselves
    again when :func:`resolve` builds the Settings)."""
    if not isinstance(spec, dict):
        raise error(f"{name} must be a mapping of {', '.join(NAMES)}")
    unknown = sorted(set(map(str, spec)) - set(NAMES))
    if unknown:
        raise error(unknown_key(unknown[0], NAMES, name))
    return {key: BY_NAME[key].parse(value, error) for key, value in spec.items()}


if tuple(Settings.__dataclass_fields__) != NAMES:
    raise ImportError("Settings' fields must be the names of SETTINGS, in order")
