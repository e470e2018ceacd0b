"""The ``srarap`` command group: each subcommand in its own module, loaded on first use."""
import difflib
import importlib
import re
import sys
from collections.abc import Sequence
from typing import Any, NoReturn

import click
from click.core import Command, Context
from click.formatting import HelpFormatter

from ..runtime import descriptors, exit_codes, limits, signals, streams
from ..runtime.errors import InputError, plain
from ..runtime.lazy_modules import defer_unused_numpy_modules
from ..runtime.threads import pin_process
from ..runtime.warning_codes import LEVELS

#: name -> (module, function, one-line help shown by ``srarap --help``)
COMMANDS = {
    "deform": ("deform", "deform", "Deform MESH as rigidly as possible with smooth rotations."),
    "bench": ("bench", "bench", "Run each method on MESH + HANDLES from the same start and "
                                "compare them."),
    "animate": ("animate", "animate", "Deform MESH through the keyframes of HANDLES, writing "
                                      "one mesh per frame."),
    "compare": ("compare", "compare", "Compare meshes A and B: per vertex when they have the "
                                      "same vertices and faces, else by the distance of "
                                      "every vertex to the other surface, both ways (both "
                                      "one-sided distances are said)."),
    "batch": ("batch", "batch", "Run every job of MANIFEST (YAML/JSON); a failing job never "
                                "stops the others."),
    "info": ("info", "info", "Describe MESH and what HANDLES selects and does, without "
                             "solving."),
    "render": ("render", "render", "Render MESH to a PNG, headless."),
    "samples": ("samples", "samples", "Copy the sample meshes, handle files and goldens into "
                                      "FOLDER (three subfolders)."),
    "plot": ("render", "plot", "Plot total energy against iteration and time for one or more "
                               "deform logs (CSV/JSONL)."),
}


def _leave_now(code: int, text: str) -> NoReturn:
    click.echo(f"srarap: error: {text}", err=True)
    sys.exit(code)


def usage_hint(message: str) -> str:
    """What a usage error most likely meant: a command's name misspelt, a strictness level
    given after a space (``--strict all``: an optional value takes ``=``).

    Examples
    --------
    >>> usage_hint("No such command 'defrom'.")
    " Did you mean 'deform'?"
    >>> usage_hint("Got unexpected extra argument (all)")
    '; a level of --strict goes after an equals sign: --strict=all'
    """
    unknown = re.match(r"No such command '(.*)'", message)
    if unknown:
        close = difflib.get_close_matches(unknown[1], list(COMMANDS), n=1)
        return f" Did you mean {close[0]!r}?" if close else ""
    extra = re.match(r"Got unexpected extra arguments? \(([^)\s]+)", message)
    if extra and extra[1] in LEVELS:
        return f"; a level of --strict goes after an equals sign: --strict={extra[1]}"
    return ""


class LazyGroup(click.Group):
    """A group whose commands are imported on first use."""

    def list_commands(self, ctx: Context) -> list[str]:
        return list(COMMANDS)

    def get_command(self, ctx: Context, name: str) -> Command | None:
        if name not in COMMANDS:
            return None
        module, attr, _ = COMMANDS[name]
        # imports numpy: here, after main's BLAS thread settings, and not for ``srarap --help``;
        # with SIGINT/SIGTERM held back, since one raised inside numpy's class set-up surfaced
        # as a RuntimeError: it is raised once the imports are done
        try:
            limits.check_start()
            with signals.deferred():
                defer_unused_numpy_modules()
                found = getattr(importlib.import_module(f".{module}", __package__), attr)
            limits.start_libraries()
        except InputError as exc:
            _leave_now(exit_codes.INVALID_INPUT, str(exc))
        except (MemoryError, ImportError, OSError) as exc:
            if not (isinstance(exc, MemoryError) or limits.is_out_of_memory(exc)):
                raise
            _leave_now(exit_codes.INVALID_INPUT, "out of memory: srarap's libraries do not fit "
                       f"in the memory this process may use ({limits.memory_note()})")
        return found

    def main(self, args: Sequence[str] | None = None, prog_name: str | None = None,  # type: ignore[override]
             complete_var: str | None = None, standalone_mode: bool = True,
             **extra: Any) -> Any:
        """Click's main, with its errors as one ``srarap: error:`` line like every other
        failure (Click prints a usage block first), exit code 2 for bad usage."""
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, False, **extra)
        pin_process()
        with signals.routed():
            self._main_routed(args, prog_name, complete_var, **extra)

    def _main_routed(self, args: Sequence[str] | None, prog_name: str | None,
                     complete_var: str | None, **extra: Any) -> NoReturn:
        try:
            code = self._parse_and_invoke(args, prog_name, **extra)
        except signals.Terminated:  # before a command's own handling took over
            signals.block()
            streams.release()
            click.echo("srarap: error: terminated; no output written", err=True)
            sys.exit(exit_codes.TERMINATED)
        except click.UsageError as exc:
            where = exc.ctx.command_path if exc.ctx is not None else "srarap"
            said = plain(exc.format_message())
            click.echo(f"srarap: error: {said}{usage_hint(said)} (see '{where} --help')",
                       err=True)
            sys.exit(exc.exit_code)
        except click.ClickException as exc:
            click.echo(f"srarap: error: {plain(exc.format_message())}", err=True)
            sys.exit(exc.exit_code)
        except BrokenPipeError:  # --help or --version into a pipe whose reader went away
            descriptors.quiet_stdout()
            sys.exit(exit_codes.BROKEN_PIPE)
        except OSError as exc:  # ... or onto a full disk (> /dev/full): one line, exit 6
            click.echo(f"srarap: error: <stdout>: cannot write: {exc.strerror or exc}",
                       err=True)
            sys.exit(exit_codes.OUTPUT_ERROR)
        except (click.Abort, KeyboardInterrupt):
            signals.block()
            streams.release()
            click.echo("srarap: error: interrupted; no output written", err=True)
            sys.exit(exit_codes.INTERRUPTED)
        sys.exit(code if isinstance(code, int) else 0)

    def _parse_and_invoke(self, args: Sequence[str] | None, prog_name: str | None,
                          **extra: Any) -> Any:
        """What Click's main does before its own error handling (which prints a blank line
        on an interrupt, a second line where srarap says one): parse, invoke, return the
        exit code."""
        args = sys.argv[1:] if args is None else list(args)
        try:
            with self.make_context(prog_name or "srarap", args, **extra) as ctx:
                return self.invoke(ctx)
        except click.exceptions.Exit as exc:
            return exc.exit_code

    def format_commands(self, ctx: Context, formatter: HelpFormatter) -> None:
        with formatter.section("Commands"):
            formatter.write_dl([(name, short) for name, (_, _, short) in COMMANDS.items()])


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--debug", is_flag=True, help="Show tracebacks of failures.")
@click.version_option(package_name="srarap-cli", prog_name="srarap")
def main(debug: bool) -> None:
    """Deform triangle meshes as rigidly as possible with smooth rotations (SR-ARAP)."""
