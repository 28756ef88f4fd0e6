"""Queries: interpolation against closed forms on synthetic tables, the shipped tables,
the exact route, and the CLI contract."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designkit import InputError
from designkit.query import table as q
from designkit.sweep import SweepConfig
from designkit.tables.store import load_table, table_header, write_table

RATIOS = (0.001, 0.002, 0.005, 0.01, 0.02)
CONTACTS = (0.5, 1.0, 2.0, 4.0)
A, B, K = 9000.0, 2000.0, 0.4  # delta = (A - B t) * (1 + K ln(r / 0.001)), any e


def _delta(t, r):
    return (A - B * t) * (1 + K * math.log(r / 0.001))


@pytest.fixture(scope="module")
def linear_table(tmp_path_factory):
    """A table whose delta is linear in contact time and in log(sigma/dT): interpolation is exact.

    It has no ideal arrays: min-contact's efficiency route (which needs the table's ideal arrays to be the
    closed-form ideal observer's) does not apply, and the interpolation route is what is tested here."""
    cfg = SweepConfig(name="linear", intervals=40, noise_ratio=RATIOS, contact_s=CONTACTS)
    d = np.array([[[_delta(t, r)] * 40 for t in CONTACTS] for r in RATIOS])
    arrays = {name: d.copy() for name in ("delta_up", "delta_down")}
    arrays.update(delta_up_lo=d * 0.9, delta_down_lo=d * 0.9, delta_up_hi=d * 1.1, delta_down_hi=d * 1.1,
                  fits=np.zeros((5, 4), dtype=np.int64), chunk_wall_s=np.zeros((5, 4)))
    path = write_table(tmp_path_factory.mktemp("t") / "linear.npz", table_header(cfg, arrays), arrays)
    return load_table(path)


@settings(max_examples=60, deadline=None)
@given(noise=st.floats(0.011, 0.19), gap=st.floats(2500, 9000), base=st.floats(100, 20000))
def test_min_contact_interpolates_exactly(linear_table, noise, gap, base):
    r = noise / 10.0
    ans = q.min_contact(base, base + gap, noise_c=noise, delta_t_c=10.0, table=linear_table, ideal_table=None)
    scale = 1 + K * math.log(r / 0.001)
    exact = (A - gap / scale) / B  # solves delta(t, r) = gap
    if exact <= CONTACTS[0]:
        assert ans.value == CONTACTS[0]
    elif exact > CONTACTS[-1]:
        assert ans.value is None
    else:
        # the grid's raw linear crossing is exact on this table; the answer corrects it for the grid's
        # rounding of delta (half a width) and interpolates log-log
        raw = ans.computation.get("table_crossing_s", ans.value)
        assert raw == pytest.approx(exact, rel=1e-9)
        # interpolated between two tabulated contacts: an interval at the stated coverage around the answer
        # (Monte Carlo ends and interpolation error), never below the bound
        bound = ans.ideal if ans.ideal is not None else -math.inf
        d = ans.to_dict()["interval"]
        assert d["method"] == "table-estimate" and d["coverage"] == 0.9
        assert d["low"] <= ans.value <= d["high"] and d["low"] < d["high"]
        assert d["low"] >= min(bound, ans.value) - 1e-12  # (this synthetic table's answers may lie below it)
    assert ans.in_grid == {"noise_ratio": True, "effusivity": True}


def test_max_noise_and_min_delta_t_interpolate_exactly(linear_table):
    t, gap = 2.0, 9000.0
    # delta(t, r) = gap  =>  ln(r/0.001) = (gap / (A - B t) - 1) / K
    r_star = 0.001 * math.exp((gap / (A - B * t) - 1) / K)
    mn = q.max_noise(1000, 1000 + gap, contact_s=t, delta_t_c=10.0, table=linear_table, ideal_table=None)
    # the grid's raw crossing is exact on this table (the answer corrects it for the grid's rounding)
    assert mn.computation["table_crossing_noise_ratio"] == pytest.approx(r_star, rel=1e-9)
    md = q.min_delta_t(1000, 1000 + gap, contact_s=t, noise_c=0.05, table=linear_table, ideal_table=None)
    assert md.computation["table_crossing_noise_ratio"] == pytest.approx(r_star, rel=1e-9)
    assert mn.value == pytest.approx(0.05 * 10.0 / md.value, rel=1e-9)  # one crossing answers both
    de = q.delta_e(20000, contact_s=3.0, noise_c=0.05, delta_t_c=10.0, table=linear_table, ideal_table=None)
    assert de.extra["delta_e_lower"] == pytest.approx(_delta(3.0, 0.005), rel=1e-12)


def test_outside_the_grid_is_refused_not_extrapolated(linear_table):
    far = q.min_contact(1000, 9000, noise_c=1.0, delta_t_c=10.0, table=linear_table, ideal_table=None)
    assert far.value is None and far.in_grid["noise_ratio"] is False and "no extrapolation" in far.note
    out = q.min_contact(1000, 45000, noise_c=0.05, delta_t_c=10.0, table=linear_table, ideal_table=None)
    assert out.value is None and out.in_grid["effusivity"] is False
    assert q.delta_e(2000, contact_s=20.0, table=linear_table, ideal_table=None).in_grid["contact_s"] is False


def test_nan_means_beyond_the_grid_and_is_never_interpolated_into(tmp_path):
    cfg = SweepConfig(name="nan", intervals=10, noise_ratio=(0.005,), contact_s=(1.0, 2.0, 3.0))
    d = np.array([[[np.nan] * 10, [3000.0] * 10, [1000.0] * 10]])
    arrays = {"delta_up": d, "delta_down": d, "fits": np.zeros((1, 3), dtype=np.int64),
              "chunk_wall_s": np.zeros((1, 3))}
    t = load_table(write_table(tmp_path / "nan.npz", table_header(cfg, arrays), arrays))
    ans = q.min_contact(1000, 5000, table=t, ideal_table=None)
    assert ans.value == 2.0  # 1 s has no answer: 2 s is the first that suffices, no interpolation into NaN
    assert q.min_contact(1000, 3000, table=t, ideal_table=None).value == pytest.approx(2.5)  # 3000 -> 1000 over 2-3 s


def test_table_threshold_and_sensor_must_match(linear_table, tmp_path):
    with pytest.raises(InputError, match="threshold 0.9"):
        q.min_contact(1000, 5000, threshold=0.95, table=linear_table)
    other = tmp_path / "s.yaml"
    from designkit import Sensor

    Sensor(1000.0, 1e-9, name="other").to_yaml(other)
    with pytest.raises(InputError, match="built for sensor"):
        q.min_contact(1000, 5000, table=linear_table, sensor=other)


@pytest.mark.parametrize("kwargs,match", [
    ({"e1": 1000, "e2": 1000}, "equal"),
    ({"e1": -5, "e2": 1000}, "positive"),
    ({"e1": float("nan"), "e2": 1000}, "number"),
    ({"e1": 1000, "e2": 5000, "delta_t_c": 0}, "temperature difference is 0"),
    ({"e1": 1000, "e2": 5000, "noise_c": -1}, "noise"),
])
def test_query_rejects_bad_input(kwargs, match):
    with pytest.raises(InputError, match=match):
        q.min_contact(table="ideal-paper", **kwargs)


def test_ideal_table_agrees_with_the_closed_form(paper_sensor):
    """Shipped ideal table vs bisection on the exact closed form: within its grid step."""
    from designkit.recognition.ideal import ideal_pair
    from designkit.scene import Scene

    t = load_table("ideal-paper")
    rng = np.random.default_rng(1)
    for _ in range(6):
        e1 = rng.uniform(200, 30000)
        e2 = e1 * rng.uniform(1.2, 3.0)
        if e2 > 39000:
            continue
        noise = rng.uniform(0.01, 0.15)
        ans = q.min_contact(e1, e2, noise_c=noise, delta_t_c=10.0, table=t, ideal_table=t)
        lo, hi = (e1, e1 + 80), (e2, e2 + 80)

        def ok(c):
            return ideal_pair(lo, hi, paper_sensor, Scene.from_delta_t(contact_s=c, noise_c=noise,
                                                                       delta_t_c=10.0)).f1 >= 0.9

        if ans.value is None:
            assert not ok(9.75)
            continue
        a, b = 0.05, 10.0
        if ok(a):
            exact = a
        else:
            for _ in range(30):
                m = 0.5 * (a + b)
                a, b = (a, m) if ok(m) else (m, b)
            exact = b
        # one contact step (0.25 s) plus the effusivity interval width of the table
        assert abs(ans.value - exact) <= 0.3, (e1, e2, noise, ans.value, exact)


@settings(max_examples=40, deadline=None)
@given(e1=st.floats(100, 30000), ratio=st.floats(1.05, 4.0), n1=st.floats(0.005, 0.1), dn=st.floats(0.001, 0.08))
def test_more_noise_never_needs_less_contact(e1, ratio, n1, dn):
    e2 = min(e1 * ratio, 39900.0)
    t = load_table("ideal-paper")
    a = q.min_contact(e1, e2, noise_c=n1, table=t, ideal_table=t).value
    b = q.min_contact(e1, e2, noise_c=n1 + dn, table=t, ideal_table=t).value
    if a is None:
        assert b is None
    elif b is not None:
        assert b >= a - 1e-9


PAPER12 = ("Cardboard", "Wood", "ABS", "Rubber", "MDF", "Acrylic", "Porcelain", "Glass", "Granite",
           "Stainless Steel", "Aluminum", "Copper")


def test_materials_rule_answers_for_the_facing_edges(cli):
    """Materials: the hardest pair, one class width at the facing edges; the same rule on both routes."""
    from designkit.query import pair_question

    pq = pair_question(m1="paper12:copper", m2="paper12:stainless steel")
    ss, cu = pq.classes
    assert ss.e_range == pytest.approx((10184.17 - 80, 10184.17)) and cu.e_range == pytest.approx((23049.18,
                                                                                                   23129.18))
    ans = q.min_contact(m1="paper12:copper", m2="paper12:stainless steel", table="ideal-paper",
                        ideal_table="ideal-paper")
    edge = q.min_contact(10184.17 - 80, 23049.18, table="ideal-paper", ideal_table="ideal-paper")
    assert ans.value == edge.value and ans.ideal == edge.ideal
    assert ans.materials_rule.startswith("materials: the hardest pair")
    assert [o["material"] for o in ans.to_dict()["objects"]] == ["Copper", "Stainless Steel"]
    assert [o["effusivity_range"] for o in ans.to_dict()["limiting_pair"]] == [list(ss.e_range), list(cu.e_range)]
    overlap = q.min_contact(m1="paper12:copper", m2="paper12:aluminum", table="ideal-paper")
    assert overlap.value is None and "overlap" in overlap.note and overlap.to_dict()["limiting_pair"] == []
    r = cli("min-contact", "--m1", "copper", "--m2", "stainless steel", "--table", "ideal-paper", "--json")
    assert r.exit_code == 0 and json.loads(r.stdout)["materials_rule"].startswith("materials: the hardest pair")
    r = cli("min-contact", "--m1", "unobtainium", "--m2", "copper")
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1


@pytest.mark.slow
def test_materials_edge_pair_against_the_old_nine_by_nine_worst_case():
    """On the shipped svm-paper table, the paper's 12 materials' non-overlapping pairs: the facing-edge answer
    (classes inside the materials) against the worst case over a 9 x 9 grid of effusivity pairs (the rule
    before the redesign). The grid's closest pair (a_max, b_min) stands for the classes [a_max, a_max + 80)
    and [b_min, b_min + 80): one class width closer than the materials' facing edges, so the edge answer
    never needs more contact. Measured: equal in 30 of the 55 pairs (those far apart, where both are the
    table's shortest contact), within 0.07 s wherever the materials are more than 1000 apart, and up to 1.2 s
    less for the closest pairs (porcelain vs glass, 99 apart: 1.21 s instead of 2.38 s), where one class
    width is most of the gap; three pairs closer than one width (cardboard-ABS, wood-ABS, rubber-MDF) had no
    grid answer and now have one. (Since min-contact reads the SVM's efficiency against the exact ideal
    observer, far-apart pairs no longer share the table's shortest contact, so equality is rare; the edge
    answer is still never the more demanding.)"""
    from designkit.materials import get_material
    from designkit.query import ask

    tab = load_table("svm-paper")
    mats = {n: get_material(f"paper12:{n}").effusivity_range for n in PAPER12}
    compared = same = 0
    for i, a in enumerate(PAPER12):
        for b in PAPER12[i + 1:]:
            (a0, a1), (b0, b1) = sorted([mats[a], mats[b]])
            if max(a0, b0) < min(a1, b1):
                continue
            edge = q.min_contact(m1=f"paper12:{a}", m2=f"paper12:{b}", table=tab, ideal_table=None).value
            x, y = np.meshgrid(np.linspace(a0, a1, 9), np.linspace(b0, b1, 9), indexing="ij")
            keep = x != y
            grid = ask("min-contact", route="table", e1=x[keep], e2=y[keep], table=tab, ideal_table=None,
                       ideal_bound=False).value  # one array call (the scalar route's values), NaN: no answer
            worst = None if np.isnan(grid).any() else float(grid.max())
            compared += 1
            assert edge is not None, (a, b)
            if worst is None:
                assert b0 - a1 < 80.0, (a, b)  # the old grid's closest pair overlapped as classes
                continue
            assert edge <= worst + 1e-12, (a, b, edge, worst)
            same += edge == worst
            if b0 - a1 > 1000.0:
                assert worst - edge < 0.07, (a, b, edge, worst)
    assert compared == 55 and same >= 1


@pytest.mark.parametrize("cmd,quantity", [
    (["min-contact", "--e1", "35000", "--e2", "20000"], "contact_s"),
    (["max-noise", "--e1", "35000", "--e2", "20000", "--contact", "2"], "noise_c"),
    (["min-delta-t", "--e1", "35000", "--e2", "20000", "--contact", "2"], "delta_t_c"),
    (["delta-e", "--e", "20000", "--contact", "2"], "delta_e"),
    (["distinguishable", "--e1", "35000", "--e2", "20000", "--contact", "2"], "distinguishable"),
])
def test_query_cli_json_is_the_answer_schema(cli, cmd, quantity):
    from designkit.query import ANSWER_KEYS

    r = cli(*cmd, "--table", "ideal-paper", "--json")
    assert r.exit_code == 0, r.output
    p = json.loads(r.stdout)
    assert set(p) == ANSWER_KEYS
    assert p["route"] == "table" and p["quantity"] == quantity and p["table"]["name"] == "ideal-paper"
    assert p["table"]["content_hash"].startswith("sha256:") and p["sensor"]["name"] == "paper"
    assert p["model"]["name"] == "semi-infinite" and p["threshold"] == 0.9 and all(p["in_grid"].values())
    assert set(p["scene"]) == {"contact_s", "noise_c", "delta_t_c", "noise_ratio"}
    assert set(p["interval"]) == {"low", "high", "meaning", "coverage", "method"}
    assert set(p["ideal"]) == {"value", "method"}
    if cmd[0] == "delta-e":
        assert set(p["details"]) == {"effusivity", "lower", "upper"}
    if cmd[0] == "distinguishable":
        assert p["value"] is True and p["details"]["svm_f1"] is None and p["details"]["ideal_f1"] > 0.9


@pytest.mark.parametrize("cmd", [
    ["min-contact", "--e1", "35000", "--e2", "20000"],
    ["delta-e", "--e", "20000", "--contact", "2"],
    ["distinguishable", "--e1", "35000", "--e2", "20000", "--contact", "2"],
])
def test_an_ideal_observer_tables_answer_is_not_called_the_svms(cli, cmd):
    """With --table ideal-paper the main line is the ideal observer's on that table's grid, never "SVM"; delta-e
    prints no empty interval, and no legend for a dash it did not print."""
    r = cli(*cmd, "--table", "ideal-paper")
    assert r.exit_code == 0, r.output
    assert "SVM" not in r.stdout and "ideal observer on table ideal-paper's grid" in r.stdout, r.stdout
    assert "—" not in r.stdout, r.stdout
    svm = cli(*cmd)  # the default table is an SVM table: its answer keeps its name
    assert svm.exit_code == 0 and "SVM" in svm.stdout


def test_the_same_question_has_the_same_keys_on_every_route():
    """Table, exact (semi-infinite) and exact with a slab (the former thin route): identical --json keys,
    at every level that is not route-specific (``computation`` is)."""
    from designkit.models.slab import Slab
    from designkit.query import ANSWER_KEYS, ask

    fast = dict(trials=12, folds=3, repeats=1, jobs=1, n_mc=50)
    slab = Slab(1.0, "table")  # thick: the closed-form ideal observer answers
    cases = {"min-contact": dict(noise_c=0.05, delta_t_c=10.0),
             "max-noise": dict(contact_s=0.5, delta_t_c=10.0),
             "min-delta-t": dict(contact_s=0.5, noise_c=0.05),
             "delta-e": dict(contact_s=0.3, noise_c=0.05, delta_t_c=10.0),
             "distinguishable": dict(contact_s=0.5, noise_c=0.05, delta_t_c=10.0)}
    for question, scene in cases.items():
        objs = dict(e=20000.0) if question == "delta-e" else dict(e1=35000.0, e2=20000.0)
        extra = {"min-contact": dict(max_contact_s=1.0, tolerance_s=0.2),
                 "delta-e": dict(e_max=22000.0)}.get(question, {})
        answers = [ask(question, route="table", **objs, **scene, table="ideal-paper").to_dict(),
                   ask(question, route="exact", **objs, **scene, **fast, **extra).to_dict(),
                   ask(question, route="exact", **objs, **scene, **fast, **extra, model=slab,
                       diffusivity_m2_s=1e-5).to_dict()]
        for d in answers:
            assert set(d) == ANSWER_KEYS, question
            for key in ("interval", "ideal", "scene", "details"):
                assert set(d[key]) == set(answers[0][key]), (question, key)
            assert d["question"] == question and d["quantity"] == answers[0]["quantity"]
        assert [d["route"] for d in answers] == ["table", "exact", "exact"]
        assert answers[2]["model"]["name"] == "slab" and answers[2]["model_check"]["details"]["semi_infinite_holds"]
        assert answers[1]["table"] is None and answers[0]["table"]["name"] == "ideal-paper"


def test_table_route_refuses_another_model_and_says_where_a_question_is_outside(linear_table):
    from designkit.query import TableMismatch

    with pytest.raises(TableMismatch, match="built for the semi-infinite model, not the contact"):
        q.min_contact(1000, 5000, table=linear_table, model="contact")
    far = q.min_contact(1000, 9000, noise_c=1.0, delta_t_c=10.0, table=linear_table, ideal_table=None)
    assert "noise 1 degC at dT 10 degC (sigma/dT 0.1) outside table linear's sigma/dT [0.001, 0.02]" in far.note
    assert "it answers for noise 0.01 to 0.2 degC" in far.note  # the range in the user's units
    late = q.delta_e(2000, contact_s=20.0, table=linear_table, ideal_table=None)
    assert "contact time 20 s outside table linear's [0.5, 4] s" in late.note


def test_library_errors_speak_in_library_terms():
    """No CLI flag in a message the question layer writes (the CLI adds the hints)."""
    import pathlib
    import re

    import designkit.query as pkg

    for path in pathlib.Path(pkg.__file__).parent.glob("*.py"):
        for line in path.read_text().splitlines():
            if re.search(r"""(Error|Mismatch|NeedsInput|note)\b.*["'][^"']*--[a-z]""", line):
                raise AssertionError(f"{path.name}: {line.strip()}")


@pytest.mark.parametrize("args,needle", [
    (["min-contact", "--e1", "20000", "--e2", "20000"], "equal"),
    (["min-contact", "--e1", "-1", "--e2", "20000"], "positive"),
    (["min-contact", "--e1", "nan", "--e2", "20000"], "number"),
    (["min-contact", "--e1", "35000"], "two objects"),
    (["distinguishable", "--e1", "1", "--e2", "2", "--contact", "0"], "contact"),
    (["min-contact", "--e1", "1", "--e2", "2", "--table", "/nonexistent/t"], "no table"),
    (["min-contact", "--e1", "1", "--e2", "2", "--table", "ideal-paper", "--threshold", "0.95"], "threshold"),
])
def test_query_cli_bad_input(cli, args, needle):
    r = cli(*args)
    assert r.exit_code == 2, r.output
    assert len(r.stderr.strip().splitlines()) == 1 and needle in r.stderr


def test_table_query_path_never_imports_scikit_learn():
    code = ("import sys; from typer.testing import CliRunner; from designkit.cli import app;"
            "r = CliRunner().invoke(app, ['min-contact', '--e1', '35000', '--e2', '20000', '--table', 'ideal-paper', '--json']);"
            "assert r.exit_code == 0, r.output;"
            "print(','.join(m for m in ('sklearn', 'matplotlib', 'dask', 'joblib') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


@pytest.mark.slow
def test_exact_min_contact_cli(cli):
    r = cli("min-contact", "--e1", "35000", "--e2", "20000", "--exact", "--trials", "30", "--repeats", "2",
            "--jobs", "1", "--json")
    assert r.exit_code == 0, r.output
    p = json.loads(r.stdout)
    assert p["route"] == "exact" and p["table"] is None
    assert 0.5 < p["value"] < 3.0
    lo, hi = p["interval"]["low"], p["interval"]["high"]
    assert lo <= p["value"] and (hi is None or hi >= p["value"] - 0.06)
    assert p["ideal"]["value"] <= p["value"] + 0.05 and p["ideal"]["method"] == "closed-form"


@pytest.mark.slow
def test_exact_routes_of_the_other_pair_questions_through_the_cli(cli):
    """max-noise, min-delta-t and distinguishable --exact: the CLI gives the library's computed answer,
    and the answers agree with each other (the noise that is just tolerated at dT 10 °C is the
    noise/dT ratio min-delta-t finds at that noise)."""
    small = ("--exact", "--trials", "30", "--repeats", "1", "--jobs", "1", "--json")
    pair = ("--e1", "35000", "--e2", "20000", "--contact", "1.5")
    mn = json.loads(cli("max-noise", *pair, "--delta-t", "10", *small).stdout)
    from designkit.query import exact_max_noise

    lib = exact_max_noise(35000, 20000, contact_s=1.5, delta_t_c=10, trials=30, repeats=1, jobs=1)
    assert mn["route"] == "exact" and mn["value"] == pytest.approx(lib.value)
    assert mn["ideal"]["value"] >= mn["value"]  # no classifier beats the ideal observer
    dt = json.loads(cli("min-delta-t", *pair, "--noise", str(mn["value"]), *small).stdout)
    assert dt["value"] == pytest.approx(10.0, rel=0.1)
    yes = json.loads(cli("distinguishable", *pair, "--noise", str(0.5 * mn["value"]), *small).stdout)
    no = json.loads(cli("distinguishable", *pair, "--noise", str(4 * mn["value"]), *small).stdout)
    assert yes["value"] is True and no["value"] is False
    assert yes["details"]["svm_f1"] >= 0.9 > no["details"]["svm_f1"]


def test_an_unreadable_ideal_table_is_an_error_not_a_silent_fallback():
    from designkit.query import table as qt

    with pytest.raises(InputError, match="nosuch"):
        qt.min_contact(35000, 20000, ideal_table="nosuch")


def test_the_bound_is_computed_in_closed_form_whatever_tables_there_are(tmp_path):
    """The ideal bound is never read from a grid (a grid-read bound was 1.12 s where the truth is
    1.05 s): an SVM table with no ideal arrays and no ideal table still gets the exact bound."""
    from designkit.query import table as qt

    t = load_table("svm-paper")
    arrays = {k: v for k, v in t.arrays.items() if "ideal" not in k}
    header = dict(t.header, name="svm-no-ideal",
                  arrays={k: v for k, v in t.header["arrays"].items() if "ideal" not in k})
    header.pop("content_hash", None)
    path = write_table(tmp_path / "svm-no-ideal.npz", header, arrays)
    alone = qt.min_contact(35000, 20000, table=str(path), ideal_table=None)
    d = alone.to_dict()
    assert d["ideal"] == {"value": 1.05, "method": "closed-form"} and d["ideal_table"] is None


def test_the_table_routes_bound_is_never_above_the_exact_bound():
    """0 violations over random pairs and noise ratios: the bound the table route reports is the
    closed form's first sample time (checked against scipy's closed form in test_bench)."""
    from designkit.query import table as qt
    from designkit.query.ideal_bound import exact_ideal_min_contact
    from designkit.sensor import load_sensor

    rng = np.random.default_rng(13)
    paper = load_sensor("paper")
    for _ in range(6):
        lo = float(rng.uniform(200, 30000))
        hi = lo + float(rng.uniform(400, 8000))
        noise = float(rng.choice([0.01, 0.05, 0.1]))
        a = qt.min_contact(hi, lo, noise_c=noise, delta_t_c=10.0)
        edges = [c["effusivity_range"][0] if "effusivity_range" in c else None for c in a.to_dict()["limiting_pair"]]
        exact = exact_ideal_min_contact(paper, *(edges if None not in edges else (lo, hi)), noise / 10.0)
        if a.ideal is not None:
            assert a.ideal <= float(exact) + 1e-12 and a.ideal_bound.method == "closed-form"


def test_a_question_the_table_cannot_answer_exits_3_and_bad_coverage_exits_2(cli):
    """Exit 3 (no answer here, with the quantity and its range) is distinct from bad input (2)."""
    r = cli("min-contact", "--e1", "39990", "--e2", "39000", "--noise", "0.1")
    assert r.exit_code == 3 and "contact time up to 10 s" in r.output
    r = cli("min-contact", "--e1", "35000", "--e2", "20000", "--coverage", "1.5")
    assert r.exit_code == 2 and "coverage must lie in (0, 1)" in r.output
    # outside the table's axes: every question exits 3 and names the axis and its range in user units
    for cmd in (("min-contact", "--e1", "35000", "--e2", "20000", "--noise", "1"),
                ("max-noise", "--e1", "35000", "--e2", "20000", "--contact", "20"),
                ("min-delta-t", "--e1", "35000", "--e2", "20000", "--contact", "0.2"),
                ("delta-e", "--e", "20000", "--noise", "1"),
                ("distinguishable", "--e1", "35000", "--e2", "20000", "--contact", "20")):
        r = cli(*cmd)
        assert r.exit_code == 3, (cmd, r.output)
        assert ("noise 0.005 to 0.5 degC" in r.output or "contact time" in r.output), r.output
        assert cli(*cmd, "--coverage", "0").exit_code == 2


def test_exact_min_contact_is_an_estimate_with_a_stated_coverage():
    from designkit.query import exact_min_contact

    a = exact_min_contact(35000, 20000, trials=30, repeats=2, jobs=1, coverage=0.9)
    d = a.to_dict()
    assert d["interval"]["coverage"] == 0.9 and "confidence interval" in d["interval"]["meaning"]
    assert d["ideal"] == {"value": 1.05, "method": "closed-form"}
    assert 1.05 <= d["interval"]["low"] <= d["value"] <= d["interval"]["high"] < 3.0


def test_tables_named_by_string_are_loaded_once_per_process_while_unchanged(tmp_path):
    """A name or path is read and verified once; an edited file is read again (and refused if corrupt)."""
    import shutil

    from designkit.query import table as qt
    from designkit.tables.store import resolve_table

    src = resolve_table("ideal-paper")
    for suffix in (".npz", ".json"):
        shutil.copy(src.with_suffix(suffix), tmp_path / f"copy{suffix}")
    path = str(tmp_path / "copy.npz")
    qt.clear_table_cache()
    first = qt._as_table(path)
    assert qt._as_table(path) is first  # cached: the same object
    header = tmp_path / "copy.json"
    header.write_text(header.read_text().replace('"created"', '"created" ', 1))  # touched: size changes
    assert qt._as_table(path) is not first
    (tmp_path / "copy.npz").write_bytes(b"not a table")
    with pytest.raises(InputError):
        qt._as_table(path)
    qt.clear_table_cache()


@pytest.mark.parametrize("question", ["min-contact", "distinguishable"])
def test_overlapping_materials_exit_3_with_the_reason(cli, question):
    """No scene separates materials whose effusivity ranges overlap: no answer, the documented status 3 (as
    `design` gives for the same pair), the reason in the text and null in --json."""
    r = cli(question, "--m1", "copper", "--m2", "aluminium")
    assert r.exit_code == 3, r.output
    assert "overlap" in r.output
    r = cli(question, "--m1", "copper", "--m2", "aluminium", "--json")
    assert r.exit_code == 3
    d = json.loads(r.stdout)
    assert d["value"] is None and any("overlap" in n for n in d["notes"])


@pytest.mark.parametrize("args", [
    ["min-contact", "--e1", "35000", "--e2", "20000", "--exact", "--trials", "0"],
    ["max-noise", "--e1", "35000", "--e2", "20000", "--contact", "2", "--exact", "--repeats", "0"],
    ["min-contact", "--e1", "35000", "--e2", "20000", "--exact", "--sensor-temp-spread", "10"],
])
def test_an_exact_questions_bad_input_is_one_line_on_stderr(cli, args):
    """Refused before any work, with nothing else on stderr: the progress bar drawn where stderr is no
    terminal put a blank line before the error."""
    r = cli(*args)
    assert r.exit_code == 2, r.output
    assert r.stderr.startswith("Error: ") and r.stderr.count("\n") == 1, repr(r.stderr)


def test_an_effusivity_whose_class_ends_above_the_cap_is_refused_naming_the_class(cli):
    """9999999 is below the cap of 1e7, its 80-wide class is not: the message said "effusivity 1e+07 upper bound
    must be at most 1e+07 ..., got 1.00001e+07" (a value the user did not type, rounded into the cap)."""
    r = cli("min-contact", "--e1", "9999999", "--e2", "20000")
    assert r.exit_code == 2 and r.stderr.count("\n") == 1
    assert r.stderr.startswith("Error: effusivity class 9999999, [9999999, 10000079), ends above the highest")
    assert "give at most 9999920" in r.stderr
    assert cli("min-contact", "--e1", "9999920", "--e2", "20000").exit_code != 2  # the largest value accepted


def test_the_library_chooses_the_route_and_says_why():
    """ask(route="auto") (the default) reads a table built for the sensor, model and scene asked, computes
    the answer for a sensor or spread no table holds, keeps a named table, and says why (issue 33)."""
    from designkit import SENSORS, query
    from designkit.query import NeedsInput
    from designkit.query.policy import choose_route, table_for

    mine = SENSORS["paper"].replace(effusivity=1982.0, name="mine")
    route, args, why = choose_route("min-contact", "auto", {"e1": 35000, "e2": 20000, "sensor": mine, "table": None,
                                                            "ideal_table": "ideal-paper", "trials": 20})
    assert route == "exact" and "table" not in args and "ideal_table" not in args and args["trials"] == 20
    assert why.reason.startswith("the shipped tables are for the paper sensor, not mine") and why.noted
    route, args, why = choose_route("min-contact", "auto", {"e1": 35000, "e2": 20000, "trials": 20, "width": 80.0})
    assert route == "table" and "trials" not in args and "width" not in args and "svm-fine" in why.reason
    assert table_for("min-contact", sensor_temp_spread_c=2.5, delta_t_c=7.5).table == "svm-paper-varied"
    assert table_for("min-contact", sensor_temp_spread_c=2.5, delta_t_c=10.0).table is None
    assert table_for("max-noise", sensor_temp_spread_c=2.5, delta_t_c=7.5).table is None
    assert choose_route("min-contact", "auto", {"table": "svm-paper"})[2].reason == "table svm-paper named"
    with pytest.raises(NeedsInput, match="tables answer for effusivity alone"):
        choose_route("min-contact", "auto", {"e1": 35000, "e2": 20000, "diffusivity_m2_s": 1e-7})
    a = query.min_contact(35000, 20000)
    assert a.route == "table" and a.to_dict()["route_reason"] == a.route_reason and "svm-fine" in a.route_reason
    arr = query.min_contact([35000, 30000], 20000)
    assert arr.route_reason == a.route_reason and arr.to_dict()[0]["route_reason"] == a.route_reason


@pytest.mark.parametrize("question, scene", [("min-contact", {"noise_c": 0.03}), ("max-noise", {"contact_s": 1.5}),
                                             ("min-delta-t", {"contact_s": 0.8}),
                                             ("distinguishable", {"contact_s": 1.0})])
def test_ask_each_answers_each_pair_as_ask_does(question, scene):
    # many pairs from one array call of the table route (what `designkit matrix` asks): element i is what ask
    # answers for pair i, an overlapping pair, a pair outside the grid and a pair given as classes included
    from designkit.objects import ObjectClass
    from designkit.query import ask, ask_each

    objects = [{"m1": "copper", "m2": "glass"}, {"m1": "aluminum", "m2": "copper"}, {"e1": 35000.0, "e2": 20000.0},
               {"e1": 100.0, "e2": 900.0},
               {"objects": (ObjectClass("a", (3000.0, 3400.0)), ObjectClass("b", (5000.0, 5080.0)))}]
    many = ask_each(question, objects, route="table", **scene)
    assert [a.to_dict() for a in many] == [ask(question, route="table", **o, **scene).to_dict() for o in objects]
    assert many[1].value is None and not many[1].limiting_pair  # the overlap: no answer, said so
    with pytest.raises(InputError, match="e1 and e2 are equal"):
        ask_each(question, [*objects, {"e1": 5.0e3, "e2": 5.0e3}], route="table", **scene)


def test_a_views_scene_weights_are_the_callers_own():
    # the table view keeps each scene's weights; a caller that adds a flag (the table route adds its effusivity
    # and contact flags) changes its own dict, never what the next question reads
    view = q.open_table("svm-paper").view
    combos, flags = view.scene_weights(0.05, 10.0)
    flags["effusivity"] = False
    assert view.scene_weights(0.05, 10.0) == (combos, {"noise_ratio": True})
    assert view.scene_weights(50.0, 10.0)[1] == {"noise_ratio": False}  # sigma/dT 5: beyond the grid, flagged
