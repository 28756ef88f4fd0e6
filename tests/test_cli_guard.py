"""The CLI's top-level guard: bad input exits 2 with one line, a bug exits 1 with one line naming
where to report it (the traceback only with --debug), and under --json the error is JSON on stdout;
output piped to a file is never hard-wrapped."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
import typer
from typer.testing import CliRunner

from designkit.cli._app import _Group


def _app():
    app = typer.Typer(cls=_Group, add_completion=False, pretty_exceptions_enable=False)

    @app.callback()
    def root(ctx: typer.Context, debug: bool = typer.Option(False, "--debug")):
        ctx.meta["designkit.debug"] = debug

    @app.command()
    def boom(json_: bool = typer.Option(False, "--json")):
        raise RuntimeError("the sky fell")

    @app.command()
    def bad(json_: bool = typer.Option(False, "--json")):
        raise ValueError("effusivity e1 must be positive, got -3")

    @app.command()
    def huge(json_: bool = typer.Option(False, "--json")):
        raise MemoryError()

    return app


def _run(*args):
    return CliRunner().invoke(_app(), list(args))


def test_a_bug_is_one_line_with_where_to_report_it_and_exit_1():
    r = _run("boom")
    assert r.exit_code == 1
    assert "internal error" in r.output and "RuntimeError: the sky fell" in r.output and "report it" in r.output
    assert "Traceback" not in r.output and len(r.output.strip().splitlines()) == 1


def test_debug_shows_the_traceback():
    r = _run("--debug", "boom")
    assert r.exit_code != 0 and isinstance(r.exception, RuntimeError)


@pytest.mark.parametrize("cmd, kind, status", [("boom", "internal", 1), ("bad", "bad-input", 2),
                                               ("huge", "bad-input", 2)])
def test_under_json_errors_are_json_on_stdout(cmd, kind, status):
    r = _run(cmd, "--json")
    assert r.exit_code == status
    payload = json.loads([line for line in r.stdout.splitlines() if line.startswith("{")][0])
    assert payload["error"]["kind"] == kind and payload["error"]["exit_status"] == status


def test_a_usage_error_under_json_is_json_too():
    exe = [sys.executable, "-m", "designkit"]
    r = subprocess.run(exe + ["min-contact", "--e1", "1", "--nosuch", "--json"], capture_output=True, text=True)
    assert r.returncode == 2
    assert json.loads(r.stdout)["error"]["kind"] == "usage" and "--nosuch" in r.stderr


def test_piped_output_is_not_hard_wrapped():
    exe = [sys.executable, "-m", "designkit"]
    r = subprocess.run(exe + ["tables", "list"], capture_output=True, text=True, env={"COLUMNS": "40",
                       **{k: v for k, v in __import__("os").environ.items() if k != "COLUMNS"}})
    assert r.returncode == 0
    assert "f1-matrix-fine-low" in r.stdout and "…" not in r.stdout  # no name cut at any width
