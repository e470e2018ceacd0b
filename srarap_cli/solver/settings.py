"""Every solver setting, defined once: name, type, default, allowed values, help.

The handle file's ``solver`` section, a batch manifest's ``settings``, the command line's options
(built from it in ``cli.options``) and the Python API's defaults are all derived from
:data:`SETTINGS`. Adding a setting means one entry here plus the code that uses it.

``stage`` says who takes the setting: ``setup`` goes to the solver's constructor (once per mesh
and constraint set), ``solve`` to each ``solve`` call, ``build`` chooses the solver itself.
"""
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .local_step import METHODS
from .multires.size import AUTO_RATIO, AUTO_SIZE, AUTO_THRESHOLD, parse_size

#: Edge weights of the Laplacian and the bending term (see :func:`operators.cell_graph`).
WEIGHT_KINDS = ("cotan", "cotan-clamped", "uniform")
#: How the one-solve local steps get the rotors of constrained vertices (Deformer.handle_rotors).
HANDLE_ROTORS = ("boundary", "lagged")


@dataclass(frozen=True)
class Setting:
    """One solver setting.

    Attributes
    ----------
    name : str, the Python keyword and handle-file key (the CLI flag uses dashes)
    kind : {"float", "int", "choice", "size"}
    default : the value when nobody gives one (None: no limit)
    help : str, one sentence for ``--help`` and the README
    stage : {"setup", "solve", "build"}
    minimum : float or int, optional lower bound; ``strict`` excludes it
    choices : tuple of str, for ``choice``
    method : str, optional; the local step the setting belongs to (it is ignored by others)
    metavar : str, optional, shown in ``--help``
    """

    name: str
    kind: str
    default: object
    help: str
    stage: str
    minimum: float | None = None
    strict: bool = False
    choices: tuple = ()
    method: str | None = None
    metavar: str | None = None

    @property
    def flag(self) -> str:
        return "--" + self.name.replace("_", "-")

    def parse(self, value: Any, error: Callable[[str], Exception]) -> Any:
        """``value`` checked and converted; ``error(message)`` makes the exception to raise."""
        if self.kind == "choice":
            if value not in self.choices:
                raise error(f"{self.name} must be one of {', '.join(self.choices)}")
            return value
        if self.kind == "size":
            try:
                return parse_size(value)
            except ValueError as exc:
                raise error(f"{self.name} {exc}") from None
        out: float
        if self.kind == "int":
            if isinstance(value, bool) or not isinstance(value, int):
                raise error(f"{self.name} must be an integer")
            out = value
        else:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise error(f"{self.name} must be a number")
            out = value  # as written: batch fingerprints hash the settings' JSON
            if not math.isfinite(out):
                raise error(f"{self.name} must be finite")
        if self.minimum is not None and (out <= self.minimum if self.strict
                                         else out < self.minimum):
            raise error(f"{self.name} must be {'>' if self.strict else '>='} {self.minimum:g}")
        return out


SETTINGS = (
    Setting("alpha", "float", 0.14, "Bending weight (energy uses alpha * total area).",
            "setup", minimum=0, strict=True),
    Setting("feedback", "float", 0.2,
            "Pull of each rotor toward its previous value (paper's eps).", "setup", minimum=0),
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
            "bounding-box diagonal).", "solve", minimum=0),
    Setting("time_limit", "float", None,
            "Stop (not converged) once the solve has run this many seconds.", "solve",
            minimum=0, strict=True, metavar="SECONDS"),
    Setting("accel", "choice", "anderson",
            "Outer iteration: Anderson acceleration with an energy safeguard, or none (plain "
            "local/global fixed-point iteration).", "solve", choices=("anderson", "none")),
    Setting("start", "choice", "harmonic",
            "First iterate: the handles' rotations spread harmonically (harmonic) or identity "
            "rotors (laplacian editing).", "solve", choices=("harmonic", "laplacian")),
    Setting("multires", "size", "auto",
            "Solve on a simplified mesh of N vertices (or P% of them) and carry the result to "
            f"the full mesh; auto = off below {AUTO_THRESHOLD} vertices, else {AUTO_SIZE} or "
            f"1/{AUTO_RATIO} of them, whichever is more (coarse meshes of {AUTO_THRESHOLD} or "
            "more vertices are solved through a coarser one again).",
            "build", metavar="N|P%|off|auto"),
    Setting("multires_mode", "choice", "refine",
            "With multires: refine = the transferred result starts full-resolution iterations "
            "run to tol; transfer = stop after the transfer (the paper's approximation).",
            "build", choices=("refine", "transfer")),
)
BY_NAME = {s.name: s for s in SETTINGS}
DEFAULTS: dict[str, Any] = {s.name: s.default for s in SETTINGS}
NAMES = tuple(BY_NAME)


@dataclass(frozen=True)
class Settings:
    """Every solver setting, resolved and validated once (see :func:`resolve`), then carried
    unchanged from the command line or the API to the solver.

    The fields are the names of :data:`SETTINGS` (checked when this module loads); their
    defaults, bounds and help live in that one table.

    Examples
    --------
    >>> s = resolve({"tol": 1e-8}, {"max_iter": 50, "alpha": None})
    >>> s.tol, s.max_iter, s.alpha
    (1e-08, 50, 0.14)
    >>> sorted(s.stage("solve"))
    ['accel', 'max_iter', 'start', 'time_limit', 'tol']
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
    multires: int | float | str
    multires_mode: str

    def __post_init__(self):
        for name in NAMES:
            value = getattr(self, name)
            if value is not None or BY_NAME[name].default is not None:
                object.__setattr__(self, name, BY_NAME[name].parse(value, _bad_setting))

    def stage(self, *stages: str) -> dict:
        """The settings taken at ``stages`` (``setup``, ``solve``, ``build``) as keywords, less
        the per-method settings of other local steps."""
        return {s.name: getattr(self, s.name) for s in SETTINGS
                if s.stage in stages and s.method in (None, self.method)}

    def as_dict(self) -> dict:
        """Every setting by name (JSON-serializable: fingerprints hash it)."""
        return {name: getattr(self, name) for name in NAMES}

    def replace(self, **changes: Any) -> "Settings":
        """A copy with ``changes`` (validated; None keeps the current value)."""
        check_keywords(changes, ("setup", "solve", "build"), "Settings.replace")
        return Settings(**{**self.as_dict(),
                           **{k: v for k, v in changes.items() if v is not None}})


def _bad_setting(message):
    return ValueError(message)


def resolve(file_settings: dict, overrides: dict) -> Settings:
    """Defaults, then a handle file's ``solver`` section, then explicit options (not None)."""
    return Settings(**{**DEFAULTS, **file_settings,
                       **{k: v for k, v in overrides.items() if v is not None}})


DEFAULT_SETTINGS = Settings(**DEFAULTS)


def parse_mapping(spec: Any, name: str, error: Callable[[str], Exception]) -> dict[str, Any]:
    """Validated settings from the mapping ``name`` (a handle file's ``solver``, a manifest's
    ``settings``); ``error(message)`` makes the exception raised for a bad key or value."""
    if not isinstance(spec, dict):
        raise error(f"{name} must be a mapping of {', '.join(NAMES)}")
    unknown = sorted(set(map(str, spec)) - set(NAMES))
    if unknown:
        raise error(f"unknown key {unknown[0]!r} in {name} "
                    f"(allowed: {', '.join(sorted(NAMES))})")
    return {name: BY_NAME[name].parse(value, error) for name, value in spec.items()}


def check_keywords(options: dict[str, Any], allowed_stages: tuple[str, ...], where: str) -> None:
    """Raise TypeError naming the first keyword of ``options`` that is not a setting taken
    at one of ``allowed_stages``."""
    for name in options:
        if name not in BY_NAME or BY_NAME[name].stage not in allowed_stages:
            allowed = sorted(s.name for s in SETTINGS if s.stage in allowed_stages)
            raise TypeError(f"{where}() got an unexpected keyword {name!r} "
                            f"(solver settings: {', '.join(allowed)})")


def complete(result: Any, opts: "Settings") -> bool:
    """Whether a solve ended as asked: converged; or ``tol`` 0 (no stopping test: run exactly
    ``max_iter`` iterations) with every iteration run; or the approximate mode (transfer),
    whose coarse solve converged (the full-resolution shape is never iterated there)."""
    if result.approximate:
        return bool(result.coarse_converged) or (
            opts.tol == 0 and result.coarse_iterations >= opts.max_iter)
    return bool(result.converged) or (opts.tol == 0 and result.iterations >= opts.max_iter)


if tuple(Settings.__dataclass_fields__) != NAMES:
    raise ImportError("Settings' fields must be the names of SETTINGS, in order")
