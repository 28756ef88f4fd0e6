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

``<!-- generated session: ... -->`` blocks of one file run in document order in one scratch folder
(a copy of the file's folder, with ``examples/`` beside it), so what one writes (a recording, a sensor
file) the next reads: a tutorial. A session command with ``--port P`` runs against ``designkit emulate``
on a pty playing the materials the command names (``--material`` / ``--m``); the pty's path is shown as
P. A session block that says ``slow`` is a calibration: ``--check --slow`` runs those too.

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
    python docs/generate.py --check --slow docs/tutorial.md   # every block of one file

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
VOLATILE = re.compile(r"(?<=in )[\d.]+ s \([\d.]+ s CPU\)|(?<=per class, )[\d.]+ s(?=\))|(?<=computed in )[\d.]+ s"
                      r"|(?<=, )[\d.]+ s(?= wall)|(?<=took )[\d.]+ s|[\d.]+ s(?= │\n)")


def same(old: str, new: str) -> bool:
    """Whether two outputs agree, apart from the run's own timings (VOLATILE)."""
    return VOLATILE.sub("#", old) == VOLATILE.sub("#", new)


BLOCK = re.compile(r"(<!-- generated( slow)?(?P<session> session)?(?: needs (?P<needs>[\w.,+-]+))?: (?P<cmd>.+?) -->"
                   r"\n```text\n)"
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


class Session:
    """One scratch folder for a file's session blocks: a copy of its folder, with ``examples/`` beside it."""

    def __init__(self, folder: Path):
        self._tmp = tempfile.TemporaryDirectory(prefix="designkit-session-")
        root = Path(self._tmp.name)
        self.bindir = root / "bin"
        self.bindir.mkdir()
        for name, args in (("designkit", "-m designkit "), ("python3", "")):
            shim = self.bindir / name
            shim.write_text(f'#!/bin/sh\nexec {shlex.quote(sys.executable)} {args}"$@"\n')
            shim.chmod(0o755)
        self.work = root / folder.name
        ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "_build", "*.png", "*.jsonl")
        shutil.copytree(folder, self.work, ignore=ignore)
        shutil.copytree(REPO / "examples", self.work / "examples", ignore=ignore)

    def run(self, cmd: str) -> str:
        port = re.search(r"--port\s+(\S+)", cmd)
        emu, shown = None, None
        if port:
            words = shlex.split(cmd)
            mats = [w for f, w in zip(words, words[1:]) if f in ("--material", "--m") and "=" not in w]
            emu, pty = start_emulator(mats, self.work, _env(str(self.bindir)))
            shown = port.group(1)
            cmd = cmd.replace(port.group(0), f"--port {pty}")
        try:
            r = subprocess.run(["bash", "-o", "pipefail", "-c", cmd], capture_output=True, text=True, cwd=self.work,
                               env=_env(str(self.bindir)), timeout=900)
        finally:
            if emu is not None:
                emu.terminate()
                emu.wait(timeout=30)
        out = r.stdout + r.stderr
        if shown:
            out = out.replace(pty, shown)
        return re.sub(r"/dev/pts/\d+", "/dev/pts/3", out)

    def close(self) -> None:
        self._tmp.cleanup()


def start_emulator(materials, cwd: Path, env: dict):
    """``designkit emulate`` playing ``materials`` (database names) on a pty: (process, pty path)."""
    import json

    args = [sys.executable, "-m", "designkit", "emulate", "--speed", "100", "--json"]
    for m in materials:
        args += ["--material", m]
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, cwd=cwd)
    text = ""
    for line in proc.stdout:
        text += line
        try:
            return proc, json.loads(text)["port"]
        except json.JSONDecodeError:
            continue
    raise SystemExit(f"designkit emulate printed no port: {proc.stderr.read()}")


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
    ap.add_argument("--slow", action="store_true", help="with --check: the slow blocks too")
    ap.add_argument("files", nargs="*", type=Path, help="only these Markdown files (default: every covered one)")
    args = ap.parse_args(argv)
    stale = []
    for path in [p.resolve() for p in args.files] or FILES:
        text = path.read_text(encoding="utf-8")
        new = text
        session = None
        results = []
        for cmd, slow, out, m in blocks(text):  # in document order: a session's blocks build on each other
            if args.check and slow and not args.slow:
                continue
            missing = [prog for prog in (m.group("needs") or "").split(",") if prog and not shutil.which(prog)]
            if args.check and missing:
                print(f"skipped (needs {', '.join(missing)}): {_shown(path)}: {cmd}")
                continue
            if m.group("session"):
                session = session or Session(path.parent)
                got = session.run(cmd)
            else:
                got = run(cmd, path.parent)
            results.append((cmd, out, got, m))
        if session is not None:
            session.close()
        for cmd, out, got, m in reversed(results):
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
