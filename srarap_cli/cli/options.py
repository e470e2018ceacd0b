"""Click options built from the one settings table (:data:`srarap_cli.solver.settings.SETTINGS`).

The solver's settings module knows nothing of Click; this is the only place the table becomes
command-line flags.
"""
import functools
from collections.abc import Callable, Mapping, Sequence
from typing import Any, TypeVar

import click

from ..runtime.parallel import thread_count
from ..runtime.warning_codes import CODES, REQUEST
from ..solver.multires.size import parse_size
from ..solver.settings import MAX_INT, SETTINGS, Setting
from .common import FiniteFloat

#: a command function a decorator wraps
F = TypeVar("F", bound=Callable[..., Any])


def setting_option(setting: Setting, default: object = None) -> Callable[[F], F]:
    """The Click option of one setting; its value is None unless given (the handle file and
    the defaults fill in). ``default`` replaces the shown default where a command has its own."""
    shown = setting.default if default is None else default
    shown = setting.default_text if shown is None and setting.default_text else shown
    text = f"{setting.help} [default: {'none' if shown is None else shown}]"
    if setting.kind == "level":  # a bare --strict is made --strict=request by StrictCommand
        return click.option(setting.flag, setting.name, type=click.Choice(setting.choices),
                            metavar="[=all]", help=f"{setting.help} [default: off]")
    if setting.kind == "codes":
        return click.option(setting.flag, setting.name, multiple=True, metavar=setting.metavar,
                            type=click.Choice(tuple(CODES)), show_choices=False,
                            callback=lambda _c, _p, v: v or None, help=setting.help)
    kind: click.ParamType
    if setting.kind == "choice":
        kind = click.Choice(setting.choices)
    elif setting.kind == "size":
        return click.option(setting.flag, callback=_size_option, metavar=setting.metavar,
                            help=text)
    elif setting.kind == "count":
        kind = ThreadCount()
    elif setting.kind == "int":
        low = None if setting.minimum is None else int(setting.minimum)
        kind = click.IntRange(min=low, min_open=setting.strict,
                              max=int(setting.maximum or MAX_INT))
    else:
        kind = FiniteFloat(min=setting.minimum, min_open=setting.strict, max=setting.maximum)
    return click.option(setting.flag, setting.name, type=kind, metavar=setting.metavar,
                        help=text)


class ThreadCount(click.ParamType):
    """A positive whole number in ASCII digits (``1_0`` and ``٢`` are refused, as in
    ``$SRARAP_THREADS`` and a ``threads`` setting)."""

    name = "integer"

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        count = thread_count(value)
        if count is None:
            self.fail(f"{value!r} is not a positive whole number", param, ctx)
        return count


class StrictCommand(click.Command):
    """A command with a ``--strict[=all]`` option: a bare ``--strict`` means
    ``--strict=request`` (an option whose value may be left out would take the next
    argument, the mesh's path, as its value)."""

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        return super().parse_args(ctx, bare_strict(args))


def bare_strict(args: Sequence[str]) -> list[str]:
    """``args`` with each bare ``--strict`` before ``--`` spelled ``--strict=request``."""
    out = list(args)
    end = out.index("--") if "--" in out else len(out)
    return [f"--strict={REQUEST}" if a == "--strict" and i < end else a
            for i, a in enumerate(out)]


def _size_option(_ctx, _param, value):
    if value is None:
        return None
    try:
        return parse_size(value)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from None


def settings_options(*, exclude: Sequence[str] = (),
                     defaults: Mapping[str, object] | None = None) -> Callable[[F], F]:
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
            wrapper = setting_option(s, defaults.get(s.name))(wrapper)
        return wrapper

    return decorate


def markdown_table() -> str:
    """The solver settings as the README's Markdown table (a test keeps the two equal)."""
    rows = ["| option | default | meaning |", "|---|---|---|"]
    for s in SETTINGS:
        default = (s.default_text or "none" if s.default is None else "none" if s.default == ()
                   else f"`{s.default}`")
        flag = {"level": f"{s.flag}[=all]", "codes": f"{s.flag} CODE"}.get(s.kind, s.flag)
        rows.append(f"| `{flag}` | {default} | {s.help} |")
    return "\n".join(rows) + "\n"
