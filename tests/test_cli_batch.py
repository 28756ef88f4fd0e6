"""``--batch FILE``: a CSV of pairs and scenes in, answered as one array call of the library
(designkit.io_batch), one record per row out; bad input is one line naming the line and column, exit 2."""

from __future__ import annotations

import csv
import io
import json

import pytest

from designkit._validation import InputError
from designkit.io_batch import answer_batch, read_batch


def _write(tmp_path, text, name="pairs.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_each_row_is_the_single_answer_and_missing_columns_take_the_options(cli, tmp_path):
    p = _write(tmp_path, "e1,e2,noise\n35000,20000,0.05\n35000,20000,\n30000,1000,0.1\n")
    r = cli("min-contact", "--batch", p, "--delta-t", "7", "--noise", "0.02", "--format", "csv")
    assert r.exit_code == 0, r.output
    rows = list(csv.DictReader(io.StringIO(r.stdout)))
    assert [float(x["noise_c"]) for x in rows] == [0.05, 0.02, 0.1]   # the empty cell: --noise
    assert {float(x["delta_t_c"]) for x in rows} == {7.0}               # the column left out: --delta-t
    for row in rows:
        one = json.loads(cli("min-contact", "--e1", row["e1"], "--e2", row["e2"], "--noise", row["noise_c"],
                             "--delta-t", "7", "--json").stdout)
        assert float(row["value"]) == pytest.approx(one["value"])
        assert float(row["interval_low"]) == pytest.approx(one["interval"]["low"])


def test_materials_by_name_and_every_format(cli, tmp_path):
    p = _write(tmp_path, "m1,m2,contact\ncopper,wood,1\nglass,wood,2\ncopper,wood,3\n")
    nd = cli("distinguishable", "--batch", p, "-f", "ndjson")
    assert nd.exit_code == 0, nd.output
    recs = [json.loads(x) for x in nd.stdout.splitlines()]
    assert [(x["m1"], x["contact_s"]) for x in recs] == [("copper", 1.0), ("glass", 2.0), ("copper", 3.0)]
    assert json.loads(cli("distinguishable", "--batch", p, "--json").stdout) == recs
    assert cli("distinguishable", "--batch", p).exit_code == 0  # text: the records as a table


def test_delta_e_reads_its_reference_column(cli, tmp_path):
    p = _write(tmp_path, "e,contact\n20000,1\n20000,2\n")
    rows = list(csv.DictReader(io.StringIO(cli("delta-e", "--batch", p, "-f", "csv").stdout)))
    assert [float(x["contact_s"]) for x in rows] == [1.0, 2.0] and float(rows[0]["lower"]) > float(rows[1]["lower"])


def test_stdin(cli):
    r = cli("min-contact", "--batch", "-", "-f", "csv", input="e1,e2\n35000,20000\n")
    assert r.exit_code == 0 and len(r.stdout.splitlines()) == 2


@pytest.mark.parametrize("text, words", [
    (None, "no such file"),
    ("", "is empty"),
    ("e1,e2\n", "no rows"),
    ("e1,e2,colour\n1,2,red\n", "unknown column 'colour'"),
    ("e1,e2\n35000,abc\n", "line 2, column e2: 'abc' is not a number"),
    ("e1,e2\n35000,20000\n35000,inf\n", "line 3, column e2"),
    ("e1,e2\n35000\n", "line 2: 1 cells"),
    ("e1,m2\n35000,wood\n", "not both"),
    ("e1\n35000\n", "without e2"),
    ("e1,e2,noise\n35000,20000,0.05\n35000,20000,-1\n", "noise_c (line 3)"),
    ("e1,e2,e1\n1,2,3\n", "given twice"),
])
def test_bad_batch_is_one_line_exit_2(cli, tmp_path, text, words):
    p = tmp_path / "missing.csv" if text is None else _write(tmp_path, text)
    r = cli("min-contact", "--batch", p, "-f", "csv")
    assert r.exit_code == 2, r.output
    assert words in r.output and "Traceback" not in r.output and r.stdout.count("\n") <= 1


def test_over_the_per_call_limit(tmp_path):
    with pytest.raises(InputError, match="more than 3 rows"):
        read_batch(io.StringIO("e1,e2\n" + "35000,20000\n" * 4), "min-contact", max_rows=3)


def test_one_array_call_for_numbers():
    b = read_batch(io.StringIO("e1,e2,noise\n35000,20000,0.05\n30000,1000,0.1\n"), "min-contact")
    from designkit.query import min_contact

    arr = min_contact([35000, 30000], [20000, 1000], noise_c=[0.05, 0.1]).to_dict()
    got = answer_batch(b)
    assert [g["value"] for g in got] == [a["value"] for a in arr]
