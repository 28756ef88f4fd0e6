"""Thin samples through the question layer: touches of a slab on a backing (the forward-model seam),
the slab questions as the exact route with ``model=Slab(...)``, the model's check in every answer, and the
CLI's --thickness. (Before the redesign: designkit/query/thin.py, its own nouns, simulation and questions.)

The Monte Carlo ideal observer for shapes that differ per object moves to
designkit.recognition.ideal_mc; the tests that need it skip until it is there."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import optimize, stats

from designkit import SENSORS, InputError, Scene
from designkit.models.slab import Slab, slab_response
from designkit.objects import ObjectClass
from designkit.query import exact_delta_e, exact_distinguishable, exact_max_noise, exact_min_contact
from designkit.query import exact_min_delta_t, pair_question
from designkit.recognition.ideal import ideal_pair
from designkit.recognition.svm import interval_pair_f1, pair_f1
from designkit.simulation import simulate_class, simulate_interval

SENSOR = SENSORS["paper"]
THICK = Slab(math.inf, "insulated")
FAST = dict(trials=30, repeats=1, jobs=1)


def obj(lo, hi, a_lo, a_hi=None, label="x"):
    return ObjectClass(label, (lo, hi), (a_lo, a_lo if a_hi is None else a_hi))


def _needs_monte_carlo_ideal():
    pytest.importorskip("designkit.recognition.ideal_mc", reason="the Monte Carlo ideal observer lands with "
                                                                 "designkit.recognition.ideal_mc")


# ----------------------------------------------------------------------------- simulation
@pytest.mark.parametrize("thickness", [math.inf, 1e3])
def test_a_slab_too_thick_to_matter_gives_the_semi_infinite_touches(thickness):
    scene = Scene(contact_s=1.0, noise_c=0.05)
    o = obj(1400.0, 1480.0, 4e-7, 6e-7)
    thin = simulate_class(o, 20, SENSOR, scene, [3, 1], Slab(thickness, "steel"))
    semi = simulate_interval(1400.0, 1480.0, 20, SENSOR, scene, seed=[3, 1])
    np.testing.assert_array_equal(thin.effusivity, semi.effusivity)
    np.testing.assert_allclose(thin.temperature_c, semi.temperature_c, rtol=0, atol=1e-12)
    assert np.all((thin.diffusivity_m2_s >= 4e-7) & (thin.diffusivity_m2_s < 6e-7))
    assert np.unique(thin.diffusivity_m2_s).size == 20  # drawn per trial


def test_truncated_touches_are_the_touches_of_a_shorter_contact():
    slab = Slab(5e-4, "steel")
    o = obj(500.0, 670.0, 8.3e-8, 1.5e-7)
    long = simulate_class(o, 15, SENSOR, Scene(contact_s=3.0), 5, slab)
    short = simulate_class(o, 15, SENSOR, Scene(contact_s=1.5), 5, slab)
    m = short.time_s.size
    np.testing.assert_array_equal(long.diffusivity_m2_s, short.diffusivity_m2_s)
    # same draws; the model differs only within the solver's tolerance (<= 1e-5, x dT = 10 degC, twice)
    np.testing.assert_allclose(long.temperature_c[:, :m], short.temperature_c, rtol=0, atol=2e-4)


def test_thin_readings_are_the_slab_model_plus_noise():
    slab = Slab(1e-3, "wood")
    scene = Scene(contact_s=8.0, noise_c=0.0, sensor_temp_c=35.0, ambient_temp_c=25.0)
    o = obj(15000.0, 15080.0, 2e-5)  # 1 mm of metal on wood: far from semi-infinite within 8 s
    tr = simulate_class(o, 4, SENSOR, scene, 0, slab)
    ref = slab_response(tr.time_s, tr.effusivity, 2e-5, 1e-3, "wood", SENSOR, tolerance=1e-10)
    np.testing.assert_allclose(tr.temperature_c, ref.temperature_c(35.0, 25.0), rtol=0, atol=1e-6)
    semi = slab_response(tr.time_s, tr.effusivity, 2e-5, 1e-3, "wood", SENSOR, method="semi-infinite")
    assert np.max(np.abs(tr.temperature_c - semi.temperature_c(35.0, 25.0))) > 1.0  # the slab matters here


@settings(max_examples=25, deadline=None)
@given(e_lo=st.floats(10.0, 30000.0), e_width=st.floats(1.0, 5000.0), alpha=st.floats(1e-8, 1e-4),
       alpha_factor=st.floats(1.0, 5.0), thickness=st.floats(1e-5, 0.1),
       backing=st.sampled_from(["insulated", "air", "table", "steel", "copper alloys"]),
       contact=st.floats(0.01, 6.0))
def test_noise_free_thin_readings_stay_between_ambient_and_sensor_temperature(e_lo, e_width, alpha, alpha_factor,
                                                                              thickness, backing, contact):
    """Maximum principle: without noise every reading lies in [Ta, Ts0], whatever the slab and backing."""
    o = obj(e_lo, e_lo + e_width, alpha, alpha * alpha_factor)
    scene = Scene(contact_s=contact, noise_c=0.0, sensor_temp_c=35.0, ambient_temp_c=25.0)
    tr = simulate_class(o, 3, SENSOR, scene, 1, Slab(thickness, backing))
    assert np.all(np.isfinite(tr.temperature_c))
    assert np.all(tr.temperature_c <= 35.0 + 1e-9) and np.all(tr.temperature_c >= 25.0 - 1e-9)
    assert np.all(tr.temperature_c[:, 0] == 35.0)  # no heat has moved at the instant of contact


def test_svm_on_a_thick_slab_is_the_papers_pipeline():
    scene = Scene(contact_s=0.5, noise_c=0.05)
    a, b = obj(20000.0, 20080.0, 3e-5), obj(35000.0, 35080.0, 1e-4)
    thin = pair_f1(b, a, SENSOR, scene, model=THICK, trials=30, seed=4)  # order does not matter
    ref = interval_pair_f1((20000.0, 20080.0), (35000.0, 35080.0), SENSOR, scene, trials=30, seed=4)
    assert thin.f1 == ref.f1 and thin.fold_f1 == ref.fold_f1


# ----------------------------------------------------------------------------- ideal observer (seam)
def test_ideal_uses_the_closed_form_when_the_slab_is_invisible():
    scene = Scene(contact_s=1.0, noise_c=0.05)
    acrylic, glass = pair_question(m1="acrylic", m2="glass").asked
    r = ideal_pair(acrylic, glass, SENSOR, scene, model=Slab(0.003, "steel"))
    exact = ideal_pair(acrylic.e_range, glass.e_range, SENSOR, scene)
    assert r == exact and r.method == "closed-form"


def _two_curves_scores(d):
    """Bayes accuracy and best F1 for two known curves in white noise, separation d' = d."""
    acc = stats.norm.cdf(d / 2)

    def neg_f1(th):  # log-likelihood ratio ~ N(+-d^2/2, d^2)
        tpr = stats.norm.sf((th - d * d / 2) / d)
        fpr = stats.norm.sf((th + d * d / 2) / d)
        return -2 * tpr / (1 + tpr + fpr)

    best = optimize.minimize_scalar(neg_f1, bounds=(-4 * d * d - 5, 4 * d * d + 5), method="bounded")
    return acc, -best.fun


def test_ideal_observer_tells_apart_objects_that_differ_only_in_diffusivity_through_the_slab():
    """Same effusivity, different diffusivity: identical to eq. 2, but not as 0.5 mm sheets on steel.
    Reference: two known curves (classes 1e-6 wide), accuracy Phi(d'/2), d' = ||T1 - T2|| / sigma."""
    _needs_monte_carlo_ideal()
    scene = Scene(contact_s=2.0, noise_c=0.06)
    a, b = obj(583.0, 583.0 + 1e-6, 1.0e-7), obj(583.0, 583.0 + 1e-6, 1.2e-7)
    t = SENSOR.times_s(2.0)
    u = slab_response(t, [583.0, 583.0], [1.0e-7, 1.2e-7], 5e-4, "steel", SENSOR, tolerance=1e-12).response
    d = np.linalg.norm(u[0] - u[1]) * 10.0 / 0.06
    acc, f1 = _two_curves_scores(d)
    assert 0.75 < acc < 0.97  # a test with power
    r = ideal_pair(a, b, SENSOR, scene, model=Slab(5e-4, "steel"), n_mc=1500, seed=0)
    assert r.method == "monte-carlo"
    assert abs(r.accuracy - acc) < 4 * r.accuracy_standard_error
    assert abs(r.f1 - f1) < 4 * r.standard_error


# ----------------------------------------------------------------------------- objects and inputs
def test_objects_from_numbers_and_materials():
    slab = Slab(0.001)
    a, b = pair_question(e1=500.0, m2="glass", diffusivity_m2_s=1.2e-7, width=40.0, model=slab).asked
    assert a.e_range == (500.0, 540.0) and a.diffusivity_range_m2_s == (1.2e-7, 1.2e-7)
    assert b.material == "Glass" and b.diffusivity_range_m2_s[0] < b.diffusivity_range_m2_s[1]
    with pytest.raises(InputError, match="no diffusivity, which the slab model needs"):
        pair_question(e1=500.0, e2=900.0, model=slab)
    with pytest.raises(InputError, match="database"):
        pair_question(m1="acrylic", m2="glass", diffusivity_m2_s=1e-7, model=slab)
    with pytest.raises(InputError, match="does not use it"):
        pair_question(e1=500.0, e2=900.0, diffusivity_m2_s=1e-7)
    with pytest.raises(InputError, match="give two objects"):
        pair_question(e1=500.0, diffusivity_m2_s=1e-7, model=slab)
    with pytest.raises(InputError):
        pair_question(e1=-5.0, e2=500.0, diffusivity_m2_s=1e-7, model=slab)
    with pytest.raises(InputError):
        pair_question(e1=500.0, e2=900.0, diffusivity_m2_s=float("nan"), model=slab)
    with pytest.raises(InputError):
        pair_question(m1="unobtainium", e2=500.0)
    with pytest.raises(InputError):
        Slab(-0.001)
    with pytest.raises(InputError, match="unknown backing"):
        Slab(0.001, "marshmallow")
    assert Slab(0.001).backing.name == "Hardwood, across grain"  # a sample lying on a table


# ----------------------------------------------------------------------------- the slab questions
def test_min_contact_of_a_thick_slab_is_the_exact_semi_infinite_answer():
    kw = dict(noise_c=0.05, delta_t_c=10.0, max_contact_s=2.0, seed=1, **FAST)
    a, b = obj(1000.0, 1080.0, 1e-7), obj(1300.0, 1380.0, 1e-7)
    thin = exact_min_contact(objects=(a, b), model=THICK, **kw)
    ref = exact_min_contact(1000.0, 1300.0, **kw)
    # the estimate's design starts at the ideal bound, which the thick slab reaches through its own
    # (invisible-slab) check: the same touches give the same crossing up to that start (< 0.01 s here)
    assert thin.value == pytest.approx(ref.value, abs=0.01)
    assert thin.interval == pytest.approx(ref.interval, abs=0.01)
    assert thin.ideal == pytest.approx(ref.ideal, abs=0.011)
    assert thin.model_check["details"]["semi_infinite_holds"] and thin.ideal_bound.method == "closed-form"


def test_min_contact_of_a_3mm_acrylic_sheet_says_the_semi_infinite_answer_holds():
    ans = exact_min_contact(m1="acrylic", m2="glass", model=Slab(0.003, "steel"), max_contact_s=2.0, n_mc=200,
                            **FAST)
    assert ans.value is not None and ans.value < 2.0 and ans.ideal <= ans.value + 0.05
    chk = ans.model_check
    assert chk["name"] == "slab" and chk["details"]["semi_infinite_holds"]
    assert "semi-infinite model and its tables hold" in chk["message"]
    assert ans.model["thickness_m"] == 0.003 and ans.model["backing"]["name"] == "Low carbon steel"
    # the materials rule: the facing edges of acrylic's and glass's ranges
    lo, hi = ans.to_dict()["limiting_pair"]
    assert "Acrylic" in lo["material"] and hi["material"] == "Glass"
    assert hi["effusivity_range"][1] - hi["effusivity_range"][0] == pytest.approx(80.0)


def test_model_check_says_when_a_sheet_stops_being_semi_infinite():
    acrylic = pair_question(m1="acrylic", m2="glass").asked[0]
    slab = Slab(0.003, "steel")
    early = slab.check([acrylic], SENSOR, contact_s=4.0, noise_c=0.05, delta_t_c=10.0)
    late = slab.check([acrylic], SENSOR, contact_s=30.0, noise_c=0.05, delta_t_c=10.0)
    assert early.details["semi_infinite_holds"] and not late.details["semi_infinite_holds"]


@pytest.mark.slow
def test_max_noise_and_min_delta_t_are_one_question_about_sigma_over_dt():
    """Readings depend on sigma and dT only through their ratio, slab or not: the two questions share one
    bisection over sigma/dT, so max-noise(dT) / dT == sigma / min-delta-t(sigma)."""
    _needs_monte_carlo_ideal()
    a, b = obj(583.0, 663.0, 1.0e-7), obj(583.0, 663.0, 1.3e-7)  # differ only in diffusivity
    kw = dict(objects=(a, b), model=Slab(3e-4, "steel"), contact_s=1.5, n_mc=200, **FAST)
    mx = exact_max_noise(delta_t_c=10.0, **kw)
    mn = exact_min_delta_t(noise_c=0.05, **kw)
    assert mx.value is not None and mn.value is not None
    assert mx.value / 10.0 == pytest.approx(0.05 / mn.value, rel=1e-12)
    assert mx.ideal / 10.0 == pytest.approx(0.05 / mn.ideal, rel=1e-12)
    assert mx.ideal >= mx.value * 0.9  # the ideal observer tolerates at least about as much noise
    assert "monte-carlo" in mx.ideal_bound.method
    assert not mx.model_check["details"]["semi_infinite_holds"]  # the answer exists only because of the slab


def test_distinguishable_changes_with_the_backing():
    """1 mm metal sheets (stainless vs aluminium, their facing-edge classes) on a wooden table vs on steel,
    1 s touch. On wood the heat stays in the sheet and its diffusivity (about 15x larger for aluminium)
    shows: the edge classes, not separable as thick blocks, become separable; on steel the heat leaves
    through the backing and the sheets read almost like thick blocks. (Before the materials rule the classes
    were the whole ranges and the sheets on wood were the harder case.)"""
    _needs_monte_carlo_ideal()
    kw = dict(m1="stainless steel", m2="aluminium alloys", contact_s=1.0, noise_c=0.05, n_mc=300, **FAST)
    wood = exact_distinguishable(model=Slab(1e-3, "wood"), **kw)
    steel = exact_distinguishable(model=Slab(1e-3, "steel"), **kw)
    semi = exact_distinguishable(model=Slab(math.inf, "wood"), **kw)
    assert not wood.model_check["details"]["semi_infinite_holds"]
    assert semi.model_check["details"]["semi_infinite_holds"]
    assert wood.ideal_bound.method == "monte-carlo" and semi.ideal_bound.method == "closed-form"
    se = wood.computation["ideal_evaluations"][0]["standard_error"]
    assert wood.ideal > semi.ideal + 3 * se and wood.ideal > steel.ideal + 3 * se
    assert semi.ideal < 0.9  # as thick blocks the facing edges are not separable in 1 s


def test_delta_e_of_a_thin_sheet_needs_its_diffusivity():
    with pytest.raises(InputError, match="diffusivity"):
        exact_delta_e(583.0, model=Slab(1e-3), contact_s=1.0)
    with pytest.raises(InputError, match="database"):
        exact_delta_e(m="acrylic", diffusivity_m2_s=1e-7, model=Slab(1e-3), contact_s=1.0)


def test_delta_e_of_a_thick_slab_is_the_exact_semi_infinite_answer():
    kw = dict(contact_s=0.5, noise_c=0.05, delta_t_c=10.0, width=80.0, e_max=2000.0, seed=2, **FAST)
    thin = exact_delta_e(1000.0, model=THICK, diffusivity_m2_s=3e-7, **kw)
    ref = exact_delta_e(1000.0, **kw)
    for side in ("lower", "upper"):
        assert thin.details[side]["value"] == ref.details[side]["value"]
        assert thin.details[side]["ideal"] == pytest.approx(ref.details[side]["ideal"], abs=1.0)


# ----------------------------------------------------------------------------- CLI
def test_cli_min_contact_with_thickness(cli):
    r = cli("min-contact", "--m1", "acrylic", "--m2", "glass", "--thickness", "0.003", "--trials", "30",
            "--repeats", "1", "--jobs", "1", "--max-contact", "2", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["route"] == "exact" and d["value"] is not None
    assert d["model_check"]["details"]["semi_infinite_holds"]
    assert d["model"]["backing"]["name"] == "Hardwood, across grain" and d["model"]["thickness_m"] == 0.003
    human = cli("min-contact", "--m1", "acrylic", "--m2", "glass", "--thickness", "0.003", "--backing", "steel",
                "--trials", "30", "--repeats", "1", "--jobs", "1", "--max-contact", "2", "--explain")
    assert human.exit_code == 0, human.output
    assert "semi-infinite model and its tables hold" in " ".join(human.output.split())


@pytest.mark.parametrize("args, message", [
    (["max-noise", "--e1", "500", "--e2", "900", "--diffusivity", "1e-7"], "give --thickness"),
    (["distinguishable", "--e1", "500", "--e2", "900", "--thickness", "0.001"], "give --diffusivity"),
    (["min-delta-t", "--m1", "acrylic", "--m2", "glass", "--thickness", "0.001", "--diffusivity", "1e-7"],
     "database"),
    (["delta-e", "--e", "583", "--thickness", "0.001"], "diffusivity"),
    (["min-contact", "--m1", "acrylic", "--m2", "glass", "--thickness", "-1"], "thickness"),
    (["min-contact", "--m1", "acrylic", "--m2", "glass", "--thickness", "0.001", "--backing", "jelly"],
     "unknown backing"),
    (["min-contact", "--e1", "500", "--e2", "900", "--conductance", "3000", "--table", "svm-paper"],
     "use --exact"),
])
def test_cli_refuses_incomplete_thin_scenes(cli, args, message):
    r = cli(*args)
    assert r.exit_code == 2
    assert message in " ".join(r.output.split()) and "Traceback" not in r.output


def test_console_script_distinguishable_with_thickness():
    exe = os.path.join(os.path.dirname(sys.executable), "designkit")
    if not os.path.exists(exe):
        pytest.skip(f"console script not installed next to {sys.executable}")
    out = subprocess.run([exe, "distinguishable", "--e1", "583", "--e2", "700", "--diffusivity", "1.2e-7",
                          "--thickness", "0.3", "--backing", "steel", "--contact", "0.6", "--trials", "30",
                          "--repeats", "1", "--jobs", "1", "--json"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["value"] in (True, False) and 0 <= d["ideal"]["value"] <= 1
    assert d["model"]["thickness_m"] == 0.3 and d["objects"][0]["diffusivity_range_m2_s"] == [1.2e-7, 1.2e-7]


# ----------------------------------------------------------------------------- the contact model
def test_the_contact_model_through_every_exact_question():
    """``designkit min-contact --e1 35000 --e2 20000 --exact --model contact --conductance 3000`` and the
    others: the SVM answers through the seam; the ideal bound needs the Monte Carlo observer."""
    _needs_monte_carlo_ideal()
    from designkit.models.contact import Contact

    fm = Contact(3000.0)
    fast = dict(trials=12, repeats=1, jobs=1, n_mc=60, model=fm)
    assert exact_min_contact(35000, 20000, max_contact_s=1.0, tolerance_s=0.2, **fast).model["name"] == "contact"
    assert exact_max_noise(35000, 20000, contact_s=0.5, **fast).route == "exact"
    assert exact_min_delta_t(35000, 20000, contact_s=0.5, **fast).route == "exact"
    assert exact_distinguishable(35000, 20000, contact_s=0.5, **fast).details["svm_f1"] is not None
    assert exact_delta_e(20000, contact_s=0.3, e_max=22000.0, **fast).question == "delta-e"


def test_cli_contact_model_is_computed_not_read_from_a_semi_infinite_table(cli):
    _needs_monte_carlo_ideal()
    r = cli("distinguishable", "--e1", "35000", "--e2", "20000", "--exact", "--model", "contact",
            "--conductance", "3000", "--contact", "0.5", "--trials", "12", "--repeats", "1", "--jobs", "1",
            "--n-mc", "60", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["model"] == {"name": "contact", "conductance_w_m2k": 3000.0} and d["route"] == "exact"
