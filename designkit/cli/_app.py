"""The typer application and what every command shares.

Commands live in sibling modules (one per topic) and import their library
layer inside the command body, so that ``designkit --help`` and a table query
never import scikit-learn, matplotlib or dask.

Bad input anywhere below (``ValueError``, including designkit's ``InputError``,
and ``OSError`` for unreadable files) is printed as one line on stderr and
exits with status 2, never as a traceback.
"""

from __future__ import annotations

import json
import math
import sys
from typing import Any

import typer
from typer.core import TyperGroup

try:  # recent typer vendors click; older typer uses click itself
    from typer._click.exceptions import ClickException as _ClickException
    from typer._click.exceptions import NoArgsIsHelpError as _NoArgsIsHelp
except ImportError:  # pragma: no cover - depends on the installed typer
    from click.exceptions import ClickException as _ClickException
    from click.exceptions import NoArgsIsHelpError as _NoArgsIsHelp

EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130


class _Group(TyperGroup):
    """Typer group that turns bad input into a one-line error and exit status 2."""

    def main(self, *args: Any, standalone_mode: bool = True, **kwargs: Any) -> Any:
        if not standalone_mode:
            return super().main(*args, standalone_mode=False, **kwargs)
        try:
            rv = super().main(*args, standalone_mode=False, **kwargs)
        except _NoArgsIsHelp as exc:
            exc.show()
            sys.exit(exc.exit_code)
        except _ClickException as exc:  # usage errors: one line, not a box
            hint = ""
            ctx = getattr(exc, "ctx", None)
            if ctx is not None:
                hint = f" (see '{ctx.command_path} --help')"
            typer.echo(f"Error: {exc.format_message()}{hint}", err=True)
            sys.exit(exc.exit_code)
        except typer.Abort:
            typer.echo("Aborted.", err=True)
            sys.exit(1)
        sys.exit(rv if isinstance(rv, int) else 0)

    def invoke(self, ctx: Any) -> Any:
        try:
            return super().invoke(ctx)
        except (ValueError, OSError) as exc:
            message = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            if isinstance(exc, OSError) and exc.filename and str(exc.filename) not in message:
                message = f"{message}: {exc.filename}"
            typer.echo(f"Error: {message}", err=True)
            raise typer.Exit(EXIT_BAD_INPUT) from None


app = typer.Typer(
    cls=_Group,
    name="designkit",
    help="Design guidelines for active thermal tactile sensors: which contact time, noise and "
         "temperature difference separate two materials (semi-infinite model + SVM, Bai et al.).",
    no_args_is_help=True,
    add_completion=False,
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
    version: bool = typer.Option(False, "--version", "-V", callback=_show_version, is_eager=True,
                                 help="Print designkit's version and exit."),
) -> None:
    """The top-level options (only --version): typer's group callback."""


# Help panels of ``designkit --help``, in the order a new user needs them.
ASK = "Ask a design question"
TABLES = "Lookup tables and embedding"
SENSOR = "Your sensor"
MODEL = "Model and sweeps"
REPORTS = "The paper and accuracy"


def sub_app(name: str, help: str, panel: str) -> typer.Typer:
    """A command group (``designkit NAME ...``) registered on the main app in help ``panel``."""
    group = typer.Typer(cls=_Group, help=help, no_args_is_help=True, add_completion=False,
                        pretty_exceptions_enable=False, rich_markup_mode="markdown")
    app.add_typer(group, name=name, rich_help_panel=panel)
    return group


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if hasattr(obj, "tolist"):  # numpy arrays and scalars
        return _jsonable(obj.tolist())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def emit_json(payload: Any) -> None:
    """Print ``payload`` as JSON on stdout (NaN and inf become null)."""
    sys.stdout.write(json.dumps(_jsonable(payload), indent=2, allow_nan=False) + "\n")
    sys.stdout.flush()


def console(stderr: bool = False):
    """A rich console (imported lazily: rich costs ~50 ms)."""
    from rich.console import Console

    return Console(stderr=stderr, highlight=False)


def main() -> None:
    """Console-script entry point."""
    try:
        app()
    except KeyboardInterrupt:
        typer.echo("Interrupted.", err=True)
        sys.exit(EXIT_INTERRUPTED)
