"""Every example in every ``--help`` runs as printed, from an installed designkit, in a scratch folder.

An example is a help line ``Example: `designkit ...``` or ``Example (words): `designkit ...``` and
nothing after the command (prose glued onto a command made copy-paste fail). Each runs in one scratch folder
(no clone: ``tables/``, ``docs/`` are not there), calibration first, so that a file one example writes (a
recording, a sensor file) is there for the next: under bash where it is a shell line (a pipe, a redirection) or
reads a port, else in-process through typer's runner, the command line split as the shell splits it (the same
words reach the same application, without a Python start per example). An example that reads a serial port runs
against ``designkit emulate`` on a pty playing the materials the example names: its ``--port`` value is
the emulator's pty (a rig's ``/dev/ttyACM0`` is not here). The count is printed at the end of the module
(``pytest -s``); none may fail.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent

#: One example: its words (optional) and the command, alone on its line.
EXAMPLE = re.compile(r"^\s*Example(?: \((?P<words>[^)]*)\))?: `(?P<cmd>designkit [^`]+)`\s*$")


def _helps() -> list[tuple[str, str]]:
    """(command path, help text) of every command and group, in ``designkit --help`` order."""
    import typer.main

    from designkit.cli import app

    out = []

    def walk(cmd, path):
        if path:
            out.append((" ".join(path), cmd.help or ""))
        for name, sub in (getattr(cmd, "commands", None) or {}).items():
            walk(sub, path + [name])

    walk(typer.main.get_command(app), [])
    return out


HELPS = _helps()
EXAMPLES = [(path, m.group("cmd")) for path, text in HELPS for line in text.splitlines()
            if (m := EXAMPLE.match(line))]
# the calibration's examples first: they record trials/ and write my-sensor.yaml, which others read
EXAMPLES.sort(key=lambda pc: not pc[0].startswith("calibrate"))
#: Commands that need a serial port: run against the emulator.
NEEDS_PORT = re.compile(r"--port\s+(\S+)")
#: What makes an example a shell line rather than one command (run under bash).
SHELL = re.compile(r"[|<>;&$`]")


def test_every_example_line_is_a_command_alone():
    """A help line that says "Example" holds one command in backticks and no prose after it."""
    bad = [(path, line.strip()) for path, text in HELPS for line in text.splitlines()
           if line.lstrip().startswith("Example") and not EXAMPLE.match(line)]
    assert not bad, bad
    assert len(EXAMPLES) >= 30


@pytest.mark.parametrize("path", sorted({p for p, _ in HELPS}))
def test_the_help_prints_each_example_whole(path, cli, monkeypatch):
    """What --help prints holds each example on one line, as the test runs it (at 200 columns)."""
    monkeypatch.setenv("COLUMNS", "200")
    r = cli(*path.split(), "--help")
    assert r.exit_code == 0, r.output
    flat = r.output
    for p, cmd in EXAMPLES:
        if p == path:
            assert cmd in flat, (cmd, flat)


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    """A scratch folder and a ``designkit`` on PATH that runs this checkout (as ``pip install`` would)."""
    folder = tmp_path_factory.mktemp("examples")
    bindir = tmp_path_factory.mktemp("bin")
    shim = bindir / "designkit"
    shim.write_text(f"#!/bin/sh\nexec {shlex.quote(sys.executable)} -m designkit \"$@\"\n")
    shim.chmod(0o755)
    env = {**os.environ, "PATH": f"{bindir}{os.pathsep}{os.environ.get('PATH', '')}", "COLUMNS": "100",
           "DESIGNKIT_DATA_DIR": str(folder / "data"),  # 'tables build' registers there, not in the user's folder
           "PYTHONPATH": os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH", "")) if p)}
    return folder, env


def _emulated_materials(cmd: str) -> list[str]:
    """The database materials an example names (--material / --m NAME): what the emulator plays, in order."""
    words = shlex.split(cmd)
    return [w for flag, w in zip(words, words[1:]) if flag in ("--material", "--m") and "=" not in w]


class _Emulator:
    """``designkit emulate`` on a pty (a subprocess), stopped when the example is done."""

    def __init__(self, materials: list[str], env: dict, cwd: Path):
        args = [sys.executable, "-m", "designkit", "emulate", "--speed", "100", "--json"]
        for m in materials:
            args += ["--material", m]
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                                     cwd=cwd)
        text = ""
        for line in self.proc.stdout:
            text += line
            try:
                self.info = json.loads(text)
                break
            except json.JSONDecodeError:
                continue
        else:
            raise AssertionError(f"designkit emulate printed no port: {self.proc.stderr.read()}")

    def stop(self) -> None:
        self.proc.terminate()
        self.proc.wait(timeout=30)


RESULTS: dict[str, int] = {}


def _in_process(cmd: str, folder: Path, monkeypatch) -> tuple[int, str]:
    """Run one command (no shell syntax) through typer's runner in ``folder``: (exit status, output)."""
    from typer.testing import CliRunner

    from designkit.cli import app

    monkeypatch.chdir(folder)
    r = CliRunner().invoke(app, shlex.split(cmd)[1:], env={"COLUMNS": "100"})
    if r.exception is not None and not isinstance(r.exception, SystemExit):
        import traceback

        return 1, r.output + "".join(traceback.format_exception(r.exception))
    return r.exit_code, r.output


@pytest.mark.slow
@pytest.mark.parametrize("path,cmd", EXAMPLES, ids=[f"{p}: {c[10:60]}" for p, c in EXAMPLES])
def test_the_example_runs_as_printed(path, cmd, scratch, monkeypatch):
    folder, env = scratch
    if not SHELL.search(cmd) and not NEEDS_PORT.search(cmd):
        RESULTS[cmd] = -1
        RESULTS[cmd], output = _in_process(cmd, folder, monkeypatch)
        assert RESULTS[cmd] == 0, f"{cmd}\n{output[-3000:]}"
        return
    emu = None
    run = cmd
    port = NEEDS_PORT.search(cmd)
    if port:
        emu = _Emulator(_emulated_materials(cmd), env, folder)
        run = cmd.replace(port.group(0), f"--port {emu.info['port']}")
    RESULTS[cmd] = -1  # a timeout counts as a failure
    try:
        r = subprocess.run(["bash", "-o", "pipefail", "-c", run], cwd=folder, env=env, capture_output=True,
                           text=True, timeout=300)
    finally:
        if emu is not None:
            emu.stop()
    RESULTS[cmd] = r.returncode
    assert r.returncode == 0, f"{cmd}\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}"


def teardown_module(module):
    if RESULTS:
        failed = sum(rc != 0 for rc in RESULTS.values())
        print(f"\nhelp examples: {len(EXAMPLES)}, {len(RESULTS)} run, {failed} failing")
