"""What every subcommand shares: error-to-exit-code mapping and output preflight."""
import functools
import math
import os
import sys
import traceback
import warnings
from collections import Counter
from collections.abc import Callable, Sequence
from typing import Any, NoReturn

import click
import numpy as np

from ..io.mesh import FORMATS, MeshFormat
from ..runtime import descriptors, exit_codes, signals, streams
from ..runtime.commit import COMMITTED
from ..runtime.errors import OutputError
from ..runtime.failures import classify
from ..runtime.parallel import default_threads
from ..runtime.signals import Terminated


def fail(code: int, message: str) -> NoReturn:
    """One line on stderr (a file name holding a newline is printed escaped) and ``code``."""
    streams.release()
    line = message.replace("\n", "\\n").replace("\r", "\\r")
    try:
        click.echo(f"srarap: error: {line}", err=True)
    except OSError:  # stderr itself is gone: the exit code is all that can tell
        pass
    sys.exit(code)


def say(text: str) -> None:
    """One line on standard error: a summary, a warning, a table row, its control characters
    written out (:func:`printable`: a group or job name from a file can neither colour the
    terminal nor break the line). A standard error that cannot take it (a full device, a
    closed pipe) loses the line, not the run, whose outputs and exit code stand."""
    try:
        click.echo(printable(text), err=True)
    except OSError:
        pass


def printable(text: str) -> str:
    r"""``text`` for one line of a terminal: control characters (an ESC sequence, a newline)
    written out.

    Examples
    --------
    >>> printable("bar\x1b[31m\nred")
    'bar\\x1b[31m\\nred'
    """
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def write_stdout(data: bytes) -> None:
    """``data`` (bytes) to standard output; a full device or a closed pipe is an output error
    and a broken pipe respectively, never an internal one.

    A buffered write that the reader's exit cut short returns the bytes it got out instead
    of raising (``-o - | head -c 100`` said "wrote <stdout>" and exited 0): the rest is
    written again, which raises the broken pipe, and a write that takes nothing is one."""
    try:
        rest = memoryview(data)
        while rest:
            written = sys.stdout.buffer.write(rest)
            if not written:
                raise BrokenPipeError("standard output took no bytes")
            rest = rest[written:]
        sys.stdout.buffer.flush()
    except BrokenPipeError:
        raise
    except OSError as exc:
        raise OutputError(f"<stdout>: cannot write: {exc.strerror or exc}") from None


def guarded(func: Callable[..., None]) -> Callable[..., None]:
    """Turn known failures into one stderr line and a documented exit code."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        debug = click.get_current_context().find_root().params.get("debug", False)
        COMMITTED.clear()  # this command's files only (a host may run several in-process)
        try:
            # non-finite results are detected and reported as numerical failures; numpy's own
            # floating-point warnings would only add multi-line noise to stderr
            with signals.routed(), np.errstate(all="ignore"), warnings.catch_warnings():
                if not debug:  # a library's warning is its text and its source line on
                    warnings.simplefilter("ignore")  # stderr: what matters is said by srarap
                default_threads()  # a bad $SRARAP_THREADS: the same line in every command
                return func(*args, **kwargs)
        except (click.exceptions.Exit, click.ClickException, SystemExit):
            raise
        except BrokenPipeError:
            # the reader went away (``| head``): end quietly, as a process killed by SIGPIPE
            descriptors.quiet_stdout()
            sys.exit(exit_codes.BROKEN_PIPE)
        # the command's outermost boundary: anything unexpected still becomes one line and
        # exit code 1 (traceback with --debug), never a raw traceback in a user's pipeline
        except Exception as exc:  # noqa: BLE001
            if debug:
                traceback.print_exc()
            code, text = classify(exc, written())
            fail(code, text)
        except KeyboardInterrupt:
            signals.block()
            fail(exit_codes.INTERRUPTED, f"interrupted; {written()}")
        except Terminated:
            signals.block()
            fail(exit_codes.TERMINATED, f"terminated; {written()}")

    return wrapper


def written() -> str:
    """What the run had committed when a signal stopped it (an animation's resume state is
    not named, but said to be there)."""
    files = list(dict.fromkeys(p for p in COMMITTED
                               if not os.path.basename(p).startswith(".srarap-")))
    if not files:
        return "no output written"
    text = (f"stopped after writing {files[0]}" if len(files) == 1 else
            f"stopped after writing {len(files)} files ({files[0]} .. {files[-1]}), kept")
    if len(files) < len(set(COMMITTED)):
        text += "; run it again with --resume to continue"
    return text


verbosity_options = [
    click.option("-q", "--quiet", "verbosity", flag_value=0,
                 help="Errors and warnings only (no summary line)."),
    click.option("-v", "--verbose", "verbosity", flag_value=2,
                 help="Also the stages, their timings and peak memory (sampled: nothing "
                 "reset, /usr/bin/time stays true)."),
]


def with_verbosity(func: Callable[..., None]) -> Callable[..., None]:
    """``-q`` / ``-v``: the command receives ``verbosity`` 0, 1 (default) or 2."""
    for option in reversed(verbosity_options):
        func = option(func)
    return func


def report(verbosity: int | None, *, warnings: Sequence[str] = (), details: Sequence[str] = (),
           summary: str | None = None) -> None:
    """Print what a run has to say on stderr: each distinct warning once (with how many times
    it came up), the detail lines with ``-v``, the summary line unless ``-q``."""
    counts = Counter(warnings)
    for text, n in counts.items():
        say(f"srarap: warning: {text}" + (f" ({n} times)" if n > 1 else ""))
    if verbosity is not None and verbosity >= 2:
        for line in details:
            say(line)
    if summary is not None and (verbosity is None or verbosity >= 1):
        say(summary)


class EarlyWarnings:
    """Says each warning as soon as the run knows it (a CI log shows a units mistake before
    a long solve, not after it), once; :meth:`rest` gives the run's warnings not said yet,
    for the closing :func:`report`."""

    def __init__(self) -> None:
        self.said: set[str] = set()

    def __call__(self, warnings: Sequence[str]) -> None:
        for text in dict.fromkeys(warnings):
            if text not in self.said:
                self.said.add(text)
                say(f"srarap: warning: {text}")

    def rest(self, warnings: Sequence[str]) -> list[str]:
        """``warnings`` less those said already."""
        return [w for w in warnings if w not in self.said]


class FiniteFloat(click.FloatRange):
    """A float option's type: in its range and finite (Click's FloatRange lets NaN through
    every bound, and infinity through an open one)."""

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        out = super().convert(value, param, ctx)
        if out is not None and not math.isfinite(out):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        return out


class Tolerance(click.ParamType):
    """A distance tolerance: a finite number >= 0, or a percentage (``1%``: 0.01, relative
    to the diagonal). Converts to ``(value, relative)``."""

    name = "tol"

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        if isinstance(value, tuple):
            return value
        text = str(value).strip()
        percent = text.endswith("%")
        try:
            number = float(text.removesuffix("%").strip())
        except ValueError:
            self.fail(f"{value!r} is neither a number >= 0 nor a percentage (1%)", param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        if number < 0:
            self.fail(f"{value!r} is below 0", param, ctx)
        return (number / 100, True) if percent else (number, False)


class MeshFormatType(click.ParamType):
    """A registered mesh format's name, as its :class:`~srarap_cli.io.mesh.MeshFormat`;
    the choices are read from the format table when used, so a format registered after
    this module was imported is one too."""

    name = "format"

    def get_metavar(self, param: click.Parameter, ctx: click.Context) -> str:
        return "[" + "|".join(FORMATS) + "]"

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> MeshFormat:
        if isinstance(value, MeshFormat):
            return value
        fmt = FORMATS.get(str(value).lower())
        if fmt is None:
            self.fail(f"{value!r} is not one of {', '.join(map(repr, FORMATS))}", param, ctx)
        return fmt


input_format_option = click.option(
    "--input-format", type=MeshFormatType(),
    help="Format of a mesh given as '-' (standard input). [default: told from its bytes]")


def pose_options(func: Callable[..., None]) -> Callable[..., None]:
    """``--fps`` and ``--frame``: which pose of a keyframed handle file a single solve takes."""
    func = click.option("--frame", type=FiniteFloat(min=0), default=0.0, show_default=True,
                        help="Pose of keyframed groups at this frame (fractional frames "
                             "interpolate).")(func)
    return click.option("--fps", type=FiniteFloat(min=0, min_open=True),
                        help="Frames per second, for keyframes given by time (needed with "
                             "--frame unless every key gives its frame).")(func)


cache_option = click.option("--cache", type=click.Path(file_okay=False),
                            help="Folder keeping simplified meshes between runs (multires).")
