"""``designkit design`` under a rig's contact (designkit.design.contact): the contact conductance, the contact
area's ramp and the thermistor's own lag decide how fast a skin responds; a design is credited at least
MIN_SAMPLES samples of contact; bad input is one line, exit 2."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from designkit.design.contact import RigContact, d_star, screen_contact
from designkit.design.search import MIN_SAMPLES, Constraints, recommend, targets_from
from designkit.models import sensor_model
from designkit.query.ideal_bound import exact_ideal_min_contact
from designkit.sensor import Sensor, load_sensor

#: The lab's rig as `calibrate fit` identified it on the shared recordings (default model selection:
#: layered + lag + smoothing + drift + area; h_c 1827 W m^-2 K^-1, area settling over 2 s, lag 1.1 s).
RIG = Path(__file__).parent / "data" / "rig_sensor.yaml"
PEEK = "Polyetheretherketone (PEEK)"
GUIDE = ["20000=20000", "35000=35000"]


def test_the_rig_fixture_is_the_calibrated_contact():
    c = RigContact.from_sensor(load_sensor(RIG))
    d = c.to_dict()
    assert 1500 < d["conductance_w_m2k"] < 2200 and d["contact_ramp_s"] == pytest.approx(2.0, abs=0.1)
    assert 0.5 < d["thermistor_tau_s"] < 2 and d["noise_correlation_s"] > 0 and d["onset_offset_s"] < 0
    # a design's sensor is the rig's with the design's changes, played by the same models
    s = c.sensor(effusivity=700.0, diffusivity_m2_s=1e-7, depth_m=50e-6, thermistor_tau_s=0.1, pace=0.5)
    fm = sensor_model(s)
    assert fm.name == "force-ramp" and fm.base.lag_s == 0.1 and fm.base.conductance_w_m2k == c.conductance_w_m2k
    assert fm.ramp_duration_s == pytest.approx(0.5 * c.ramp_s, abs=0.02)
    # explicit values override the file's; a ramp given is the file's press played at another pace
    c2 = RigContact.from_sensor(load_sensor(RIG), conductance_w_m2k=800.0, contact_ramp_s=1.0, thermistor_tau_s=0.2)
    assert (c2.conductance_w_m2k, c2.thermistor_tau_s) == (800.0, 0.2)
    assert c2.ramp_s == pytest.approx(1.0, abs=0.02) and "given" in c2.source


def test_screen_is_the_closed_form_under_perfect_instant_contact():
    """With perfect contact, no ramp, no lag and white noise the screen's d' of point classes is the paper's
    ideal observer: its contact is the closed form's to a sample (near-point classes, 1 wide)."""
    c = RigContact.explicit(conductance_w_m2k=None, contact_ramp_s=None, thermistor_tau_s=None)
    s = c.sensor(effusivity=892.0, diffusivity_m2_s=1.19e-9, depth_m=80e-6)
    lo, hi = np.array([20000.0, 500.0]), np.array([35000.0, 700.0])
    got = screen_contact(s, lo + 0.5, hi + 0.5, 0.005, max_contact_s=4.0, threshold=0.9)
    ref = exact_ideal_min_contact(Sensor(892.0, 1.19e-9), lo, hi, 0.005, width=1.0, threshold=0.9, max_contact_s=4.0)
    assert np.all(np.abs(got - ref) <= 1.5 / 200.0), (got, ref)
    assert round(d_star(0.9), 3) == 2.563


def test_a_slow_contact_slows_every_skin():
    """The same search under an imperfect, ramped contact with a lagging thermistor needs longer contact than
    under the paper's instantaneous perfect contact, whatever the skin."""
    t = targets_from(GUIDE)
    cons = Constraints(max_contact_s=6.0, depth_um=(50.0, 50.0), min_thermistor_tau_s=0.3)
    ideal = recommend(t, cons, skins=(PEEK, "Alumina"), n_depth=1)
    slow = RigContact.explicit(conductance_w_m2k=1600.0, contact_ramp_s=2.0, thermistor_tau_s=0.3)
    r = recommend(t, cons, skins=(PEEK, "Alumina"), n_depth=1, contact=slow)
    assert r.best is not None and r.best.method == "screen" and r.best.thermistor_tau_s == 0.3
    assert r.best.min_contact_s > 5 * ideal.best.min_contact_s
    assert r.best.min_contact_s == min(d.min_contact_s for d in r.designs)
    # a faster press (the ramp's pace) never hurts
    by = {(d.skin, d.press_pace): d.min_contact_s for d in r.designs}
    assert all(by[(s, 0.5)] <= by[(s, 1.0)] for s in (PEEK, "Alumina"))


def test_no_recommendation_rests_on_the_first_samples():
    """The paper's instantaneous contact lets alumina 20 um deep separate the guideline pair after one sample:
    it is credited MIN_SAMPLES samples, and says so."""
    r = recommend(targets_from(GUIDE), Constraints(), skins=("Alumina",), n_depth=1)
    assert r.best.ideal_time_s == pytest.approx(0.005) and r.best.min_contact_s == MIN_SAMPLES / 200.0
    assert f"credited {MIN_SAMPLES} samples" in r.reason
    assert all(t >= MIN_SAMPLES / 200.0 for _, t in r.pareto if math.isfinite(t))


def test_rig_search_reports_the_rig_as_built(cli, tmp_path):
    r = cli("design", "--sensor", str(RIG), "--m", GUIDE[0], "--m", GUIDE[1], "--skin", PEEK, "--depth-um", "80:80",
            "--skin-thickness-um", "250:250", "--max-press-speedup", "1", "--max-contact", "6", "--no-svm", "--json",
            "--plot", str(tmp_path / "d.png"))
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    best, base = out["best"], out["baseline"]
    assert out["rig_contact"]["source"] == "sensor file rig" and out["min_samples"] == MIN_SAMPLES
    assert out["constraints"]["noise_c"] == pytest.approx(0.0306, abs=1e-3)   # the rig's, from its file
    assert out["constraints"]["max_delta_t_c"] == pytest.approx(6.94, abs=0.01)
    assert best["ideal"]["method"] == "screen" and best["thermistor_tau_s"] is not None
    assert base["skin"] == "rig as built" and base["thermistor_tau_s"] == pytest.approx(out["rig_contact"]["thermistor_tau_s"])
    assert (base["ideal"]["value"] or math.inf) >= best["ideal"]["value"]
    assert (tmp_path / "d.png").stat().st_size > 10_000


@pytest.mark.parametrize("args,msg", [
    (["--sensor", "no-such-rig.yaml"], "no-such-rig.yaml"),
    (["--contact-ramp-s", "-1"], "--contact-ramp-s must be between 0 and 60 s"),
    (["--contact-conductance", "0"], "--contact-conductance"),
    (["--thermistor-tau-s", "nan"], "--thermistor-tau-s"),
    (["--contact-conductance", "1600", "--max-press-speedup", "0.5"], "press speed-up"),
    (["--contact-conductance", "1600", "--skin-thickness-um", "500:50"], "skin thicknesses contradict"),
])
def test_bad_contact_input_is_one_line(cli, args, msg):
    r = cli("design", "--m", "a=1000", "--m", "b=2000", "--no-svm", *args)
    assert r.exit_code == 2, r.output
    assert msg in r.output and len(r.output.strip().splitlines()) == 1


def test_a_tiny_svm_prediction_and_confirmation():
    """The recommendation's stated interval (the exact route's estimate of the SVM's mean-F1 crossing) and its
    confirmation: the same crossing measured again with fresh seeds (disjoint from the statement's, more per
    contact), under the design's contact model; holds says whether the confirmation lies inside the stated
    interval, and nothing is credited fewer than MIN_SAMPLES samples."""
    from designkit.design.search import predict_and_confirm

    t = targets_from(GUIDE)
    quick = RigContact.explicit(conductance_w_m2k=5000.0, contact_ramp_s=0.2, thermistor_tau_s=0.05)
    cons = Constraints(max_contact_s=2.0, noise_c=0.02, max_delta_t_c=10.0, depth_um=(50.0, 50.0),
                       min_thermistor_tau_s=0.05)
    r = recommend(t, cons, skins=("Alumina",), n_depth=1, contact=quick)
    out = predict_and_confirm(r, t, trials=20, repeats=2, confirm_repeats=4, n_mc=50)
    pred = out["prediction"]
    assert pred["value"] is not None and pred["counted_from"] == "first contact" and pred["repeats"] == 2
    assert out["value"] is not None and out["seeds"] == 4 and out["seed"] != pred["seed"]
    assert "mean F1" in pred["covers"] and out["covers"] == pred["covers"]
    low, high = pred["interval"]["low"], pred["interval"]["high"]
    if low is not None and high is not None:
        assert out["holds"] == (low - 1 / 200 - 1e-9 <= out["value"] <= high + 1 / 200 + 1e-9)
    floor = MIN_SAMPLES / 200.0
    assert all(x >= floor for x in (pred["value"], out["value"], *(e["contact_s"] for e in out["evaluations"])))
    with pytest.raises(Exception, match="seeds of its own"):
        predict_and_confirm(r, t, trials=20, repeats=2, confirm_repeats=4, n_mc=50, confirm_seed=0)
