"""Thin-sample queries: simulated touches of a slab on a backing, the Monte Carlo ideal observer
on the full-curve likelihood, the semi-infinite check, the queries, and the CLI's --thickness."""

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
from designkit.recognition.ideal import ideal_pair
from designkit.recognition.svm import interval_pair_f1
from designkit.simulation import simulate_interval
from designkit.models.slab import slab_response
from designkit.query.thin import (
    SlabObject,
    SlabScene,
    semi_infinite_check,
    simulate_slab_class,
    slab_ideal_pair,
    slab_object,
    slab_objects,
    slab_pair_f1,
    thin_delta_e,
    thin_distinguishable,
    thin_max_noise,
    thin_min_contact,
    thin_min_delta_t,
)

SENSOR = SENSORS["paper"]
THICK = SlabScene.make(math.inf, "insulated")
FAST = dict(trials=30, repeats=1, jobs=1)


def obj(lo, hi, a_lo, a_hi=None, label="x"):
    return SlabObject(label, (lo, hi), (a_lo, a_lo if a_hi is None else a_hi))


# ----------------------------------------------------------------------------- simulation
@pytest.mark.parametrize("thickness", [math.inf, 1e3])
def test_a_slab_too_thick_to_matter_gives_the_semi_infinite_touches(thickness):
    scene = Scene(contact_s=1.0, noise_c=0.05)
    o = obj(1400.0, 1480.0, 4e-7, 6e-7)
    thin = simulate_slab_class(o, 20, SENSOR, scene, SlabScene.make(thickness, "steel"), seed=[3, 1])
    semi = simulate_interval(1400.0, 1480.0, 20, SENSOR, scene, seed=[3, 1])
    np.testing.assert_array_equal(thin.effusivity, semi.effusivity)
    np.testing.assert_allclose(thin.temperature_c, semi.temperature_c, rtol=0, atol=1e-12)
    assert thin.method == "semi-infinite"
    assert np.all((thin.diffusivity_m2_s >= 4e-7) & (thin.diffusivity_m2_s < 6e-7))
    assert np.unique(thin.diffusivity_m2_s).size == 20  # drawn per trial


def test_truncated_touches_are_the_touches_of_a_shorter_contact():
    slab = SlabScene.make(5e-4, "steel")
    o = obj(500.0, 670.0, 8.3e-8, 1.5e-7)
    long = simulate_slab_class(o, 15, SENSOR, Scene(contact_s=3.0), slab, seed=5)
    short = simulate_slab_class(o, 15, SENSOR, Scene(contact_s=1.5), slab, seed=5)
    m = short.time_s.size
    assert long.method == "image-series"
    np.testing.assert_array_equal(long.diffusivity_m2_s, short.diffusivity_m2_s)
    # same draws; the model differs only within the series' rigorous error bounds (x dT = 10 degC)
    bound = 10.0 * (long.error_bound + short.error_bound)
    assert 0 < bound < 1e-4
    np.testing.assert_allclose(long.temperature_c[:, :m], short.temperature_c, rtol=0, atol=bound)


def test_thin_readings_are_the_slab_model_plus_noise():
    slab = SlabScene.make(1e-3, "wood")
    scene = Scene(contact_s=8.0, noise_c=0.0, sensor_temp_c=35.0, ambient_temp_c=25.0)
    o = obj(15000.0, 15080.0, 2e-5)  # 1 mm of metal on wood: far from semi-infinite within 8 s
    tr = simulate_slab_class(o, 4, SENSOR, scene, slab, seed=0)
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
    tr = simulate_slab_class(o, 3, SENSOR, scene, SlabScene.make(thickness, backing), seed=1)
    assert np.all(np.isfinite(tr.temperature_c))
    assert np.all(tr.temperature_c <= 35.0 + 1e-9) and np.all(tr.temperature_c >= 25.0 - 1e-9)
    assert np.all(tr.temperature_c[:, 0] == 35.0)  # no heat has moved at the instant of contact


def test_svm_on_a_thick_slab_is_the_papers_pipeline():
    scene = Scene(contact_s=0.5, noise_c=0.05)
    a, b = obj(20000.0, 20080.0, 3e-5), obj(35000.0, 35080.0, 1e-4)
    thin = slab_pair_f1(b, a, SENSOR, scene, THICK, trials=30, seed=4)  # order does not matter
    ref = interval_pair_f1((20000.0, 20080.0), (35000.0, 35080.0), SENSOR, scene, trials=30, seed=4)
    assert thin.f1 == ref.f1 and thin.fold_f1 == ref.fold_f1


# ----------------------------------------------------------------------------- ideal observer
def test_monte_carlo_ideal_reduces_to_the_closed_form_for_a_thick_slab():
    scene = Scene(contact_s=1.0, noise_c=0.05)
    a, b = obj(20000.0, 20080.0, 3e-5), obj(35000.0, 35080.0, 1e-4)
    mc = slab_ideal_pair(a, b, SENSOR, scene, SlabScene.make(1e3, "steel"), n_mc=1500, seed=2,
                         method="monte-carlo").result
    exact = ideal_pair((20000.0, 20080.0), (35000.0, 35080.0), SENSOR, scene)
    assert mc.method == "monte-carlo" and exact.method == "closed-form"
    assert abs(mc.accuracy - exact.accuracy) < 4 * mc.accuracy_standard_error
    assert abs(mc.f1 - exact.f1) < 4 * mc.standard_error


def test_monte_carlo_ideal_of_wide_classes_matches_the_closed_form():
    # wide, adjacent classes: the likelihood is an integral over each class (grids of ~50 and ~30 points)
    scene = Scene(contact_s=1.0, noise_c=0.02)
    a, b = obj(3000.0, 5000.0, 2e-6), obj(5000.0, 8000.0, 5e-6)
    r = slab_ideal_pair(a, b, SENSOR, scene, SlabScene.make(1e3, "wood"), n_mc=2000, seed=0,
                        method="monte-carlo")
    exact = ideal_pair((3000.0, 5000.0), (5000.0, 8000.0), SENSOR, scene)
    assert r.details["grid"][0][0] > 32 and r.details["basis_rank"] == 1
    assert abs(r.result.accuracy - exact.accuracy) < 4 * r.result.accuracy_standard_error
    assert abs(r.result.f1 - exact.f1) < 4 * r.result.standard_error


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
    scene = Scene(contact_s=2.0, noise_c=0.06)
    slab = SlabScene.make(5e-4, "steel")
    a, b = obj(583.0, 583.0 + 1e-6, 1.0e-7), obj(583.0, 583.0 + 1e-6, 1.2e-7)
    t = SENSOR.times_s(2.0)
    u = slab_response(t, [583.0, 583.0], [1.0e-7, 1.2e-7], 5e-4, "steel", SENSOR, tolerance=1e-12).response
    d = np.linalg.norm(u[0] - u[1]) * 10.0 / 0.06
    acc, f1 = _two_curves_scores(d)
    assert 0.75 < acc < 0.97  # a test with power
    r = slab_ideal_pair(a, b, SENSOR, scene, slab, n_mc=1500, seed=0)
    assert r.result.method == "monte-carlo" and r.deviation_norm > 1
    assert abs(r.result.accuracy - acc) < 4 * r.result.accuracy_standard_error
    assert abs(r.result.f1 - f1) < 4 * r.result.standard_error
    # without the slab they are the same object
    semi = slab_ideal_pair(a, b, SENSOR, scene, THICK)
    assert semi.result.method == "closed-form" and semi.result.accuracy == 0.5


def test_ideal_uses_the_closed_form_when_the_slab_is_invisible():
    scene = Scene(contact_s=1.0, noise_c=0.05)
    acrylic, glass = slab_objects(m1="acrylic", m2="glass")
    r = slab_ideal_pair(acrylic, glass, SENSOR, scene, SlabScene.make(0.003, "steel"))
    exact = ideal_pair(acrylic.e_range, glass.e_range, SENSOR, scene)
    assert r.result == exact
    assert 0 <= r.deviation_norm <= 0.01


def test_ideal_refuses_what_it_does_not_model():
    a, b = obj(500.0, 580.0, 1e-7), obj(900.0, 980.0, 1e-7)
    slab = SlabScene.make(1e-3, "wood")
    with pytest.raises(InputError, match="fixed initial conditions"):
        slab_ideal_pair(a, b, SENSOR, Scene(sensor_temp_spread_c=2.5), slab)
    with pytest.raises(InputError, match="identical"):
        slab_ideal_pair(a, a, SENSOR, Scene(), slab)
    with pytest.raises(InputError, match="method"):
        slab_ideal_pair(a, b, SENSOR, Scene(), slab, method="magic")


# ----------------------------------------------------------------------------- semi-infinite check
def _first_crossing(obj_, slab, tol_c, dt_c, t_end):
    """Brute force: first time any examined object's slab reading departs from eq. 2 by tol_c."""
    t = np.linspace(0.01, t_end, 6000)
    e, a = obj_.sample_points()
    first = math.inf
    for ai in a:
        full = slab_response(t, e, ai, slab.thickness_m, slab.backing, SENSOR, tolerance=1e-12).response
        semi = slab_response(t, e, ai, slab.thickness_m, slab.backing, SENSOR, method="semi-infinite").response
        over = np.nonzero(np.any(dt_c * np.abs(full - semi) > tol_c, axis=0))[0]
        if over.size:
            first = min(first, t[over[0]])
    return first


def test_semi_infinite_check_finds_when_a_sheet_stops_being_semi_infinite():
    (acrylic,) = [slab_object(material="acrylic")]
    on_steel = SlabScene.make(0.003, "steel")
    c = semi_infinite_check([acrylic], on_steel, SENSOR, needed_s=4.0, noise_c=0.05, delta_t_c=10.0)
    ref = _first_crossing(acrylic, on_steel, 0.005, 10.0, 60.0)
    assert c.holds and c.valid_up_to_s == pytest.approx(ref, abs=0.02)
    assert 10 < c.valid_up_to_s < 30  # 3 mm of acrylic: semi-infinite for the paper's 1-4 s touches
    assert "hold for this scene" in c.message
    late = semi_infinite_check([acrylic], on_steel, SENSOR, needed_s=30.0, noise_c=0.05, delta_t_c=10.0)
    assert not late.holds and "does NOT hold" in late.message
    assert late.valid_up_to_s == pytest.approx(c.valid_up_to_s, rel=1e-6)
    # a thinner sheet stops earlier; more noise tolerates more
    thin = semi_infinite_check([acrylic], SlabScene.make(0.001, "steel"), SENSOR, needed_s=4.0, noise_c=0.05,
                               delta_t_c=10.0)
    assert thin.valid_up_to_s < c.valid_up_to_s
    noisy = semi_infinite_check([acrylic], on_steel, SENSOR, needed_s=4.0, noise_c=0.5, delta_t_c=10.0)
    assert noisy.valid_up_to_s > c.valid_up_to_s


def test_semi_infinite_check_of_a_thick_object_or_a_matched_backing():
    glass = slab_object(material="glass")
    assert semi_infinite_check([glass], THICK, SENSOR, needed_s=10.0, noise_c=0.05,
                               delta_t_c=10.0).valid_up_to_s is None
    # 10 cm of glass: nothing comes back within a minute
    c = semi_infinite_check([glass], SlabScene.make(0.1, "air"), SENSOR, needed_s=4.0, noise_c=0.01, delta_t_c=10.0)
    assert c.holds and c.valid_up_to_s is None and "for any contact up to 60 s" in c.message


# ----------------------------------------------------------------------------- objects and inputs
def test_objects_from_numbers_and_materials():
    a, b = slab_objects(e1=500.0, m2="glass", diffusivity_m2_s=1.2e-7, width=40.0)
    assert a.e_range == (500.0, 540.0) and a.alpha_range_m2_s == (1.2e-7, 1.2e-7)
    assert b.material == "Glass" and b.alpha_range_m2_s[0] < b.alpha_range_m2_s[1]
    with pytest.raises(InputError, match="needs --diffusivity"):
        slab_objects(e1=500.0, e2=900.0)
    with pytest.raises(InputError, match="database"):
        slab_objects(m1="acrylic", m2="glass", diffusivity_m2_s=1e-7)
    with pytest.raises(InputError, match="give two objects"):
        slab_objects(e1=500.0, diffusivity_m2_s=1e-7)
    with pytest.raises(InputError):
        slab_object(e=-5.0, diffusivity_m2_s=1e-7)
    with pytest.raises(InputError):
        slab_object(e=500.0, diffusivity_m2_s=float("nan"))
    with pytest.raises(InputError):
        slab_object(material="unobtainium")
    with pytest.raises(InputError):
        SlabScene.make(-0.001)
    with pytest.raises(InputError, match="unknown backing"):
        SlabScene.make(0.001, "marshmallow")
    assert SlabScene.make(0.001).backing.name == "Hardwood, across grain"  # a sample lying on a table


# ----------------------------------------------------------------------------- queries
def test_min_contact_of_a_thick_slab_is_the_exact_semi_infinite_answer():
    from designkit.query.table import exact_min_contact

    acrylic, ptfe = slab_objects(m1="acrylic", m2="PTFE")
    kw = dict(noise_c=0.05, delta_t_c=10.0, max_contact_s=2.0, seed=1, **FAST)
    thin = thin_min_contact(acrylic, ptfe, thickness_m=math.inf, **kw)
    ref = exact_min_contact(ranges=(acrylic.e_range, ptfe.e_range), **kw)
    assert thin.value == ref.value and thin.interval == ref.interval
    assert thin.ideal == pytest.approx(ref.ideal, abs=0.011)
    assert thin.extra["slab"]["holds"] and thin.extra["ideal_methods"] == ["closed-form"]


def test_min_contact_of_a_3mm_acrylic_sheet_says_the_semi_infinite_answer_holds():
    acrylic, glass = slab_objects(m1="acrylic", m2="glass")
    ans = thin_min_contact(acrylic, glass, thickness_m=0.003, backing="steel", max_contact_s=2.0, n_mc=200,
                           **FAST)
    assert ans.value is not None and ans.value < 2.0 and ans.ideal <= ans.value + 0.05
    slab = ans.extra["slab"]
    # 3 mm of acrylic stays semi-infinite for ~20 s; 3 mm of glass (4x the diffusivity) limits it to a few s
    assert slab["holds"] and 3 < slab["semi_infinite"]["valid_up_to_s"] < 10
    assert slab["semi_infinite"]["limiting_object"]["diffusivity_m2_s"] >= glass.alpha_range_m2_s[0]
    assert ans.inputs["thickness_m"] == 0.003 and ans.inputs["backing"] == "Low carbon steel"


@pytest.mark.slow
def test_max_noise_and_min_delta_t_are_one_question_about_sigma_over_dt():
    """Readings depend on sigma and dT only through their ratio, slab or not: the two questions share one
    bisection over sigma/dT, so max-noise(dT) / dT == sigma / min-delta-t(sigma)."""
    a, b = obj(583.0, 663.0, 1.0e-7), obj(583.0, 663.0, 1.3e-7)  # differ only in diffusivity
    kw = dict(thickness_m=3e-4, backing="steel", contact_s=1.5, n_mc=200, **FAST)
    mx = thin_max_noise(a, b, delta_t_c=10.0, **kw)
    mn = thin_min_delta_t(a, b, noise_c=0.05, **kw)
    assert mx.value is not None and mn.value is not None
    assert mx.value / 10.0 == pytest.approx(0.05 / mn.value, rel=1e-12)
    assert mx.ideal / 10.0 == pytest.approx(0.05 / mn.ideal, rel=1e-12)
    assert mx.ideal >= mx.value * 0.9  # the ideal observer tolerates at least about as much noise
    assert "monte-carlo" in mx.extra["ideal_methods"]
    assert not mx.extra["slab"]["holds"]  # the answer exists only because of the slab


def test_distinguishable_changes_with_the_backing():
    """1 mm metal sheets (stainless vs aluminium) on a wooden table vs on steel, 1 s touch."""
    ss, al = slab_objects(m1="stainless steel", m2="aluminium alloys")
    kw = dict(thickness_m=1e-3, contact_s=1.0, noise_c=0.05, n_mc=300, **FAST)
    wood = thin_distinguishable(ss, al, backing="wood", **kw)
    steel = thin_distinguishable(ss, al, backing="steel", **kw)
    semi = thin_distinguishable(ss, al, backing="wood", **{**kw, "thickness_m": math.inf})
    assert not wood.extra["slab"]["holds"] and semi.extra["slab"]["holds"]
    assert wood.extra["ideal_methods"] == ["monte-carlo"] and semi.extra["ideal_methods"] == ["closed-form"]
    # on wood the sheets' heat runs into the table slowly: they are harder to tell apart than thick blocks
    assert wood.ideal < semi.ideal - 3 * wood.extra["ideal_evaluations"][0]["standard_error"]
    assert steel.ideal > wood.ideal


def test_delta_e_of_a_thin_sheet_needs_its_diffusivity():
    with pytest.raises(InputError, match="diffusivity"):
        thin_delta_e(583.0, thickness_m=1e-3, contact_s=1.0)
    with pytest.raises(InputError, match="database"):
        thin_delta_e(material="acrylic", diffusivity_m2_s=1e-7, thickness_m=1e-3, contact_s=1.0)


def test_delta_e_of_a_thick_slab_is_the_exact_semi_infinite_answer():
    from designkit.query.table import exact_delta_e

    kw = dict(contact_s=0.5, noise_c=0.05, delta_t_c=10.0, width=80.0, e_max=2000.0, seed=2, **FAST)
    thin = thin_delta_e(1000.0, thickness_m=math.inf, diffusivity_m2_s=3e-7, **kw)
    ref = exact_delta_e(1000.0, **kw)
    for k in ("delta_e_lower", "delta_e_upper"):
        assert thin.extra[k] == ref.extra[k]
        assert thin.extra[k + "_ideal"] == pytest.approx(ref.extra[k + "_ideal"], abs=1.0)


# ----------------------------------------------------------------------------- CLI
def test_cli_min_contact_with_thickness(cli):
    r = cli("min-contact", "--m1", "acrylic", "--m2", "glass", "--thickness", "0.003", "--trials", "30",
            "--repeats", "1", "--jobs", "1", "--max-contact", "2", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["source"] == "computed" and d["contact_time_s"] is not None
    assert d["slab"]["holds"] and d["slab"]["backing"]["name"] == "Hardwood, across grain"
    assert d["inputs"]["thickness_m"] == 0.003
    human = cli("min-contact", "--m1", "acrylic", "--m2", "glass", "--thickness", "0.003", "--backing", "steel",
                "--trials", "30", "--repeats", "1", "--jobs", "1", "--max-contact", "2")
    assert human.exit_code == 0, human.output
    assert "semi-infinite tables hold" in " ".join(human.output.split())


@pytest.mark.parametrize("args, message", [
    (["min-contact", "--m1", "acrylic", "--m2", "glass", "--backing", "steel"], "give its --thickness"),
    (["max-noise", "--e1", "500", "--e2", "900", "--diffusivity", "1e-7"], "give its --thickness"),
    (["distinguishable", "--e1", "500", "--e2", "900", "--thickness", "0.001"], "needs --diffusivity"),
    (["min-delta-t", "--m1", "acrylic", "--m2", "glass", "--thickness", "0.001", "--diffusivity", "1e-7"],
     "database"),
    (["delta-e", "--e", "583", "--thickness", "0.001"], "diffusivity"),
    (["min-contact", "--m1", "acrylic", "--m2", "glass", "--thickness", "-1"], "thickness"),
    (["min-contact", "--m1", "acrylic", "--m2", "glass", "--thickness", "0.001", "--backing", "jelly"],
     "unknown backing"),
])
def test_cli_refuses_incomplete_thin_scenes(cli, args, message):
    r = cli(*args)
    assert r.exit_code == 2
    assert message in " ".join(r.output.split()) and "Traceback" not in r.output


def test_console_script_distinguishable_with_thickness():
    exe = os.path.join(os.path.dirname(sys.executable), "designkit")
    out = subprocess.run([exe, "distinguishable", "--e1", "583", "--e2", "700", "--diffusivity", "1.2e-7",
                          "--thickness", "0.0003", "--backing", "steel", "--contact", "0.6", "--trials", "30",
                          "--repeats", "1", "--jobs", "1", "--json"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["distinguishable"] in (True, False) and 0 <= d["ideal_f1"] <= 1
    assert d["slab"]["thickness_m"] == 0.0003 and d["inputs"]["objects"][0]["alpha_range_m2_s"] == [1.2e-7, 1.2e-7]
