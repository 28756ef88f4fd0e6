"""``designkit design``: the recommendation is the grid's best by the ideal observer, checked against the
independent closed form of designkit.recognition.ideal; no design is exit 3, contradictions exit 2."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from designkit.design.search import Constraints, recommend, targets_from
from designkit.recognition.ideal import ideal_pair
from designkit.scene import Scene

PEEK = "Polyetheretherketone (PEEK)"


def test_recommendation_is_the_grid_minimum_and_matches_the_ideal_observer():
    targets = targets_from(["low=20000", "high=35000"])
    cons = Constraints(max_contact_s=4.0, noise_c=0.05, max_delta_t_c=10.0, max_rate_hz=200.0,
                       depth_um=(200.0, 2000.0))
    r = recommend(targets, cons, skins=(PEEK, "Silicone elastomers"), n_depth=4)
    assert r.best.min_contact_s > 0.1  # several samples: the check one sample earlier means something
    best = r.best
    assert best.min_contact_s == min(d.min_contact_s for d in r.designs)
    # independent check (scipy closed form): F1 >= 0.9 at the answer, below it one sample earlier
    sensor, fs = best.sensor(), best.sample_rate_hz
    at = ideal_pair((20000, 20080), (35000, 35080), sensor, Scene(contact_s=best.min_contact_s, noise_c=0.05))
    before = ideal_pair((20000, 20080), (35000, 35080), sensor,
                        Scene(contact_s=best.min_contact_s - 1 / fs, noise_c=0.05))
    assert at.f1 >= 0.9 > before.f1
    # deeper thermistors are slower for one skin (a physical sanity check of the search)
    peek = sorted((d for d in r.designs if d.skin == PEEK), key=lambda d: d.depth_um)
    assert all(a.min_contact_s <= b.min_contact_s for a, b in zip(peek, peek[1:]))
    # noise over dT is the only scene variable: the trade-off curve rises with it
    t = [x for _, x in r.pareto]
    assert all(a <= b for a, b in zip(t, t[1:]))


def test_paper12_at_identified_effusivities_and_overlapping_ranges():
    r = recommend(targets_from(set_name="paper12", identified=True), Constraints(), skins=(PEEK,), n_depth=2)
    assert r.best is not None and len(r.pairs) == 66
    names = {t.name for t in targets_from(set_name="paper12", identified=True)}
    assert set(r.best.limiting_pair) <= names
    # the paper's database ranges overlap (wood and acrylic): no design separates them
    r = recommend(targets_from(["wood", "Polymethyl methacrylate (Acrylic, PMMA)"]), Constraints(), skins=(PEEK,))
    assert r.best is None and "overlap" in r.reason


def test_cli_json_with_svm_confirmation(cli, tmp_path):
    r = cli("design", "--m", "a=20000", "--m", "b=35000", "--skin", PEEK, "--depth-um", "400:400", "--json",
            "--plot", str(tmp_path / "d.png"))
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    svm, pred = out["svm"], out["svm"]["prediction"]
    assert out["best"]["skin"] == PEEK and svm["value"] is not None and pred["value"] is not None
    # the statement and its confirmation: the same quantity (the crossing of the SVM's mean F1), each with an
    # interval, the confirmation from fresh seeds; neither beats the ideal observer's bound
    assert min(svm["value"], pred["value"]) >= out["best"]["ideal"]["value"]
    assert svm["seed"] != pred["seed"] and svm["seeds"] == 4 * pred["repeats"]
    assert pred["interval"]["low"] <= pred["value"] <= pred["interval"]["high"]
    assert svm["holds"] == (pred["interval"]["low"] - 0.005 - 1e-9 <= svm["value"] <= pred["interval"]["high"] + 0.005 + 1e-9)
    assert pred["counted_from"] == "first contact"  # the paper's sensor: no rig onset
    assert (tmp_path / "d.png").stat().st_size > 10_000
    # its csv record (one row, built from this JSON document): the SVM's confirmation as svm_*, the figure
    import csv
    import io

    from designkit.cli._format import render_rows
    from designkit.cli.design import _record

    (row,) = list(csv.DictReader(io.StringIO(render_rows([_record(out)], fmt="csv"))))
    assert float(row["svm_value"]) == svm["value"] and float(row["svm_high"]) == svm["interval"]["high"]
    assert float(row["svm_prediction_value"]) == pred["value"] and row["svm_holds"] == str(svm["holds"])
    assert float(row["svm_minus_ideal_s"]) == svm["svm_minus_ideal_s"] and row["svm_note"] == ""
    assert row["figure"] == out["figure"] and row["skin"] == PEEK and "svm_svm_value" not in row


@pytest.mark.parametrize("args,code,msg", [
    (["--m", "wood", "--m", "Polymethyl methacrylate (Acrylic, PMMA)"], 3, "overlap"),
    # two single values 50 apart: the classes judged, and why they overlap, are said
    (["--m", "a=400", "--m", "b=450"], 3, "a [400, 480) and b [450, 530) overlap in effusivity (each material is "
                                          "judged as a class 80"),
    (["--m", "a=20000", "--m", "b=20100", "--max-contact", "0.5", "--skin", PEEK, "--depth-um", "400:400"], 3,
     "no allowed design"),
    # a set whose handbook ranges overlap but which gives identified effusivities: the reason says what to do
    (["--set", "paper12"], 3, "overlap in effusivity"),
    (["--set", "paper12", "--sensor", str(Path(__file__).parent / "data" / "rig_sensor.yaml")], 3,
     "the paper12 set's handbook ranges overlap, so judge its materials at their identified effusivities with "
     "--identified"),
    (["--m", "a=1000", "--m", "b=2000", "--depth-um", "500:20"], 2, "contradict"),
    (["--m", "a=1000", "--m", "b=2000", "--max-rate", "10", "--max-contact", "0.05"], 2, "contradict"),
    (["--m", "a=1000"], 2, "at least two"),
    (["--m", "a=1000", "--m", "b=2000", "--noise", "-1"], 2, "noise floor"),
    # a touch of more samples than any other command allows: the search ran on, 8-9 GB in 25 s
    (["--m", "a=1000", "--m", "b=2000", "--max-rate", "1e9"], 2, "samples per touch; the limit is 1e+06"),
    (["--m", "a=1000", "--m", "b=2000", "--max-contact", "1e6"], 2, "samples per touch; the limit is 1e+06"),
])
def test_cli_no_design_and_bad_input(cli, args, code, msg):
    r = cli("design", "--no-svm", *args)
    assert r.exit_code == code, r.output
    assert msg in r.output and len(r.output.strip().splitlines()) == 1


def test_set_means_ranges_as_in_matrix_unless_identified_is_asked():
    """`--set paper12` is the set's ranges in design as in matrix (one meaning per flag); the paper's
    handbook ranges overlap (Cardboard / Wood), so only the identified effusivities give a design."""
    ranges = {t.name: t.e_range for t in targets_from(set_name="paper12")}
    assert all(t.e_low != t.e_low for t in targets_from(set_name="paper12"))  # NaN: judged by its range
    from designkit.query.matrix import resolve_materials
    assert ranges == {m.name: (m.e_min, m.e_max) for m in resolve_materials(set="paper12")}
    assert recommend(targets_from(set_name="paper12"), Constraints(), skins=(PEEK,), n_depth=2).best is None
