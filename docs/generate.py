"""Regenerate the example output in README.md and docs/*.md from the real commands.

A generated block in a Markdown file is written as

    <!-- generated: designkit min-contact --e1 35000 --e2 20000 -->
    ```text
    ...output...
    ```
    <!-- /generated -->

and this script runs each command (``designkit`` as ``python -m designkit`` with this Python)
and replaces the text between the markers with what it prints.
``<!-- generated slow: ... -->`` marks a command that takes more than a few seconds:
``--check`` (what the test suite runs) skips those; a plain run regenerates them too.
``<!-- generated needs make,cc: ... -->`` names programs the command needs besides designkit:
where one is not installed, ``--check`` says so and skips the block.

A command that is not a plain ``designkit ...`` line (a ``make`` target, a pipeline, ``&&``) runs
under ``bash`` in a temporary copy of the Markdown file's own folder, so what it builds (an
exported header, a compiled program) is thrown away and the checkout stays clean; there
``designkit`` and ``python3`` are this Python (with the checkout first on ``PYTHONPATH``). Every
command runs this checkout's designkit, whichever one is installed.

Files covered: README.md, docs/*.md, examples/*/README.md, calibration/README.md and
tables/README.md (``FILES``). ``tests/test_docs_current.py`` also checks that the repository paths
these files name exist, and that calibration/README.md's library snippet defines every name it uses.

Usage::

    python docs/generate.py            # rewrite every generated block in place
    python docs/generate.py --check    # exit 1 and list the blocks that are stale (fast ones)

The run's own wall and CPU times in an output (``in 0.35 s (0.17 s CPU)``) are not compared:
a block whose output differs only there is left as it is.
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
FILES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md")),
         *sorted((REPO / "examples").glob("*/README.md")),
         REPO / "calibration" / "README.md", REPO / "tables" / "README.md"]
SHELL = re.compile(r"[|&;<>()$`]")
#: The run's own wall and CPU times (they differ from run to run): compared with the number masked,
#: so a block counts as stale only when something else changed.
VOLATILE = re.compile(r"(?<=in )[\d.]+ s \([\d.]+ s CPU\)|(?<=per class, )[\d.]+ s(?=\))|(?<=computed in )[\d.]+ s")


def same(old: str, new: str) -> bool:
    """Whether two outputs agree, apart from the run's own timings (VOLATILE)."""
    return VOLATILE.sub("#", old) == VOLATILE.sub("#", new)


BLOCK = re.compile(r"(<!-- generated( slow)?(?: needs (?P<needs>[\w.,+-]+))?: (?P<cmd>.+?) -->\n```text\n)"
                   r"(?P<out>.*?)(```\n<!-- /generated -->)",
                   re.S)


def _env(bindir: str | None = None) -> dict:
    """The environment of a generated command: this checkout first on PYTHONPATH, fixed width."""
    env = {**os.environ, "COLUMNS": "100",
           "PYTHONPATH": os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH", "")) if p)}
    if bindir:
        env["PATH"] = bindir + os.pathsep + env.get("PATH", "")
    return env


def is_shell(cmd: str) -> bool:
    """Whether ``cmd`` needs a shell and the Markdown file's folder (see the module docstring)."""
    return not cmd.startswith("designkit ") or bool(SHELL.search(cmd))


def run(cmd: str, folder: Path | None = None) -> str:
    """What ``cmd`` prints (stdout, then stderr), as a user's terminal would show it piped.

    A plain ``designkit`` command runs in the repository root; any other command runs under
    bash in a temporary copy of ``folder`` (the Markdown file's folder).
    """
    if not is_shell(cmd):
        argv = [sys.executable, "-m", "designkit", *shlex.split(cmd)[1:]]
        r = subprocess.run(argv, capture_output=True, text=True, cwd=REPO, env=_env(), timeout=900)
        return r.stdout + r.stderr
    if folder is None or folder.resolve() == REPO:
        raise SystemExit(f"a shell command needs its own folder, not the repository root: {cmd}")
    with tempfile.TemporaryDirectory(prefix="designkit-docs-") as tmp:
        bindir = Path(tmp) / "bin"
        bindir.mkdir()
        for name, args in (("designkit", "-m designkit "), ("python3", "")):
            shim = bindir / name
            shim.write_text(f'#!/bin/sh\nexec {shlex.quote(sys.executable)} {args}"$@"\n')
            shim.chmod(0o755)
        work = Path(tmp) / folder.name
        shutil.copytree(folder, work, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        r = subprocess.run(["bash", "-o", "pipefail", "-c", cmd], capture_output=True, text=True, cwd=work,
                           env=_env(str(bindir)), timeout=900)
    return r.stdout + r.stderr


def _shown(path: Path) -> str:
    """A covered file's name as the stale list shows it: relative to the repository when inside it."""
    return str(path.relative_to(REPO)) if path.is_relative_to(REPO) else str(path)


def blocks(text: str):
    """(command, slow, current output, match) for every generated block."""
    for m in BLOCK.finditer(text):
        yield m.group("cmd"), bool(m.group(2)), m.group("out"), m


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="report stale fast blocks instead of rewriting")
    args = ap.parse_args(argv)
    stale = []
    for path in FILES:
        text = path.read_text(encoding="utf-8")
        new = text
        for cmd, slow, out, m in reversed(list(blocks(text))):
            if args.check and slow:
                continue
            missing = [prog for prog in (m.group("needs") or "").split(",") if prog and not shutil.which(prog)]
            if args.check and missing:
                print(f"skipped (needs {', '.join(missing)}): {_shown(path)}: {cmd}")
                continue
            got = run(cmd, path.parent)
            if not same(out, got):
                stale.append(f"{_shown(path)}: {cmd}")
                new = new[:m.start("out")] + got + new[m.end("out"):]
        if not args.check and new != text:
            path.write_text(new, encoding="utf-8")
    if args.check and stale:
        print("stale generated output (run python docs/generate.py):\n  " + "\n  ".join(stale))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
