"""Click options built from the one settings table (:data:`srarap_cli.solver.settings.SETTINGS`).

The solver's settings module knows nothing of Click; this is the only place the table becomes
command-line flags.
"""
import functools
from collections.abc import Callable, Mapping, Sequence
from typing import Any, TypeVar

import click

from ..solver.multires.size import parse_size
from ..solver.settings import SETTINGS, Setting
from .common import FiniteFloat

#: a command function a decorator wraps
F = TypeVar("F", bound=Callable[..., Any])


def setting_option(setting: Setting, default: object = None) -> Callable[[F], F]:
    """The Click option of one setting; its value is None unless given (the handle file and
    the defaults fill in). ``default`` replaces the shown default where a command has its own."""
    shown = setting.default if default is None else default
    shown = setting.default_text if shown is None and setting.default_text else shown
    text = f"{setting.help} [default: {'none' if shown is None else shown}]"
    if setting.kind == "flag":
        return click.option(setting.flag, setting.name, is_flag=True, default=None,
                            help=f"{setting.help} [default: off]")
    kind: click.ParamType
    if setting.kind == "choice":
        kind = click.Choice(setting.choices)
    elif setting.kind == "size":
        return click.option(setting.flag, callback=_size_option, metavar=setting.metavar,
                            help=text)
    elif setting.kind == "int":
        low = None if setting.minimum is None else int(setting.minimum)
        kind = click.IntRange(min=low, min_open=setting.strict)
    else:
        kind = FiniteFloat(min=setting.minimum, min_open=setting.strict)
    return click.option(setting.flag, setting.name, type=kind, metavar=setting.metavar,
                        help=text)


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
        default = (s.default_text or "none" if s.default is None else "off" if s.kind == "flag"
                   else f"`{s.default}`")
        rows.append(f"| `{s.flag}` | {default} | {s.help} |")
    return "\n".join(rows) + "\n"
