"""The main job's answer carries the paper's own guideline beside it (issue 13: "the paper's 'at least
2 s' on its 1-s grid beside it"), in the guideline's scene only; the figures come from
designkit.query.guideline.GUIDELINE (re-exported by designkit_lab.reproduce.paper), never from a string in the CLI."""

from __future__ import annotations

import pytest

from designkit.query.guideline import GUIDELINE, guideline_remark


def _paper_words() -> str:
    return f"at least {GUIDELINE['min_contact_s']:g} s on its 1-s grid"


@pytest.mark.parametrize("pair", [("35000", "20000"), ("20000", "35000")])
def test_main_job_prints_the_paper_figure_with_explain(cli, pair):
    r = cli("min-contact", "--e1", pair[0], "--e2", pair[1], "--explain")
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    i = next(k for k, line in enumerate(lines) if _paper_words() in line)
    # the answer first, its ideal bound second; the paper's figure among the explanation, placed on its grid
    assert lines[0].startswith("shortest contact: ") and "ideal observer bound" in lines[1] and i > 2
    value = float(lines[0].split(": ")[1].split(" s")[0])
    on_grid = min(c for c in GUIDELINE["contact_grid_s"] if c >= value)
    assert f"rounds up to {on_grid:g} s there" in lines[i]
    short = cli("min-contact", "--e1", pair[0], "--e2", pair[1])
    assert _paper_words() not in short.output and len(short.output.splitlines()) <= 4


@pytest.mark.parametrize("args", [("--e1", "35000", "--e2", "20000", "--noise", "0.1"),
                                  ("--e1", "35000", "--e2", "20000", "--delta-t", "5"),
                                  ("--e1", "35000", "--e2", "21000")])
def test_no_paper_line_outside_the_guideline_scene(cli, args):
    r = cli("min-contact", *args)
    assert r.exit_code == 0, r.output
    assert _paper_words() not in r.output


def test_remark_for_exact_answers_and_other_questions():
    from designkit import query

    a = query.ask("min-contact", route="table", e1=35000, e2=20000).to_dict()
    assert guideline_remark(a).startswith("the paper (section VIII-B)")
    assert guideline_remark({**a, "value": 4.5}).endswith("lies beyond that grid's 4 s")
    assert guideline_remark({**a, "value": None}).endswith("(1, 2, 3, 4 s)")
    assert guideline_remark({**a, "question": "max-noise"}) is None
    assert guideline_remark({**a, "sensor": {"name": "other"}}) is None
    assert guideline_remark({**a, "threshold": 0.8}) is None
    assert guideline_remark({**a, "computation": {"sensor_temp_spread_c": 2.5}}) is None
    assert guideline_remark({}) is None


def test_reproduce_reads_the_same_guideline():
    from designkit_lab.reproduce import paper

    assert paper.GUIDELINE is GUIDELINE and "GUIDELINE" in paper.__all__
