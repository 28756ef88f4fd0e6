"""The force-driven contact area and the heater drift travel in the sensor file, and every command plays them.

A sensor calibrated with ``+drift+area`` records the area threshold c and the calibration touches' median
force ramp; questions, simulate and f1 answer with the model plus that nominal ramp (a question has no
force trace) and no drift (a per-touch nuisance), and say so (issue 14).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import integrate

from designkit import SENSORS, InputError
from designkit.calibration.candidates import Candidate
from designkit.calibration.force import nominal_force_profile, relative_force
from designkit.calibration.identify import identify
from designkit.calibration.trials import Trial
from designkit.models import get_model, load_sensor_model, sensor_model, sensor_model_notes
from designkit.models.ramp import ForceRamp, area_share
from designkit.rig import rig_scene
from designkit.sensor import Sensor

SENSOR = Sensor(1000.0, 1.5e-9, depth_m=80e-6, name="synthetic")
CHAIN = Candidate("contact+drift+area", "contact", ("diffusivity_m2_s", "conductance_w_m2k", "contact_force_fraction"),
                  drift=True, force_area=True)
RANGES = {"wood": (331.0, 506.46), "granite": (2252.32, 2749.87)}
E_O = {"wood": 400.0, "granite": 2500.0}
C_TRUE, HC_TRUE, OFFSET_S = 0.3, 2500.0, 0.1


# ------------------------------------------------------------------ the model
def test_a_ramp_is_duhamel_s_integral_of_the_step_response():
    """A linear area ramp against scipy's quadrature of (1/T) int_0^min(t,T) u_step(t - s) ds."""
    base = get_model("contact", conductance_w_m2k=HC_TRUE)
    ramp_s, dt = 0.5, 5e-4
    tj = np.arange(0.0, ramp_s + dt / 2, dt)
    ramp = ForceRamp(base, tuple(tj), tuple(np.minimum((tj + dt) / ramp_s, 1.0)))
    t = np.array([0.05, 0.2, 0.49, 0.8, 2.0])
    got = ramp.response(t, [400.0], SENSOR)[0]

    def step(x):
        return base.response([x], [400.0], SENSOR)[0, 0] if x > 0 else 0.0

    want = [integrate.quad(lambda s: step(tt - s) / ramp_s, 0.0, min(tt, ramp_s), limit=200)[0] for tt in t]
    assert got == pytest.approx(want, abs=2e-3)   # the stepwise ramp's discretization (dt / T = 1e-3)
    assert np.all(got < base.response(t, [400.0], SENSOR)[0])


def test_an_instant_ramp_is_the_base_model_even_smoothed():
    layered = get_model("layered", film_thickness_m=2e-4, backing_effusivity_ws05_m2k=600.0, conductance_w_m2k=3000.0,
                        lag_s=0.5, smoothing_window=99, smoothing_order=3)
    t = np.arange(401) / 200.0
    instant = ForceRamp(layered, (0.0,), (1.0,))
    assert instant.response(t, [400.0, 20000.0], SENSOR) == pytest.approx(
        layered.response(t, [400.0, 20000.0], SENSOR), abs=1e-12)
    # the smoothing is applied once to the sum: a two-step ramp is the smoothed sum of shifted raw readings
    two = ForceRamp(layered, (0.0, 0.25), (0.4, 1.0))
    raw = get_model("layered", **{**layered.parameters(), "smoothing_window": 0})
    pre = np.arange(-49, 0) / 200.0
    grid = np.concatenate([pre, t])
    summed = 0.4 * raw.response(np.maximum(grid, 0.0), [400.0], SENSOR) \
        + 0.6 * np.where(grid > 0.25, raw.response(np.maximum(grid - 0.25, 0.0), [400.0], SENSOR), 0.0)
    from scipy.signal import savgol_filter

    want = np.clip(savgol_filter(summed, 99, 3, axis=-1, mode="interp")[:, 49:], 0, 1)
    assert two.response(t, [400.0], SENSOR) == pytest.approx(want, abs=1e-9)


@pytest.mark.parametrize("times, areas, message", [
    ((0.1, 0.2), (0.5, 1.0), "start at 0"),
    ((0.0, 0.2), (0.5, 0.9), "end at 1"),
    ((0.0, 0.2, 0.3), (0.6, 0.5, 1.0), "non-decreasing"),
    ((0.0,), (1.0, 1.0), "as many"),
])
def test_a_bad_ramp_is_one_line(times, areas, message):
    with pytest.raises(InputError, match=message):
        ForceRamp(get_model("contact", conductance_w_m2k=HC_TRUE), times, areas)


def test_a_ramp_survives_to_dict_and_back():
    r = ForceRamp.from_force_profile(get_model("contact", conductance_w_m2k=HC_TRUE), [0.0, 0.1, 0.2, 0.3],
                                     [0.1, 0.5, 0.9, 1.0], C_TRUE, source="test")
    again = get_model(json.loads(json.dumps(r.to_dict())))
    assert again == r and hash(again) == hash(r) and "growing over 0.20 s" in again.describe()
    with pytest.raises(InputError, match="never exceeds"):
        ForceRamp.from_force_profile(r.base, [0.0, 0.1], [0.1, 0.2], 0.5)


# ------------------------------------------------------------------ synthetic calibration
def _touches(seed: int, n_per: int = 6) -> list[Trial]:
    """Touches whose sensor drifts and whose area follows a force ramp of its own pace (summed in a loop)."""
    rng = np.random.default_rng(seed)
    model = get_model("contact", conductance_w_m2k=HC_TRUE)
    t = np.arange(-200, 1201) / 200.0
    out = []
    for k, (name, eo) in enumerate(E_O.items()):
        for i in range(n_per):
            ramp = rng.uniform(0.3, 1.0)
            force = 4.5 * np.clip(0.2 + 0.8 * t / ramp, 0.0, 1.0)
            d_area = np.diff(area_share(force / 4.5, C_TRUE), prepend=0.0)
            u = np.zeros(t.size)
            for j in np.flatnonzero(d_area):
                tt = t - t[j] - OFFSET_S
                pos = tt > 0
                u[pos] += d_area[j] * model.response(tt[pos], [eo], SENSOR)[0]
            ts0, to, slope = 29.5 + rng.normal(0, 0.2), 22.5 + rng.normal(0, 0.3), rng.normal(0.1, 0.03)
            y = (ts0 + slope * t) * (1.0 - u) + to * u + rng.normal(0, 0.01, t.size)
            out.append(Trial(t, y, np.full(t.size, to), force, name, source=f"set{i + 1:02d}_{name}_{k}.csv"))
    return out


@pytest.fixture(scope="module")
def synthetic_fit():
    trials = _touches(seed=5)
    return trials, identify(trials, CHAIN, ranges=RANGES)


def test_the_sensor_file_records_c_the_nominal_force_ramp_and_the_drift(synthetic_fit, tmp_path):
    trials, res = synthetic_fit
    path = tmp_path / "chain.yaml"
    res.sensor(name="chain").to_yaml(path)
    text = path.read_text()
    assert "contact_area:" in text and "drift: per-touch" in text and "a question's touch has none" in text
    sen, fm = load_sensor_model(path)
    area = sen.model["contact_area"]
    c = res.parameter("contact_force_fraction")
    # the interval in the schema's shape (docs/schema.md: {low, high, coverage}), as calibrate fit's parameters
    assert area["force_fraction"] == c.value and "force_fraction_ci95" not in area
    assert area["force_fraction_interval"] == {"low": c.ci95[0], "high": c.ci95[1], "coverage": 0.95} \
        == c.to_dict()["interval"] and c.ci95[0] < c.value < c.ci95[1]
    assert c.to_dict()["identifiable"] is True and "identified" not in c.to_dict()
    assert area["force_fraction"] == pytest.approx(C_TRUE, rel=0.05) and area["n_touches"] == len(trials)
    # the nominal ramp is the touches' median F / F_p, the force averaged over 25 ms (5 samples at 200 Hz,
    # ends held), computed here without identify
    grid = np.asarray(area["time_s"])

    def smooth(f):
        return np.convolve(np.pad(f, 2, mode="edge"), np.ones(5) / 5, mode="valid")

    med = np.median([np.interp(grid, tr.time_s, smooth(tr.force_n) / np.median(smooth(tr.force_n)[tr.time_s >= 1.0]))
                     for tr in trials], axis=0)
    assert area["force_share"] == pytest.approx(med, abs=1e-4)
    # and the model that answers is the file's contact model played along that ramp
    assert isinstance(fm, ForceRamp) and fm.base == res.model() and fm.force_fraction == c.value
    first = grid[np.flatnonzero(area_share(med, c.value) > 0)[0]]
    t = np.arange(0, 801) / 200.0
    want = res.reading(t + first + res.parameter("time_offset_s").value, "wood", force=med, force_time_s=grid)
    got = fm.response(t, [res.ratios["wood"].value * res.effusivity.value], sen)[0]
    assert got == pytest.approx(want, abs=2e-3)   # the reading's force is interpolated at 5 ms, the ramp at 20 ms
    notes = sensor_model_notes(sen, fm)
    assert notes[0] == "model contact with a force-driven contact area: recorded in sensor file chain " \
                       "(calibrated as contact+drift+area)"
    assert "median force ramp of the 12 calibration touches" in notes[1] and "a new touch has none" in notes[2]


def test_a_record_with_a_broken_contact_area_is_one_line(tmp_path):
    rec = {"name": "contact", "params": {"conductance_w_m2k": 2500.0}, "contact_area": {"force_fraction": 0.2}}
    with pytest.raises(InputError, match="its recorded model: contact_area needs time_s, force_share"):
        sensor_model(SENSORS["paper"].replace(model=rec))
    path = tmp_path / "bad.yaml"
    path.write_text("effusivity: 1000\ndiffusivity_m2_s: 1e-9\nmodel: {name: contact, drift: [1]}\n")
    with pytest.raises(InputError, match="model.drift"):
        load_sensor_model(path)


def test_nominal_force_profile_of_trials_and_of_prepared_data_agree(synthetic_fit):
    trials, res = synthetic_fit
    assert nominal_force_profile(trials) == res.force_profile
    assert res.to_dict()["force_profile"]["n_touches"] == len(trials)
    # identify's own area share is the model layer's
    assert relative_force(trials[0])[-1] == pytest.approx(1.0)


def test_commands_answer_with_the_ramp_and_say_what_they_play(cli, synthetic_fit, tmp_path):
    _, res = synthetic_fit
    path = tmp_path / "chain.yaml"
    res.sensor(name="chain").to_yaml(path)
    sim = json.loads(cli("simulate", "--e", "400", "--contact", "1", "--sensor", path, "--json").stdout)
    assert sim["model"]["name"] == "force-ramp" and sim["model"]["base"]["name"] == "contact"
    assert sim["model_source"] == "sensor file"
    full = json.loads(cli("simulate", "--e", "400", "--contact", "1", "--sensor", path, "--conductance",
                          str(res.model().conductance_w_m2k), "--json").stdout)
    ramped, at_once = np.ravel(sim["temperature_c"]), np.ravel(full["temperature_c"])
    assert abs(ramped[-1] - ramped[0]) < abs(at_once[-1] - at_once[0])   # the area comes in over the ramp
    f1 = cli("f1", "--e1", "400", "--e2", "2000", "--contact", "1", "--trials", "20", "--sensor", path)
    assert f1.exit_code == 0, f1.output
    words = " ".join(f1.stdout.split())
    assert "with a contact area growing over" in words and "heater drift: fitted per touch" in words
    ans = json.loads(cli("distinguishable", "--e1", "400", "--e2", "2000", "--contact", "1", "--sensor", path,
                         "--trials", "20", "--repeats", "1", "--n-mc", "50", "--json").stdout)
    assert ans["route"] == "exact" and ans["model"]["name"] == "force-ramp"
    assert any("median force ramp of the 12 calibration touches" in n for n in ans["notes"])
    assert any("not played here: a new touch has none" in n for n in ans["notes"])


# ------------------------------------------------------------------ the real sensor
def test_the_real_sensor_file_answers_questions_with_its_model(cli, robot_data_dir, tmp_path):
    out = tmp_path / "real.yaml"
    fit = cli("calibrate", "fit", robot_data_dir / "index.csv", "--only", "metal", "--only", "wood", "--range",
              "metal=aluminium", "--model", "layered+lag+smoothing+drift+area", "--fit-sets", "1-4", "--out", out)
    assert fit.exit_code == 0, fit.output
    sen, fm = load_sensor_model(out)
    assert sen.model["candidate"] == "layered+lag+smoothing+drift+area" and sen.model["drift"] == "per-touch"
    assert isinstance(fm, ForceRamp) and fm.base.name == "layered" and fm.base.smoothing_window == 99
    assert 0.0 < fm.force_fraction < 0.5 and 0.5 < fm.ramp_duration_s < 3.0 and sen.model["contact_area"][
        "n_touches"] == 24
    # the rig's scene: each of the 24 calibration presses, the residual's correlation, the recorder's onset
    assert len(fm.touch_ramps) == 24 and np.ptp([d for d, _, _ in fm.touch_ramps]) > 0.3
    assert 0.2 < sen.conditions["noise_correlation_s"] < 3.0
    assert rig_scene(sen)["onset_s"] == pytest.approx(-sen.conditions["onset_offset_s"], abs=1e-3)
    ans = json.loads(cli("distinguishable", "--m1", "wood", "--m2", "glass", "--contact", "1", "--sensor", out,
                         "--trials", "20", "--repeats", "1", "--n-mc", "50", "--json").stdout)
    assert ans["model"]["name"] == "force-ramp" and ans["model"]["base"]["name"] == "layered"
    assert any("recorded in sensor file real (calibrated as layered+lag+smoothing+drift+area)" in n
               for n in ans["notes"])


def test_a_sweep_config_takes_the_ramp_and_its_record_survives_json(synthetic_fit, tmp_path):
    from designkit.sweep.config import SweepConfig

    _, res = synthetic_fit
    path = tmp_path / "chain.yaml"
    res.sensor(name="chain").to_yaml(path)
    cfg = SweepConfig(sensor=str(path), intervals=4, contact_s=(1.0,))
    assert cfg.model == sensor_model(load_sensor_model(path)[0]) and cfg.model.name == "force-ramp"
    assert get_model(json.loads(json.dumps(cfg.model.to_dict()))) == cfg.model   # what a table header keeps


def test_touches_press_as_the_calibration_touches_did(paper_sensor):
    """With touch ramps each simulated touch reads one calibration press (its own pace and first contact):
    the class's curves spread where the nominal ramp gives one curve."""
    from designkit import Scene
    from designkit.models.semi_infinite import SemiInfinite
    from designkit.objects import object_class
    from designkit.simulation import simulate_class

    t = np.arange(0, 60) * 0.02
    med = np.clip(t / 0.6, 0, 1)
    touches = [np.clip((t - d) / p, 0, 1) for d, p in ((0.0, 0.3), (0.2, 0.6), (-0.0, 1.0))]
    fm = ForceRamp.from_force_profile(SemiInfinite(), t, med, 0.1, touch_force_rel=touches)
    assert len(fm.touch_ramps) == 3 and fm.touch_ramps[1][0] == pytest.approx(0.2)
    assert get_model(fm.to_dict()) == fm and fm.nominal().touch_ramps == ()
    scene = Scene(contact_s=1.0, noise_c=0.0)
    pressed = simulate_class(object_class(20000), 30, paper_sensor, scene, seed=3, model=fm).temperature_c
    nominal = simulate_class(object_class(20000), 30, paper_sensor, scene, seed=3, model=fm.nominal()).temperature_c
    assert np.ptp(pressed[:, -1]) > 20 * np.ptp(nominal[:, -1])
    assert len({round(v, 9) for v in pressed[:, 100]}) >= 3


def test_a_class_s_touches_read_at_once_are_each_touch_ramp_s_response():
    """ForceRamp.touch_readings (a class's touches, each pressing as its calibration touch, smoothed in one call)
    gives what each touch's own ramp reads at its own first contact, to rounding; and the layered model's cached
    Laplace parts do not depend on which grids were read before (a longer grid of the same start first)."""
    from designkit.models import layered

    lay = get_model("layered", film_thickness_m=2.2e-4, backing_effusivity_ws05_m2k=2000.0, conductance_w_m2k=1800.0,
                    lag_s=1.1, smoothing_window=99, smoothing_order=3)
    tp = np.arange(0, 60) * 0.02
    ramp = ForceRamp.from_force_profile(lay, tp, np.clip(tp / 0.9, 0, 1), 0.16,
                                        touch_force_rel=[np.clip((tp - d) / w, 0, 1) for d, w in
                                                         ((0.1, 0.5), (0.0, 0.9), (0.3, 0.7))])
    t = 0.4 + np.arange(120) / SENSOR.sample_rate_hz
    e = np.array([300.0, 450.0, 2500.0, 800.0, 20000.0])
    touch = np.array([2, 0, 1, 2, 0])
    layered._scene_parts.cache_clear()
    got = ramp.touch_readings(t, e, touch, SENSOR)
    for k in range(e.size):
        one, delay = ramp.touch(touch[k])
        np.testing.assert_allclose(got[k], one.response(t - delay, e[k:k + 1], SENSOR)[0], rtol=0, atol=1e-13)
    short = np.arange(1, 150) / 200.0
    layered._scene_parts.cache_clear()
    cold = lay.conduction(short, e, SENSOR)
    lay.conduction(np.arange(1, 900) / 200.0, e, SENSOR)   # a longer grid of the same start read in between
    np.testing.assert_array_equal(lay.conduction(short, e, SENSOR), cold)


def test_a_ramp_on_the_grid_s_own_step_reads_one_step_response():
    """A ramp sampled on the grid's own step (a calibrated rig's touch ramp, 20 ms, on 200 Hz readings from its
    onset) reads its base model once on one lag grid, although the shares' fractional shifts differ in their last
    bits (they used to straddle a 9-digit rounding: two step responses, twice the work); the reading is the
    Duhamel sum read share by share at any times, to rounding."""
    from designkit.models.semi_infinite import SemiInfinite

    grids = []

    class Counting(SemiInfinite):
        def response(self, time_s, e_object, sensor, **kw):
            grids.append(np.size(time_s))
            return super().response(time_s, e_object, sensor, **kw)

    tj = np.round(np.arange(127) * 0.02, 9)
    ramp = ForceRamp(Counting(), tuple(tj), tuple(np.linspace(0.05, 1.0, tj.size)))
    t = 0.9177346451224817 + np.arange(400) * 0.004999999999999893
    got = ramp.response(t, [450.0], SENSOR)
    assert len(grids) == 1
    jitter = t + np.r_[0.0, 1e-7, np.zeros(398)]   # not uniform: every share read at its own lags
    np.testing.assert_allclose(got[:, 2:], ramp.response(jitter, [450.0], SENSOR)[:, 2:], rtol=1e-11, atol=1e-14)


def test_a_class_s_touch_ramps_share_one_step_response():
    """The touches of a class, each pressing as its calibration touch (ramps on the grid's step, delays of whole
    samples), read the base model once, on the lag grid of the latest share, for all objects; each touch as its
    own ramp reads it alone, to rounding."""
    from designkit.models.semi_infinite import SemiInfinite

    grids = []

    class Counting(SemiInfinite):
        def response(self, time_s, e_object, sensor, **kw):
            grids.append((np.size(time_s), np.size(e_object)))
            return super().response(time_s, e_object, sensor, **kw)

    tp = np.arange(0, 60) * 0.02
    ramp = ForceRamp.from_force_profile(Counting(), tp, np.clip(tp / 0.9, 0, 1), 0.16,
                                        touch_force_rel=[np.clip((tp - d) / w, 0, 1) for d, w in
                                                         ((0.1, 0.5), (0.0, 0.9), (0.3, 0.7))])
    t = 0.4 + np.arange(120) / SENSOR.sample_rate_hz
    e = np.array([300.0, 450.0, 2500.0, 800.0, 20000.0])
    touch = np.array([2, 0, 1, 2, 0])
    got = ramp.touch_readings(t, e, touch, SENSOR)
    assert len(grids) == 1 and grids[0][1] == e.size
    for k in range(e.size):
        one, delay = ramp.touch(touch[k])
        np.testing.assert_allclose(got[k], one.response(t - delay, e[k:k + 1], SENSOR)[0], rtol=0, atol=1e-13)


def test_a_ramp_unpickled_in_another_process_hashes_as_one_made_there():
    """A ramp's hash is made once per process (scene caches look it up class after class) and never carried by a
    pickle (a string's hash differs between processes): a sweep worker's unpickled model hashes as an equal model
    made there."""
    import os
    import pickle
    import subprocess
    import sys

    ramp = ForceRamp(None, (0.0, 0.1), (0.5, 1.0), 0.1, "calibration touches")
    hash(ramp)
    code = ("import pickle, sys; from designkit.models.ramp import ForceRamp; "
            "r = pickle.loads(sys.stdin.buffer.read()); "
            "made = ForceRamp(None, (0.0, 0.1), (0.5, 1.0), 0.1, 'calibration touches'); "
            "print(hash(r) == hash(made) and r == made)")
    out = subprocess.run([sys.executable, "-c", code], input=pickle.dumps(ramp), capture_output=True, check=True,
                         env={**os.environ, "PYTHONHASHSEED": "4321"})
    assert out.stdout.strip() == b"True"
