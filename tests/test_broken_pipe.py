"""A reader that closes the pipe early (``designkit ... | head -1``) stops designkit quietly, with status 0.

Before, the command's write into the closed pipe was caught as an ``OSError`` and reported as bad input
("Error: [Errno 32] Broken pipe", exit 2). Real pipes, real processes: the read end is closed before the
command writes anything.
"""

import subprocess
import sys

import pytest


@pytest.mark.parametrize("args", [
    ["materials", "list"],
    ["min-contact", "--e1", "35000", "--e2", "20000"],
    ["min-contact", "--e1", "35000", "--e2", "20000", "--json"],
    ["tables", "list", "--format", "csv"],
])
def test_a_closed_pipe_stops_the_command_without_an_error(args):
    p = subprocess.Popen([sys.executable, "-m", "designkit", *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    p.stdout.close()  # the reader is gone before designkit prints
    err = p.stderr.read().decode()
    p.stderr.close()
    assert p.wait(timeout=120) == 0  # the reader had what it wanted: not a failure under pipefail
    assert err == ""


@pytest.mark.parametrize("cmd", ["min-contact --e1 35000 --e2 20000 | head -1",
                                 "matrix --set paper12 --format csv | head -1"])
def test_head_under_pipefail_exits_0(cmd):
    """The shell's view: ``set -o pipefail`` with a reader that stops after the first line."""
    script = f"set -o pipefail; {sys.executable} -m designkit {cmd}"
    r = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert len(r.stdout.splitlines()) == 1 and r.stderr == ""


def test_the_same_commands_print_when_the_reader_stays():
    out = subprocess.run([sys.executable, "-m", "designkit", "tables", "list", "--format", "csv"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.startswith("name") and out.stderr == ""
