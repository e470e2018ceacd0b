"""Every solver setting, defined once: name, type, default, allowed values, help.

The handle file's ``solver`` section, a batch manifest's ``settings``, the Click options of
``deform``/``animate``/``bench`` and the Python API's defaults are all derived from
:data:`SETTINGS`. Adding a setting means one entry here plus the code that uses it.

``stage`` says who takes the setting: ``setup`` goes to the solver's constructor (once per mesh
and constraint set), ``solve`` to each ``solve`` call, ``build`` chooses the solver itself.
"""
import functools
import math
from dataclasses import dataclass

import click

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
    minimum: float = None
    strict: bool = False
    choices: tuple = ()
    method: str = None
    metavar: str = None

    @property
    def flag(self):
        return "--" + self.name.replace("_", "-")

    def parse(self, value, error):
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

    def click_option(self, default=None):
        """The Click option; its value is None unless given (file and defaults fill in)."""
        shown = self.default if default is None else default
        text = f"{self.help} [default: {'none' if shown is None else shown}]"
        if self.kind == "choice":
            kind = click.Choice(self.choices)
        elif self.kind == "size":
            return click.option(self.flag, callback=_size_option, metavar=self.metavar,
                                help=text)
        elif self.kind == "int":
            kind = click.IntRange(min=self.minimum, min_open=self.strict)
        else:
            kind = click.FloatRange(min=self.minimum, min_open=self.strict)
            return click.option(self.flag, self.name, type=kind, metavar=self.metavar,
                                help=text, callback=_finite_option)
        return click.option(self.flag, self.name, type=kind, metavar=self.metavar, help=text)


def _finite_option(_ctx, _param, value):
    if value is not None and not math.isfinite(value):
        raise click.BadParameter("must be a finite number")
    return value


def _size_option(_ctx, _param, value):
    if value is None:
        return None
    try:
        return parse_size(value)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from None


SETTINGS = (
    Setting("alpha", "float", 0.14, "Bending weight (energy uses alpha * total area).",
            "setup", minimum=0, strict=True),
    Setting("feedback", "float", 0.2,
            "Pull of each rotor toward its previous value (paper's eps).", "setup", minimum=0),
    Setting("weights", "choice", "cotan-clamped", "Edge weights.", "setup",
            choices=WEIGHT_KINDS),
    Setting("method", "choice", "sr-linear-sym", "Local step (see README).", "setup",
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
DEFAULTS = {s.name: s.default for s in SETTINGS}
NAMES = tuple(BY_NAME)


def stage_options(options, stage):
    """The entries of ``options`` (a dict) whose setting is taken at ``stage``, with the
    per-method options left out for other methods."""
    method = options.get("method", DEFAULTS["method"])
    return {k: v for k, v in options.items()
            if BY_NAME[k].stage == stage and BY_NAME[k].method in (None, method)}


def resolve(file_settings, overrides):
    """Defaults, then a handle file's ``solver`` section, then explicit options (not None)."""
    out = dict(DEFAULTS)
    out.update(file_settings)
    out.update({k: v for k, v in overrides.items() if v is not None})
    return out


def parse_mapping(spec, name, error):
    """Validated settings from the mapping ``name`` (a handle file's ``solver``, a manifest's
    ``settings``); ``error(message)`` makes the exception raised for a bad key or value."""
    if not isinstance(spec, dict):
        raise error(f"{name} must be a mapping of {', '.join(NAMES)}")
    unknown = sorted(set(map(str, spec)) - set(NAMES))
    if unknown:
        raise error(f"unknown key {unknown[0]!r} in {name} "
                    f"(allowed: {', '.join(sorted(NAMES))})")
    return {name: BY_NAME[name].parse(value, error) for name, value in spec.items()}


def check_keywords(options, allowed_stages, where):
    """Raise TypeError naming the first keyword of ``options`` that is not a setting taken
    at one of ``allowed_stages``."""
    for name in options:
        if name not in BY_NAME or BY_NAME[name].stage not in allowed_stages:
            allowed = sorted(s.name for s in SETTINGS if s.stage in allowed_stages)
            raise TypeError(f"{where}() got an unexpected keyword {name!r} "
                            f"(solver settings: {', '.join(allowed)})")


def click_options(*, exclude=(), defaults=None):
    """Decorator: one Click option per setting (bar ``exclude``); the command receives them
    together as ``overrides``, a dict of name -> value or None. ``defaults`` replaces the
    shown default where a command has its own (``bench``'s ``tol``)."""
    chosen = [s for s in SETTINGS if s.name not in exclude]
    defaults = defaults or {}

    def decorate(func):
        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            overrides = {s.name: kwargs.pop(s.name) for s in chosen}
            return func(*args, overrides=overrides, **kwargs)

        for s in reversed(chosen):
            wrapper = s.click_option(defaults.get(s.name))(wrapper)
        return wrapper

    return decorate


def complete(result, opts):
    """Whether a solve ended as asked: converged, or ``tol`` 0 (no stopping test: run exactly
    ``max_iter`` iterations) with every iteration run."""
    return bool(result.converged) or (opts["tol"] == 0 and result.iterations >= opts["max_iter"])
