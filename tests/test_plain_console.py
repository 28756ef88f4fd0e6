"""An answer is printed without rich (start-up, issues 16 and 33): on a terminal its styled parts get typer's ANSI
styles, piped the same characters without them."""

import io
import re

import pytest

from designkit import query
from designkit.cli import _app
from designkit.cli import query as cli_query

ANSWERS = [
    lambda: query.min_contact(35000, 20000),
    lambda: query.min_contact(m1="copper", m2="Stainless steel"),
    lambda: query.max_noise(35000, 20000, contact_s=2),
    lambda: query.min_delta_t(1000, 600, contact_s=3),
    lambda: query.delta_e(20000, contact_s=2),
    lambda: query.distinguishable(35000, 20000, contact_s=1),
    lambda: query.min_contact(39000, 38990),  # no answer: a note, a red line
]


_ANSI = re.compile("\x1b\\[[0-9;]*m")


@pytest.mark.parametrize("make", ANSWERS)
@pytest.mark.parametrize("explain", [False, True])
def test_piped_lines_are_the_terminals_without_its_styles(make, explain, capsys, monkeypatch):
    d = make().to_dict()
    cli_query._render_text(d, explain)
    plain = capsys.readouterr().out
    buf = io.StringIO()
    monkeypatch.setattr(_app, "text_console", lambda stderr=False: _app.Lines(stream=buf, color=True))
    cli_query._render_text(d, explain)
    styled = buf.getvalue()
    assert "\x1b[" in styled and "\x1b[" not in plain  # the answer (or the refusal) and the scene line styled
    assert _ANSI.sub("", styled) == plain
    assert "[/" not in plain and "[bold" not in plain


@pytest.mark.parametrize("text", ["[bold]a[/] b", r"\[x] and [dim]y[/dim]", "(1, 1.5] s", "e [J s^-1/2] ok"])
def test_text_is_never_read_as_markup(text):
    """A name with brackets (a user's material or sensor) is printed as it is, piped or on a terminal."""
    styled, plain = io.StringIO(), io.StringIO()
    for lines in (_app.Lines(stream=styled, color=True), _app.Lines(stream=plain)):
        lines.print(text, " ", (text, "bold green"))
    assert _ANSI.sub("", styled.getvalue()) == plain.getvalue() == f"{text} {text}\n"


@pytest.mark.parametrize("make", ANSWERS)
def test_the_answer_first_in_at_most_four_lines(make, capsys):
    """Line 1: the answer (with its interval), line 2: the ideal bound, line 3: the scene, sensor and source,
    at most one caveat; --explain prints the rest (the method, the notes) under the same three lines."""
    d = make().to_dict()
    cli_query._render_text(d)
    short = capsys.readouterr().out.splitlines()
    assert len(short) <= 4, short
    assert "ideal" in short[1] and ("table " in short[2] or "computed" in short[2]), short
    cli_query._render_text(d, explain=True)
    long = capsys.readouterr().out.splitlines()
    assert long[:3] == short[:3] and any(x.startswith("method: ") for x in long)
    assert all(n in "\n".join(long) for n in d["notes"])
