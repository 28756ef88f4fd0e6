"""The documentation site: Sphinx builds it with warnings as errors (running the examples gallery's scripts), the
tutorial's commands run and print what the page shows, and no paragraph of docs/ is a wall of text."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
DOCS = REPO / "docs"
needs_checkout = pytest.mark.skipif(not (DOCS / "conf.py").is_file(),
                                    reason="not running from a source checkout (docs/conf.py absent)")

#: The longest paragraph a page may hold [characters].
MAX_PARAGRAPH = 800


@needs_checkout
def test_the_site_builds_with_no_warnings(tmp_path):
    pytest.importorskip("sphinx", reason="sphinx is in the 'test' extra: pip install -e '.[test]'")
    r = subprocess.run([sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-q", "-d",
                        str(tmp_path / "doctrees"), str(DOCS), str(tmp_path / "html")],
                       capture_output=True, text=True, timeout=600, cwd=REPO)
    warnings = [line for line in r.stderr.splitlines() if "WARNING" in line or "ERROR" in line]
    assert r.returncode == 0 and not warnings, r.stderr[-3000:]
    api = (tmp_path / "html" / "api" / "query.html").read_text(encoding="utf-8")
    assert "min_contact" in api  # the reference is generated from the docstrings
    assert (tmp_path / "html" / "tutorial.html").is_file()
    # the gallery: sphinx-gallery ran every script of examples/gallery (a failing one fails the build) and
    # each page shows the figure it made
    scripts = sorted(p.stem for p in (REPO / "examples" / "gallery").glob("plot_*.py"))
    assert len(scripts) >= 5
    for stem in scripts:
        page = (tmp_path / "html" / "gallery" / f"{stem}.html").read_text(encoding="utf-8")
        assert f"sphx_glr_{stem}_001.png" in page, stem


def _paragraphs(text: str):
    """Prose paragraphs of a Markdown page: blank-line separated, outside code fences, tables and comments."""
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    text = re.sub(r"<!--.*?-->", "", text, flags=re.S)
    for block in re.split(r"\n\s*\n", text):
        lines = [ln for ln in block.splitlines() if ln.strip()]
        if not lines or any(ln.lstrip().startswith(("|", "#", "    ")) for ln in lines):
            continue
        item: list[str] = []  # a list item is a paragraph of its own
        for ln in lines:
            if re.match(r"\s*(?:[-*]|\d+\.)\s", ln) and item:
                yield " ".join(item)
                item = []
            item.append(ln.strip())
        yield " ".join(item)


@needs_checkout
def test_no_paragraph_in_docs_is_longer_than_800_characters():
    long = [(p.name, len(par), par[:80]) for p in sorted(DOCS.glob("*.md"))
            for par in _paragraphs(p.read_text(encoding="utf-8")) if len(par) > MAX_PARAGRAPH]
    assert not long, long


@needs_checkout
@pytest.mark.slow
def test_the_tutorials_commands_run_and_print_what_it_shows():
    """Every block of docs/tutorial.md, the calibration against the emulator included (a minute or two)."""
    r = subprocess.run([sys.executable, str(DOCS / "generate.py"), "--check", "--slow", str(DOCS / "tutorial.md")],
                       capture_output=True, text=True, timeout=900, cwd=REPO)
    assert r.returncode == 0, r.stdout + r.stderr
