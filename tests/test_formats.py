"""The one row output (designkit.cli._format): ``--format table|json|csv|md`` and ``--out FILE|-`` agree
across the commands that print rows (``materials list|show``, ``tables list|show``, ``delta-e``, ``matrix``),
and ``-`` reads stdin."""

from __future__ import annotations

import csv
import io
import json

import pytest

from designkit.cli._format import FORMATS, render_rows

ROWS = [{"name": "Stainless steel, 316 [!]", "e": 7800.123456, "ok": True, "none": None},
        {"name": "Copper", "e": 36000.0, "ok": False, "none": None}]


def test_csv_is_header_and_rows_at_full_precision():
    text = render_rows(ROWS, fmt="csv")
    rows = list(csv.reader(io.StringIO(text)))
    assert rows[0] == ["name", "e", "ok", "none"]
    assert rows[1] == ["Stainless steel, 316 [!]", "7800.123456", "True", ""]
    assert len(rows) == 3


def test_json_is_the_payload_or_the_rows():
    assert json.loads(render_rows(ROWS, fmt="json"))[0]["e"] == 7800.123456
    assert json.loads(render_rows(ROWS, fmt="json", payload={"x": float("nan")})) == {"x": None}


def test_md_escapes_pipes_and_right_aligns_numbers():
    text = render_rows([{"a": "x|y", "n": 1.5}], fmt="md", title="T", notes=["note one"])
    assert "| x\\|y | 1.5 |" in text and "|:---|---:|" in text and text.rstrip().endswith("note one")


def test_table_never_cuts_a_name_nor_eats_brackets():
    text = render_rows(ROWS, fmt="table", title="e [J s^-1/2 K^-1 m^-2]")
    assert "Stainless steel, 316 [!]" in text and "[J s^-1/2 K^-1 m^-2]" in text and "…" not in text
    # a column name with a unit in brackets is text, not a style tag
    assert "contact [s]" in render_rows([{"contact [s]": 1.0}], fmt="table")


def test_unknown_format_is_refused():
    from designkit._validation import InputError

    with pytest.raises(InputError, match="text, table, json, csv, ndjson, md"):
        render_rows(ROWS, fmt="xlsx")


@pytest.mark.parametrize("fmt", FORMATS)
def test_materials_list_every_format_and_out_dash(cli, fmt):
    r = cli("materials", "list", "--set", "paper12", "--format", fmt, "--out", "-")
    assert r.exit_code == 0, r.output
    assert "Stainless Steel" in r.stdout
    assert not (r.stdout.startswith("-") and len(r.stdout) < 3)


def test_materials_list_json_flag_equals_format_json(cli):
    assert cli("materials", "list", "--json").stdout == cli("materials", "list", "--format", "json").stdout


def test_materials_list_out_file(cli, tmp_path):
    out = tmp_path / "m.csv"
    r = cli("materials", "list", "--family", "metals", "--format", "csv", "--out", str(out))
    assert r.exit_code == 0, r.output
    rows = list(csv.DictReader(out.open()))
    assert rows and {x["family"] for x in rows} == {"metals"} and float(rows[0]["e_min"]) > 0
    assert r.stdout == ""


def test_materials_csv_pipes_into_matrix_from_stdin(cli):
    csv_text = cli("materials", "list", "--set", "paper12", "--format", "csv").stdout
    r = cli("matrix", "--from", "-", "--json", "--no-multiclass", input=csv_text)
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert [m["qualified_name"] for m in d["materials"]][:2] == ["paper12:Cardboard", "paper12:Wood"]
    assert len(d["cells"]) == 66


@pytest.mark.parametrize("text", [
    "# the bin\npaper12:glass\n\npaper12:copper\n",  # one name a line
    "name\npaper12:glass\npaper12:copper\n",  # a one-column CSV: its header was taken for a material
])
def test_matrix_reads_one_name_a_line_or_a_name_column(cli, tmp_path, text):
    p = tmp_path / "bin.txt"
    p.write_text(text)
    r = cli("matrix", "--from", str(p), "--format", "csv", "--no-multiclass")
    assert r.exit_code == 0, r.output
    assert r.stdout.splitlines()[0] == "material,Glass,Copper"


# ---------------------------------------------------------------- figures: vector formats on request
@pytest.mark.parametrize("fmt, magic", [("svg", b"<?xml"), ("pdf", b"%PDF"), ("png", b"\x89PNG")])
def test_report_figures_in_the_format_asked(tmp_path, fmt, magic):
    pytest.importorskip("matplotlib")
    from designkit.figures import pyplot
    from designkit_lab.reproduce import ReproduceSettings
    from designkit_lab.reproduce._report import Context

    ctx = Context(ReproduceSettings(figure_format=fmt), tmp_path)
    fig, ax = pyplot().subplots()
    ax.plot([0, 1], [0, 1])
    rel = ctx.save_figure(fig, "line")
    assert rel == f"figures/line.{fmt}"
    assert (tmp_path / rel).read_bytes().startswith(magic)
    assert not list((tmp_path / "figures").glob(".*"))  # no temporary file left


def test_unknown_figure_format_is_refused():
    from designkit._validation import InputError
    from designkit_lab.reproduce import ReproduceSettings

    with pytest.raises(InputError, match="png, svg or pdf"):
        ReproduceSettings(figure_format="jpg")


def test_node_graph_layout_puts_every_node_somewhere_distinct():
    nx = pytest.importorskip("networkx")
    from designkit_lab.reproduce.matrices import graph_layout

    G = nx.Graph()
    G.add_nodes_from(range(9))
    G.add_edges_from([(0, 1), (1, 2), (2, 0), (3, 4)])
    pos, angle = graph_layout(G, lambda v: v)
    assert set(pos) == set(range(9)) == set(angle)
    pts = {tuple(round(c, 9) for c in p) for p in pos.values()}
    assert len(pts) == 9
    assert all(angle[v] == -90.0 for v in (5, 6, 7, 8))  # lone nodes in a row, labels below


# ----------------------------------------------------------------- the other commands that print rows
ROW_COMMANDS = {
    "tables list": (("tables", "list"), "name", "svm-paper"),
    "tables show": (("tables", "show", "svm-paper"), "axis", "contact_s"),
    "materials show": (("materials", "show", "copper"), "property", "effusivity"),
    "delta-e": (("delta-e", "--e", "20000", "--contact", "2"), "direction", "upper"),
}


@pytest.mark.parametrize("command", sorted(ROW_COMMANDS))
def test_row_commands_print_csv_with_a_header_and_rows_only_and_json_that_parses(cli, command):
    args, key, expected = ROW_COMMANDS[command]
    r = cli(*args, "--format", "csv")
    assert r.exit_code == 0, r.output
    rows = list(csv.DictReader(io.StringIO(r.stdout)))  # a header, rows, nothing else (no comment lines)
    assert expected in [row[key] for row in rows] and len(rows) >= 2
    assert all(len(row) == len(rows[0]) and None not in row for row in rows)
    j = cli(*args, "--format", "json")
    assert j.exit_code == 0, j.output
    data = json.loads(j.stdout)
    items = data if isinstance(data, list) else [data]
    assert any(expected in json.dumps(item) for item in items)
    for fmt in ("table", "md"):
        t = cli(*args, "--format", fmt)
        assert t.exit_code == 0 and expected in t.stdout, t.output


def test_tables_list_json_flag_equals_format_json(cli):
    assert cli("tables", "list", "--json").stdout == cli("tables", "list", "--format", "json").stdout


def test_out_to_a_fifo_nothing_reads_is_refused_not_waited_on(cli, tmp_path):
    import os
    import threading

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    r = cli("tables", "list", "--format", "csv", "--out", str(fifo))
    assert r.exit_code == 2 and "nothing reads" in r.output
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()))
    reader.start()
    import time

    for _ in range(200):  # the reader opens the FIFO: now it is written to
        r = cli("tables", "list", "--format", "csv", "--out", str(fifo))
        if r.exit_code == 0:
            break
        time.sleep(0.01)
    reader.join(timeout=30)
    assert r.exit_code == 0 and got and got[0].startswith("name,")


@pytest.mark.parametrize("cmd", [
    ["delta-e", "--e", "20000", "--contact", "2"],
    ["delta-e", "--e", "39000", "--contact", "20"],  # no answer (exit 3): still its output
    ["materials", "show", "copper"],
    ["tables", "show", "ideal-paper"],
])
@pytest.mark.parametrize("json_", [False, True])
def test_out_file_holds_what_the_command_prints_without_format(cli, tmp_path, cmd, json_):
    """--out FILE without --format: the file holds the description for people (or --json's JSON) that stdout
    would have shown, and stdout gets none of it (it was silently printed instead, with exit 0)."""
    flags = ["--json"] if json_ else []
    shown = cli(*cmd, *flags)
    out = tmp_path / "answer.txt"
    r = cli(*cmd, *flags, "--out", out)
    assert r.exit_code == shown.exit_code and r.exit_code in (0, 3), r.output
    assert r.stdout == "" and out.read_text() == shown.stdout and shown.stdout.strip()
    if json_:
        json.loads(out.read_text())


def test_out_file_in_a_missing_folder_is_refused_before_any_work(cli, tmp_path):
    r = cli("delta-e", "--e", "20000", "--out", tmp_path / "nope" / "a.txt")
    assert r.exit_code == 2 and "does not exist" in r.stderr and r.stderr.count("\n") == 1


def test_tables_show_prints_names_from_the_file_as_text(cli, tmp_path):
    """A table's name holding rich markup or control characters is shown as written (markup) or escaped
    (control characters), never interpreted: '[/]' was an internal error with exit 1, an escape sequence
    reached the terminal."""
    from designkit.tables.store import load_table, write_table

    base = load_table("ideal-paper")
    for i, name in enumerate(["bad[/]", "[red]RED[/red] table", "esc\x1b[2Jclear", "two\nlines"]):
        path = write_table(tmp_path / f"t{i}.npz", {**base.header, "name": name}, dict(base.arrays))
        r = cli("tables", "show", path)
        assert r.exit_code == 0, r.output
        first = r.stdout.splitlines()[0]
        assert first.startswith(name if name.isprintable() else repr(name)[1:-1]), first
        assert "\x1b" not in r.stdout


# ---------------------------------------------------------------- --format json|csv|ndjson on every command that answers
# (one shared option and one writer: designkit.cli._format.emit). CSV and ndjson are the records of the JSON.
ANSWERING = [
    ("min-contact", "--e1", "35000", "--e2", "20000"),
    ("max-noise", "--m1", "wood", "--m2", "glass", "--contact", "2"),
    ("min-delta-t", "--e1", "35000", "--e2", "20000", "--contact", "2"),
    ("distinguishable", "--m1", "wood", "--m2", "glass", "--contact", "2"),
    ("delta-e", "--e", "20000", "--contact", "2"),
    ("validity", "--m", "acrylic", "--thickness", "0.003"),
    ("tables", "list"),
]


def _same(a, b):
    """A CSV cell (text) against the JSON value it stands for."""
    if b is None:
        return a == ""
    if isinstance(b, bool):
        return a == str(b)
    if isinstance(b, (int, float)):
        return float(a) == pytest.approx(b, rel=1e-12)
    return a == str(b)


@pytest.mark.parametrize("args", ANSWERING, ids=[" ".join(a[:2]) for a in ANSWERING])
def test_csv_and_ndjson_are_the_same_records(cli, args):
    csv_out, nd_out = cli(*args, "--format", "csv"), cli(*args, "-f", "ndjson")
    assert csv_out.exit_code == 0 and nd_out.exit_code == 0, csv_out.output + nd_out.output
    rows = list(csv.DictReader(io.StringIO(csv_out.stdout)))
    records = [json.loads(line) for line in nd_out.stdout.splitlines()]
    assert rows and len(rows) == len(records)
    for row, rec in zip(rows, records):
        assert list(row) == list(rec)
        bad = {k: (row[k], rec[k]) for k in rec if not _same(row[k], rec[k])}
        assert not bad


@pytest.mark.parametrize("question, args, key", [
    ("min-contact", ("--e1", "35000", "--e2", "20000"), "value"),
    ("distinguishable", ("--m1", "wood", "--m2", "glass", "--contact", "1.5"), "value"),
])
def test_an_answers_record_has_its_json_values(cli, question, args, key):
    d = json.loads(cli(question, *args, "--json").stdout)
    (row,) = list(csv.DictReader(io.StringIO(cli(question, *args, "--format", "csv").stdout)))
    assert _same(row[key], d[key]) and _same(row["interval_low"], d["interval"]["low"])
    assert _same(row["ideal_value"], d["ideal"]["value"]) and row["table_name"] == d["table"]["name"]
    pd = pytest.importorskip("pandas")
    frame = pd.read_csv(io.StringIO(cli(question, *args, "--format", "csv").stdout))
    assert frame.shape[0] == 1 and frame["question"][0] == question


def test_json_flag_is_format_json_and_they_cannot_disagree(cli):
    args = ("min-contact", "--e1", "35000", "--e2", "20000")
    assert cli(*args, "--json").stdout == cli(*args, "--format", "json").stdout
    r = cli(*args, "--json", "--format", "csv")
    assert r.exit_code == 2 and "contradict" in r.output
    r = cli(*args, "--format", "xlsx")  # refused before any work, as JSON when asked with --format json too
    assert r.exit_code == 2 and "ndjson" in r.output


def test_validity_csv_splits_ranges_into_min_and_max(cli):
    (row,) = list(csv.DictReader(io.StringIO(cli("validity", "--m", "acrylic", "--thickness", "0.003",
                                                 "-f", "csv").stdout)))
    d = json.loads(cli("validity", "--m", "acrylic", "--thickness", "0.003", "--json").stdout)
    assert float(row["valid_up_to_s"]) == pytest.approx(d["valid_up_to_s"])
    assert float(row["effusivity_min"]) == d["material_ranges"]["effusivity_range"][0]
    assert float(row["effusivity_max"]) == d["material_ranges"]["effusivity_range"][1]


def test_an_answer_written_with_out(cli, tmp_path):
    out = tmp_path / "a.ndjson"
    r = cli("min-contact", "--e1", "35000", "--e2", "20000", "-f", "ndjson", "--out", str(out))
    assert r.exit_code == 0 and r.stdout == ""
    assert json.loads(out.read_text())["question"] == "min-contact"


def test_f1_record_has_its_json_values(cli):
    args = ("f1", "--e1", "35000", "--e2", "20000", "--trials", "12", "--folds", "2", "--contact", "1")
    d = json.loads(cli(*args, "--json").stdout)
    (row,) = list(csv.DictReader(io.StringIO(cli(*args, "--format", "csv").stdout)))
    assert float(row["svm_f1"]) == pytest.approx(d["svm_f1"]) and float(row["ideal_f1"]) == pytest.approx(d["ideal_f1"])
    assert float(row["contact_s"]) == d["scene"]["contact_s"] == 1.0
    assert float(row["effusivity_min_1"]) == d["objects"][0]["effusivity_range"][0]


def test_simulate_records_are_its_json_curves_one_row_per_sample_time(cli, tmp_path):
    """simulate's csv and ndjson: one row per sample time, time_s then temperature_c_K of touch K, the JSON's
    own numbers (read by the csv module and by pandas); --out FILE alone writes that CSV, stdout empty."""
    args = ("simulate", "--e", "20000", "--contact", "0.05", "--trials", "2", "--seed", "3")
    d = json.loads(cli(*args, "--json").stdout)
    text = cli(*args, "--format", "csv").stdout
    rows = list(csv.DictReader(io.StringIO(text)))
    assert list(rows[0]) == ["time_s", "temperature_c_1", "temperature_c_2"] and len(rows) == len(d["time_s"]) == 11
    for i, row in enumerate(rows):
        assert _same(row["time_s"], d["time_s"][i])
        assert all(_same(row[f"temperature_c_{k + 1}"], d["temperature_c"][k][i]) for k in range(2))
    records = [json.loads(line) for line in cli(*args, "-f", "ndjson").stdout.splitlines()]
    assert records == [{k: float(v) for k, v in row.items()} for row in rows]
    pd = pytest.importorskip("pandas")
    frame = pd.read_csv(io.StringIO(text))
    assert frame["temperature_c_2"].tolist() == d["temperature_c"][1] and frame["time_s"].tolist() == d["time_s"]
    out = tmp_path / "curve.csv"
    r = cli(*args, "--out", out)
    assert r.exit_code == 0 and r.stdout == "" and out.read_text() == text


def test_design_record_is_its_json_recommendation(cli):
    """design's csv and ndjson: one record, the JSON's recommendation (best, flattened), reason and constraints
    under their own names; no design (exit 3) is still one record, its design columns empty."""
    args = ("design", "--m", "a=20000", "--m", "b=35000", "--skin", "Polyetheretherketone (PEEK)",
            "--depth-um", "100:400", "--no-svm")
    d = json.loads(cli(*args, "--json").stdout)
    text = cli(*args, "--format", "csv").stdout
    (row,) = list(csv.DictReader(io.StringIO(text)))
    (rec,) = [json.loads(line) for line in cli(*args, "-f", "ndjson").stdout.splitlines()]
    assert list(row) == list(rec)
    expect = {**{k: v for k, v in d["best"].items() if k not in ("ideal", "limiting")},
              "ideal_value": d["best"]["ideal"]["value"], "ideal_method": "closed-form", "limiting_a": "a",
              "limiting_b": "b", "reason": d["reason"], "max_contact_s": 4.0, "noise_c": 0.05,
              "depth_min_um": 100.0, "depth_max_um": 400.0, "threshold": 0.9,
              "designs_searched": d["designs_searched"], "svm_value": None, "svm_low": None, "svm_high": None}
    assert {k: rec[k] for k in expect} == expect
    assert all(_same(row[k], v) for k, v in expect.items()), row
    pd = pytest.importorskip("pandas")
    frame = pd.read_csv(io.StringIO(text))
    assert frame.shape[0] == 1 and frame["depth_um"][0] == d["best"]["depth_um"] and frame["skin"][0] == d["best"]["skin"]
    r = cli("design", "--m", "a=400", "--m", "b=450", "--no-svm", "--format", "csv")
    assert r.exit_code == 3, r.output
    (none,) = list(csv.DictReader(io.StringIO(r.stdout)))
    assert list(none) == list(row) and none["skin"] == "" and "overlap" in none["reason"]
