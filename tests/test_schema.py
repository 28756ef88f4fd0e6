"""One schema (issue 33): every command that answers with --json names each concept one way, with
one shape, as docs/schema.md lists them; the library's to_dict() is the same document; array
answers give records pandas reads; the words "at most" / "at least" follow the answer's own bound."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

SCHEMA_MD = Path(__file__).resolve().parent.parent / "docs" / "schema.md"

#: One cheap run of every command covered (docs/schema.md, "Commands covered"): shipped tables only.
COMMANDS = {
    "min-contact": ["min-contact", "--m1", "wood", "--m2", "glass"],
    "max-noise": ["max-noise", "--m1", "wood", "--m2", "glass", "--contact", "2"],
    "min-delta-t": ["min-delta-t", "--m1", "wood", "--m2", "glass", "--contact", "1", "--noise", "0.1"],
    "delta-e": ["delta-e", "--e", "20000", "--contact", "2"],
    "distinguishable": ["distinguishable", "--e1", "35000", "--e2", "20000", "--contact", "2"],
    "matrix": ["matrix", "--m", "wood", "--m", "glass", "--m", "copper"],
    "validity": ["validity", "--m", "wood", "--thickness", "0.005"],
    "materials list": ["materials", "list", "--set", "paper12"],
    "materials show": ["materials", "show", "glass"],
    "tables list": ["tables", "list"],
    "tables show": ["tables", "show", "svm-paper"],
    "simulate": ["simulate", "--e", "20000", "--contact", "0.5"],
    "f1": ["f1", "--e1", "20000", "--e2", "30000", "--contact", "1", "--trials", "30"],
    "design": ["design", "--m", "a=20000", "--m", "b=35000", "--no-svm"],
}


def _schema() -> tuple[dict[str, list[str]], set[str], set[str]]:
    """(concept key -> allowed shapes, other keys, maps) parsed from docs/schema.md."""
    text = SCHEMA_MD.read_text(encoding="utf-8")
    concepts: dict[str, list[str]] = {}
    section = text.split("## Concepts", 1)[1].split("\n## ", 1)[0]
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 2 or not cells[0].startswith("`"):
            continue
        for key in re.findall(r"`([a-z0-9_]+)`", cells[0]):
            concepts[key] = [s.strip() for s in cells[1].split(" or ")]
    other_text = text.split("## Other keys", 1)[1].split("\n## ", 1)[0]
    maps_line = next(line for line in other_text.splitlines() if line.startswith("Maps"))
    maps = set(re.findall(r"`([a-z0-9_]+)`", maps_line))
    listed = other_text.split("Maps", 1)[0]
    others = set(re.findall(r"`([a-z0-9_]+)`", listed.split(":", 1)[1]))
    return concepts, others, maps


CONCEPTS, OTHERS, MAPS = _schema()


def _is_number(v) -> bool:
    return v is None or (isinstance(v, (int, float)) and not isinstance(v, bool))


SHAPES = {
    "number": _is_number,
    "numbers": lambda v: _is_number(v) or (isinstance(v, list) and all(_is_number(x) for x in v)),
    "bool": lambda v: v is None or isinstance(v, bool),
    "string": lambda v: v is None or isinstance(v, str),
    "range": lambda v: v is None or (isinstance(v, list) and len(v) == 2 and all(_is_number(x) for x in v)),
    "interval": lambda v: v is None or (isinstance(v, dict) and {"low", "high"} <= set(v)),
    "ideal": lambda v: isinstance(v, dict) and {"value", "method"} <= set(v),
    "table": lambda v: v is None or (isinstance(v, dict) and set(v) == {"name", "content_hash"}),
    "object": lambda v: v is None or isinstance(v, dict),
    "map": lambda v: v is None or isinstance(v, dict),
    "list": lambda v: v is None or isinstance(v, list),
    "grid": lambda v: isinstance(v, list) and all(isinstance(r, list) for r in v),
}


def _kind(v) -> str | None:
    if v is None:
        return None
    if isinstance(v, bool):
        return "bool"
    if isinstance(v, (int, float)):
        return "number"
    return type(v).__name__


def _check(doc, where: str, bad: list, kinds: dict) -> None:
    """Every key of ``doc`` (recursively) documented, of its documented shape; other keys one kind each."""
    if isinstance(doc, list):
        for item in doc:
            _check(item, where, bad, kinds)
        return
    if not isinstance(doc, dict):
        return
    for key, value in doc.items():
        path = f"{where}.{key}"
        if key in MAPS:
            continue  # its keys are data (docs/schema.md, "Maps")
        if key == "matrix" and isinstance(value, dict):  # the N x N grids of the cells' keys
            for cell_key, grid in value.items():
                if cell_key not in CONCEPTS and cell_key not in OTHERS:
                    bad.append(f"{path}.{cell_key}: not in docs/schema.md")
                elif not SHAPES["grid"](grid):
                    bad.append(f"{path}.{cell_key}: not a grid")
            continue
        if key in CONCEPTS:
            shapes = CONCEPTS[key]
            if not any(SHAPES[s](value) if s in SHAPES else _kind(value) in (None, s) for s in shapes):
                bad.append(f"{path}: {json.dumps(value)[:80]} is not {' or '.join(shapes)}")
        elif key in OTHERS:
            k = _kind(value)
            if k is not None:
                kinds.setdefault(key, {}).setdefault(k, path)
        else:
            bad.append(f"{path}: not in docs/schema.md")
        _check(value, path, bad, kinds)


@pytest.fixture(scope="module")
def documents():
    from typer.testing import CliRunner

    from designkit.cli import app

    runner = CliRunner()
    out = {}
    for name, args in COMMANDS.items():
        r = runner.invoke(app, [*args, "--json"])
        assert r.exit_code in (0, 3), f"{name}: {r.output}"
        out[name] = json.loads(r.stdout)
    return out


@pytest.mark.slow
def test_the_exact_route_has_the_same_schema(cli):
    """The exact route (seconds: a small SVM run) prints the keys and shapes the table route does."""
    r = cli("distinguishable", "--e1", "35000", "--e2", "20000", "--contact", "1", "--exact", "--trials", "30",
            "--repeats", "2", "--jobs", "1", "--json")
    assert r.exit_code == 0, r.output
    bad: list[str] = []
    _check(json.loads(r.stdout), "distinguishable --exact", bad, {})
    assert not bad, "\n".join(dict.fromkeys(bad))


def test_the_schema_page_parses():
    assert {"effusivity", "effusivity_range", "interval", "ideal", "table", "value"} <= set(CONCEPTS)
    assert all(s in SHAPES or s == "bool" for shapes in CONCEPTS.values() for s in shapes)
    assert not (set(CONCEPTS) & OTHERS), "a key is both a concept and an other key"


def test_every_key_of_every_command_is_documented_with_one_shape(documents):
    bad: list[str] = []
    kinds: dict = {}
    for name, doc in documents.items():
        _check(doc, name, bad, kinds)
    bad += [f"{key}: {' and '.join(f'{k} at {p}' for k, p in seen.items())}" for key, seen in kinds.items()
            if len(seen) > 1]
    assert not bad, "\n".join(dict.fromkeys(bad))


def test_calibration_records_follow_the_schema():
    """An identified parameter (calibrate fit's results, a sensor file's provenance) and a force-driven contact
    area's threshold: the interval is {low, high, coverage}, whether the data identify it is ``identifiable``
    (a bool; ``identified`` is a paper12 material's identified effusivity, a number)."""
    from designkit.calibration.results import IdentifiedParameter

    p = IdentifiedParameter("contact_force_fraction", 0.17, (-0.05, 0.38), "", False, "on a search bound")
    bad: list[str] = []
    for doc in (p.to_dict(), {"force_fraction": 0.17, "force_fraction_interval": p.interval()}):
        _check(doc, "calibration", bad, {})
    assert not bad, bad
    assert p.to_dict()["identifiable"] is False and p.interval() == {"low": -0.05, "high": 0.38, "coverage": 0.95}
    assert CONCEPTS["identified"] == ["number"] and CONCEPTS["identifiable"] == ["bool"]
    assert CONCEPTS["force_fraction_interval"] == ["interval"]
    _check({"identified": True}, "x", bad, {})
    assert bad == ["x.identified: true is not number"]


def test_retired_names_appear_nowhere(documents):
    """The names issue 33 found for concepts that have one key now."""
    retired = {"e_range", "e1_range", "e2_range", "e_sensor", "ideal_min_contact_s", "limiting_classes",
               "svm_min_contact_s", "e"}
    text = json.dumps(documents)
    found = sorted(k for k in retired if f'"{k}":' in text)
    assert not found, found


def test_format_json_prints_the_json_document(cli):
    for args in (COMMANDS["delta-e"], COMMANDS["materials show"], COMMANDS["materials list"], COMMANDS["tables list"],
                 COMMANDS["tables show"], COMMANDS["matrix"]):
        docs = [json.loads(cli(*args, *fmt).stdout) for fmt in (("--format", "json"), ("--json",))]
        for d in docs:
            if isinstance(d, dict):
                (d.get("computation") or {}).pop("wall_s", None)  # the one figure two runs differ in
        assert docs[0] == docs[1], args


def test_library_to_dict_is_the_cli_document(documents):
    from designkit.query import min_contact

    lib = min_contact(m1="wood", m2="glass").to_dict()
    assert json.loads(json.dumps(lib)) == documents["min-contact"]


def test_array_answer_records_are_the_single_answers_record():
    from designkit.query import min_contact
    from designkit.query.answer import to_record

    arr = min_contact(np.array([35000.0, 45000.0]), 20000.0)
    records = arr.to_dict()
    single = to_record(min_contact(35000.0, 20000.0).to_dict())
    assert isinstance(records, list) and len(records) == 2 and all(isinstance(r, dict) for r in records)
    assert set(records[0]) <= set(single), set(records[0]) - set(single)
    assert {k: records[0][k] for k in ("value", "interval_low", "interval_high", "ideal_value", "table_name")} \
        == {k: single[k] for k in ("value", "interval_low", "interval_high", "ideal_value", "table_name")}
    pd = pytest.importorskip("pandas")
    frame = pd.DataFrame(arr.to_dict())
    assert frame.shape[0] == 2 and frame["value"].iloc[0] == pytest.approx(single["value"])


def test_bound_words_follow_the_answer(documents, cli):
    """An upper bound is never called "at least": the matrix, the answer and its note say the same."""
    md = documents["min-delta-t"]
    assert md["bound"] == "at-most" and md["interval"]["low"] is None  # separable at the grid's edge
    assert not any("at least" in n for n in md["notes"]) and any("at most" in n for n in md["notes"])
    text = cli(*COMMANDS["min-delta-t"]).stdout
    assert "at most 2 °C" in text and "at least" not in text
    mn = documents["max-noise"]
    assert mn["bound"] == "at-least" and "at least 0.5 °C" in cli(*COMMANDS["max-noise"]).stdout
    mc = documents["min-contact"]
    cell = next(c for c in documents["matrix"]["cells"] if {c["a"], c["b"]} == {"Wood", "Glass"})
    assert cell["value"] == mc["value"] and cell["bound"] == mc["bound"] is None
    assert "≤" not in cli(*COMMANDS["matrix"]).stdout.split("Limiting")[0]


def test_validity_headline_is_its_json_answer(documents, cli):
    v = documents["validity"]["valid_up_to_s"]
    headline = cli(*COMMANDS["validity"]).stdout.splitlines()[2]
    assert f"up to {v:.3g} s" in headline
