"""Long work shows it is running (issue 16): a spinner with the elapsed time on a terminal's stderr (a real
pty here), nothing when piped or under --json."""

from __future__ import annotations

import os
import pty
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import read_until_closed

REPO = Path(__file__).resolve().parent.parent
pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="needs a pty")


def _run_with_pty_stderr(*args: str) -> tuple[int, str, str]:
    master, slave = pty.openpty()
    env = {**os.environ, "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""), "COLUMNS": "120"}
    p = subprocess.Popen([sys.executable, "-m", "designkit", *args], stdout=subprocess.PIPE, stderr=slave, env=env)
    os.close(slave)
    err = read_until_closed(master)
    os.close(master)
    out = p.stdout.read().decode()
    return p.wait(timeout=300), out, err.decode(errors="replace")


F1 = ("f1", "--e1", "35000", "--e2", "20000", "--contact", "1", "--trials", "20")


def test_f1_shows_a_spinner_on_a_terminal():
    rc, out, err = _run_with_pty_stderr(*F1)
    assert rc == 0, err
    assert "f1: simulating touches" in err and "0:00:0" in err  # the message and the elapsed time
    assert "ideal" in out


def test_json_draws_nothing_on_the_terminal():
    rc, out, err = _run_with_pty_stderr(*F1, "--json")
    assert rc == 0, err
    assert "simulating" not in err and out.lstrip().startswith("{")
