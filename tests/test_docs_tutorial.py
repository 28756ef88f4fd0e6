"""The tutorial's commands run and print what docs/tutorial.md shows, its calibration against the emulator included.

A file of its own (about 40 s): xdist hands out whole files, so the site's build (tests/test_docs_site.py) runs beside
it on another worker instead of after it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
DOCS = REPO / "docs"
needs_checkout = pytest.mark.skipif(not (DOCS / "conf.py").is_file(),
                                    reason="not running from a source checkout (docs/conf.py absent)")


@needs_checkout
@pytest.mark.slow
def test_the_tutorials_commands_run_and_print_what_it_shows():
    """Every block of docs/tutorial.md, the calibration against the emulator included (a minute or two)."""
    r = subprocess.run([sys.executable, str(DOCS / "generate.py"), "--check", "--slow", str(DOCS / "tutorial.md")],
                       capture_output=True, text=True, timeout=900, cwd=REPO)
    assert r.returncode == 0, r.stdout + r.stderr
