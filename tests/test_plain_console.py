"""Piped answers are printed without rich (start-up, issue 16): the text must be exactly rich's."""

import io

import pytest
from rich.console import Console

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


@pytest.mark.parametrize("make", ANSWERS)
def test_plain_console_prints_what_rich_prints(make, capsys, monkeypatch):
    d = make().to_dict()
    cli_query._render_text(d)
    plain = capsys.readouterr().out
    buf = io.StringIO()
    monkeypatch.setattr(_app, "text_console",
                        lambda stderr=False: Console(file=buf, highlight=False, soft_wrap=True, width=100_000))
    cli_query._render_text(d)
    assert plain == buf.getvalue()
    assert "[/" not in plain and "[bold" not in plain


@pytest.mark.parametrize("text", ["[bold]a[/] b", r"\[x] and [dim]y[/dim]", r"\\[bold]z[/]", "(1, 1.5] s",
                                  "[#ff0000]red[/] [@click]x[/]", "e [J s^-1/2] ok"])
def test_strip_markup_matches_rich(text):
    buf = io.StringIO()
    Console(file=buf, highlight=False, soft_wrap=True, width=100_000).print(text)
    assert _app.strip_markup(text) + "\n" == buf.getvalue()
