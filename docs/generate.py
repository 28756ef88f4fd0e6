"""Regenerate the example output in README.md and docs/*.md from the real commands.

A generated block in a Markdown file is written as

    <!-- generated: designkit min-contact --e1 35000 --e2 20000 -->
    ```text
    ...output...
    ```
    <!-- /generated -->

and this script runs each command (``designkit`` is the installed console script, or
``python -m designkit``) and replaces the text between the markers with what it prints.
``<!-- generated slow: ... -->`` marks a command that takes more than a few seconds:
``--check`` (what the test suite runs) skips those; a plain run regenerates them too.

Usage::

    python docs/generate.py            # rewrite every generated block in place
    python docs/generate.py --check    # exit 1 and list the blocks that are stale (fast ones)
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
FILES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
BLOCK = re.compile(r"(<!-- generated( slow)?: (?P<cmd>.+?) -->\n```text\n)(?P<out>.*?)(```\n<!-- /generated -->)",
                   re.S)


def run(cmd: str) -> str:
    """What ``cmd`` prints (stdout, then stderr), as a user's terminal would show it piped."""
    argv = shlex.split(cmd)
    if argv[0] == "designkit":
        exe = shutil.which("designkit") or str(Path(sys.executable).with_name("designkit"))
        argv = [exe, *argv[1:]] if Path(exe).exists() else [sys.executable, "-m", "designkit", *argv[1:]]
    env = {**os.environ, "COLUMNS": "100"}
    r = subprocess.run(argv, capture_output=True, text=True, cwd=REPO, env=env, timeout=900)
    return r.stdout + r.stderr


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
            got = run(cmd)
            if got != out:
                stale.append(f"{path.relative_to(REPO)}: {cmd}")
                new = new[:m.start("out")] + got + new[m.end("out"):]
        if not args.check and new != text:
            path.write_text(new, encoding="utf-8")
    if args.check and stale:
        print("stale generated output (run python docs/generate.py):\n  " + "\n  ".join(stale))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
