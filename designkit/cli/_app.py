"""The typer application and what every command shares.

Commands live in sibling modules (one per topic) and import their library
layer inside the command body, so that ``designkit --help`` and a table query
never import scikit-learn, matplotlib or dask.

Bad input anywhere below (``ValueError``, including designkit's ``InputError``,
and ``OSError`` for unreadable files) is printed as one line on stderr and
exits with status 2, never as a traceback. Anything else is a bug: one line
naming what failed and where to report it, exit status 1, and the traceback
only with ``designkit --debug ...``. With ``--json`` on the command, errors are
JSON on stdout too (``{"error": {...}}``), so a script reads one format.
"""

from __future__ import annotations

import json
import sys
from typing import Any

import typer
from typer.core import TyperCommand, TyperGroup

from .._io import jsonable

EXIT_BAD_INPUT = 2
EXIT_BUG = 1
EXIT_INTERRUPTED = 130
ISSUES_URL = "https://github.com/designkit-dev/designkit/issues"
_DEBUG_KEY = "designkit.debug"


def wants_json(args: Any) -> bool:
    """Whether the command line asks for JSON (``--json``, ``--format json``, ``-f json``): errors then come
    as JSON on stdout too."""
    args = [str(a) for a in (args or ())]
    return any(a == "--json" or a.lower() in ("--format=json", "-fjson")
               or (a in ("--format", "-f") and i + 1 < len(args) and args[i + 1].strip().lower() == "json")
               for i, a in enumerate(args))


def _command_line(ctx: Any, sub_args: list) -> list:
    """The user's command line after ``designkit`` (the real argv when run as the console script)."""
    prog = sys.argv[0] if sys.argv else ""
    if prog.endswith(("designkit", "__main__.py")) and len(sys.argv) > 1:
        return [a for a in sys.argv[1:] if a != "--debug"]
    name = getattr(ctx, "invoked_subcommand", None)
    return ([name] if name and name not in sub_args else []) + list(sub_args)


def report_error(kind: str, message: str, status: int, as_json: bool) -> None:
    """Print one error: a line on stderr, and under --json also ``{"error": ...}`` on stdout."""
    typer.echo(f"Error: {message}", err=True)
    if as_json:
        sys.stdout.write(json.dumps({"error": {"kind": kind, "message": message, "exit_status": status}}) + "\n")
        sys.stdout.flush()


def _empty_text(ctx: Any) -> None:
    """One rule for every text option: empty is no value (``--table ''`` fell back to svm-fine, ``--out ''``
    meant the current folder, ``--port ''`` was looked for as a device).

    Click leaves a text or path option's value as the text given until typer's callback converts it, so an
    empty one is still ``""`` here, after parsing and before the command runs.
    """
    for param in ctx.command.params:
        value = ctx.params.get(param.name)
        if isinstance(value, str) and not value.strip():
            raise typer.BadParameter("it is empty; give a value (or leave the option out)", ctx=ctx, param=param)


class _Command(TyperCommand):
    """Typer command that refuses empty text options (:func:`_empty_text`)."""

    def parse_args(self, ctx: Any, args: Any) -> Any:
        rest = super().parse_args(ctx, args)
        _empty_text(ctx)
        return rest


class _Typer(typer.Typer):
    """Typer application whose commands are :class:`_Command` unless a command names its own class."""

    def command(self, *args: Any, cls: Any = None, **kwargs: Any) -> Any:
        return super().command(*args, cls=cls or _Command, **kwargs)


class _Group(TyperGroup):
    """Typer group that turns bad input into a one-line error and exit status 2."""

    def parse_args(self, ctx: Any, args: Any) -> Any:
        if not args and self.no_args_is_help and not ctx.resilient_parsing:
            # the help (typer prints it while rendering), then exit status 2, as click's NoArgsIsHelpError
            typer.echo(ctx.get_help(), err=True)
            raise typer.Exit(EXIT_BAD_INPUT)
        rest = super().parse_args(ctx, args)
        _empty_text(ctx)  # the group's own options
        return rest

    def main(self, *args: Any, standalone_mode: bool = True, **kwargs: Any) -> Any:
        if not standalone_mode:
            return super().main(*args, standalone_mode=False, **kwargs)
        try:
            rv = super().main(*args, standalone_mode=False, **kwargs)
        except typer.TyperException as exc:  # click's usage errors (typer 0.28's): one line, not a box
            hint = ""
            ctx = getattr(exc, "ctx", None)
            if ctx is not None:
                hint = f" (see '{ctx.command_path} --help')"
            argv = kwargs.get("args") if kwargs.get("args") is not None else (args[0] if args else sys.argv[1:])
            report_error("usage", f"{exc.format_message()}{hint}", exc.exit_code, wants_json(argv))
            sys.exit(exc.exit_code)
        except typer.Abort:
            typer.echo("Aborted.", err=True)
            sys.exit(1)
        sys.exit(rv if isinstance(rv, int) else 0)

    def invoke(self, ctx: Any) -> Any:
        """Run the command; a refusal is its one line alone: warnings raised on the way (numpy's, loadtxt's)
        are held back, shown after a command that answers, dropped before a refusal."""
        import warnings

        held: list = []
        answered = False
        try:
            with warnings.catch_warnings(record=True) as caught:
                try:
                    rv = self._invoke(ctx)
                    answered = True
                    return rv
                except typer.Exit as exc:
                    answered = getattr(exc, "exit_code", 0) not in (EXIT_BAD_INPUT, EXIT_BUG)
                    raise
                finally:
                    held = list(caught)
        finally:
            if answered:
                for w in held:
                    warnings.showwarning(w.message, w.category, w.filename, w.lineno, w.file, w.line)

    def _invoke(self, ctx: Any) -> Any:
        sub_args = list(getattr(ctx, "protected_args", []) or []) + list(ctx.args or [])
        try:
            return super().invoke(ctx)
        except BrokenPipeError:  # the reader had what it wanted (``| head -1``): not bad input, not a failure
            _quiet_stdout()
            raise typer.Exit(EXIT_BROKEN_PIPE) from None
        except (typer.Exit, typer.Abort, typer.TyperException, KeyboardInterrupt, SystemExit):
            raise
        except (ValueError, OSError) as exc:
            message = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            if isinstance(exc, OSError) and exc.filename and str(exc.filename) not in message:
                message = f"{message}: {exc.filename}"
            report_error("bad-input", message, EXIT_BAD_INPUT, wants_json(sub_args))
            raise typer.Exit(EXIT_BAD_INPUT) from None
        except MemoryError:
            report_error("bad-input", "out of memory: the request is too large for this machine "
                         "(ask for fewer trials, intervals or a shorter contact)", EXIT_BAD_INPUT,
                         wants_json(sub_args))
            raise typer.Exit(EXIT_BAD_INPUT) from None
        except Exception as exc:  # a bug: say so in one line; the traceback only with --debug
            if ctx.meta.get(_DEBUG_KEY):
                raise
            from designkit import __version__

            where = f"{type(exc).__name__}: {str(exc).strip().splitlines()[0] if str(exc).strip() else ''}"
            message = (f"internal error in designkit {__version__} ({where.rstrip(': ')}); this is a bug: "
                       f"please report it at {ISSUES_URL} with the output of 'designkit --debug "
                       f"{' '.join(str(a) for a in _command_line(ctx, sub_args))}'")
            report_error("internal", message, EXIT_BUG, wants_json(sub_args))
            raise typer.Exit(EXIT_BUG) from None


app = _Typer(
    cls=_Group,
    name="designkit",
    help="Design guidelines for active thermal tactile sensors: which contact time, noise and "
         "temperature difference separate two materials (semi-infinite model + SVM, Bai et al.).",
    no_args_is_help=True,
    add_completion=True,  # --install-completion / --show-completion (typer; no import cost until used)
    pretty_exceptions_enable=False,
    # markdown, not rich markup: unit brackets like [s] or [J s^-1/2 K^-1 m^-2] in help
    # texts are not style tags
    rich_markup_mode="markdown",
    context_settings={"help_option_names": ["-h", "--help"]},
)


def _show_version(value: bool) -> None:
    # Eager: click runs it while parsing, before any command (or its library layer) runs.
    if value:
        from designkit import __version__  # the package is already imported; nothing to load

        typer.echo(f"designkit {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    ctx: typer.Context,
    version: bool = typer.Option(False, "--version", "-V", callback=_show_version, is_eager=True,
                                 help="Print designkit's version and exit."),
    debug: bool = typer.Option(False, "--debug", help="Show the full traceback of an internal error."),
) -> None:
    """The top-level options (--version, --debug): typer's group callback."""
    ctx.meta[_DEBUG_KEY] = debug


# Help panels of ``designkit --help``, in the order a new user needs them.
ASK = "Ask a design question"
TABLES = "Lookup tables and embedding"
SENSOR = "Your sensor"
MODEL = "Model and sweeps"


def sub_app(name: str, help: str, panel: str) -> typer.Typer:
    """A command group (``designkit NAME ...``) registered on the main app in help ``panel``."""
    group = _Typer(cls=_Group, help=help, no_args_is_help=True, add_completion=False,
                        pretty_exceptions_enable=False, rich_markup_mode="markdown")
    app.add_typer(group, name=name, rich_help_panel=panel)
    return group


def emit_json(payload: Any) -> None:
    """Print ``payload`` as JSON on stdout (NaN and inf become null)."""
    sys.stdout.write(json.dumps(jsonable(payload), indent=2, allow_nan=False) + "\n")
    sys.stdout.flush()


def console(stderr: bool = False):
    """A rich console (rich is imported on first use).

    On a terminal it wraps to the window; piped or logged, nothing is hard-wrapped
    (a line is a line, whatever its length) and tables take the width they need.
    """
    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    if hasattr(stream, "isatty") and stream.isatty():
        return Console(stderr=stderr, highlight=False)
    return Console(stderr=stderr, highlight=False, soft_wrap=True, width=100_000)


def escape(text: str) -> str:
    r"""``rich.markup.escape(text)``: ``text`` inside a line of markup, printed as it is.

    Text without ``[`` and without a trailing backslash is returned as it is, without importing rich
    (``rich.markup.escape`` returns it unchanged; importing rich.markup is about 20 ms of a fresh
    question's start-up).

    >>> escape("svm-fine"), escape("[bold] table")
    ('svm-fine', '\\[bold] table')
    """
    if "[" not in text and not text.endswith("\\"):
        return text
    from rich.markup import escape as rich_escape

    return rich_escape(text)


#: The styles of an answer's parts (:class:`Lines`), as typer.style's keywords (click's ANSI styles).
STYLES = {"": {}, "bold": {"bold": True}, "dim": {"dim": True}, "bold green": {"fg": "green", "bold": True},
          "bold red": {"fg": "red", "bold": True}, "red": {"fg": "red"}, "yellow": {"fg": "yellow"}}


class Lines:
    """Lines of text with styled parts, for the answer a question prints.

    A part is plain text or a ``(text, style)`` pair (``style`` one of :data:`STYLES`, e.g. ``"bold green"``);
    text is never read as markup, so a material, table or sensor name needs no escaping. On a terminal the
    styled parts get typer's (click's) ANSI styles, unless ``NO_COLOR`` is set or ``TERM`` is ``dumb``;
    piped or logged, the parts' text is written as it is. Both print the same characters. Not rich: its
    console cost a fresh question on a terminal about 25 ms of start-up, and typer is loaded already
    (docs/decisions-log.md).

    >>> Lines(stream=sys.stdout).print("answer: ", ("1.2 s", "bold green"), " (SVM)")
    answer: 1.2 s (SVM)
    """

    def __init__(self, stderr: bool = False, *, stream: Any = None, color: bool | None = None):
        import os

        self._stream = stream if stream is not None else (sys.stderr if stderr else sys.stdout)
        if color is None:
            color = (stream is None and hasattr(self._stream, "isatty") and self._stream.isatty()
                     and "NO_COLOR" not in os.environ and os.environ.get("TERM") != "dumb")
        self._color = color

    def print(self, *parts: "str | tuple[str, str]") -> None:
        """Print one line made of ``parts`` (plain text, or ``(text, style)``)."""
        text = "".join(p if isinstance(p, str) else typer.style(p[0], **STYLES[p[1]]) if self._color else p[0]
                       for p in parts)
        typer.echo(text, file=self._stream, color=self._color)


def text_console(stderr: bool = False) -> Lines:
    """The lines a question's answer is printed on (stdout, or stderr): :class:`Lines`."""
    return Lines(stderr)


def _app_for(argv: list[str]) -> typer.Typer:
    """The app with only the command ``argv`` names, when it names one first (else the whole app).

    Typer turns every registered command into a click command (reading each function's signature
    and type hints) before it runs any. The lean copy holds the one command (or command group) asked
    for, with the same callback, so parsing, help, errors and output are that command's; anything else
    (no command, an unknown one, completion, options before the command) gets the whole app.
    """
    import os

    if any(k.endswith("_COMPLETE") for k in os.environ):
        return app
    if argv and argv[0] in ("--version", "-V"):  # answered while parsing the top-level options
        import copy

        lean = copy.copy(app)
        lean.registered_commands, lean.registered_groups = [], []
        return lean
    if not argv or argv[0].startswith("-"):
        return app
    name = argv[0]
    cmds = [c for c in app.registered_commands
            if (c.name or (c.callback.__name__.replace("_", "-") if c.callback else None)) == name]
    groups = [g for g in app.registered_groups if g.name == name]
    if len(cmds) + len(groups) != 1:
        return app
    import copy

    lean = copy.copy(app)
    lean.registered_commands, lean.registered_groups = cmds, groups
    return lean


class busy:
    """A spinner with the elapsed time on stderr while a long library call runs (a terminal only).

    For work whose library call reports no progress step by step (exact `distinguishable`,
    ``f1``, a model identification): the user sees that something runs and for how long. Piped,
    logged or under ``--json`` nothing is drawn; the line disappears when the work ends.

    >>> with busy("nothing to see", quiet=True):
    ...     pass
    """

    def __init__(self, message: str, *, quiet: bool = False):
        self.message, self.quiet, self._progress = message, quiet, None

    def __enter__(self) -> "busy":
        if not self.quiet and hasattr(sys.stderr, "isatty") and sys.stderr.isatty():
            from rich.console import Console
            from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

            self._progress = Progress(SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn(),
                                      console=Console(stderr=True), transient=True)
            self._progress.add_task(self.message, total=None)
            self._progress.start()
        return self

    def __exit__(self, *exc: Any) -> None:
        if self._progress is not None:
            self._progress.stop()


#: Exit status when the reader of stdout went away (``designkit ... | head -1``): 0, like a command that wrote
#: everything, so ``set -o pipefail`` scripts that read only the answer's first line do not fail (click's own
#: status for a closed pipe, 1, made ``min-contact ... | head -1`` fail them); the same at the last flush.
EXIT_BROKEN_PIPE = 0


def _quiet_stdout() -> None:
    """Point stdout at the null device: nothing more is written into the closed pipe, not even at exit."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # pragma: no cover - stdout without a file descriptor (tests)
        pass


def main() -> None:
    """Console-script entry point."""
    try:
        try:
            # one program name however it is started (console script or ``python -m designkit``): the usage
            # lines and the shell-completion script (``_DESIGNKIT_COMPLETE``) name the ``designkit`` command
            _app_for(sys.argv[1:])(prog_name="designkit")
        finally:
            sys.stdout.flush()  # a closed pipe shows here, inside the handler, not at interpreter exit
    except KeyboardInterrupt:
        typer.echo("Interrupted.", err=True)
        sys.exit(EXIT_INTERRUPTED)
    except BrokenPipeError:
        # the reader closed the pipe before the last flush: stop quietly (no "Error:", no "Exception ignored"
        # at interpreter exit)
        _quiet_stdout()
        sys.exit(EXIT_BROKEN_PIPE)
