"""Round trips over a real pty for every identifiable sensor model: a few seeds here, 50 in benchmarks/."""

from __future__ import annotations

import numpy as np
import pytest

from designkit import InputError
from designkit_lab.emulator import EmulatedMaterial, Emulator, TouchPlan
from designkit.calibration.profiles import load_profile
from designkit_lab.roundtrip import CASES, round_trip, summarize
from designkit.models import get_model
from designkit.sensor import Sensor

SENSOR = Sensor(1000.0, 1.5e-9, depth_m=80e-6)


def _emulator(model=None, noise=0.0):
    return Emulator(load_profile("designkit"), SENSOR, [EmulatedMaterial("wood", 400.0)], noise_c=noise,
                    sensor_temp_c=29.5, ambient_c=22.5, plan=TouchPlan(touch_every_s=13.0), model=model,
                    force_noise_n=0.0)


def test_the_emulator_streams_any_forward_model_reading():
    layered = get_model("layered", film_thickness_m=150e-6, backing_effusivity_ws05_m2k=300.0,
                        conductance_w_m2k=2500.0, lag_s=0.4, smoothing_window=99)
    emu = _emulator(layered)
    fs = emu.profile.sample_rate_hz
    start = emu.touch(0).start_s
    k0 = int(round(start * fs))
    v = emu.values(k0 - 10, k0 + 600)["sensor"]
    rel = (np.arange(k0 - 10, k0 + 600) / fs) - start
    pos = rel >= 0
    # the raw conduction (the wire carries no host smoothing), independently computed
    u = layered.conduction(rel[pos], [400.0], SENSOR)[0]
    assert np.allclose(v[pos], 29.5 + (22.5 - 29.5) * u, rtol=0, atol=1e-12)
    assert np.all(v[~pos] == 29.5)
    # the semi-infinite model named explicitly streams exactly what the default always did
    a, b = _emulator(None, 0.05), _emulator("semi-infinite", 0.05)
    assert np.array_equal(a.values(0, 5000)["sensor"], b.values(0, 5000)["sensor"])
    with pytest.raises(InputError, match="needs their diffusivity"):
        _emulator(get_model("slab", thickness_m=0.003))


def test_the_emulator_streams_drift_and_a_contact_area_following_each_touch_s_own_force():
    from designkit.models.ramp import ForceRamp

    contact = get_model("contact", conductance_w_m2k=2500.0)
    plan = TouchPlan(touch_every_s=15.0, contact_s=9.0, ramp_s=0.6, ramp_spread=0.5, contact_force_fraction=0.3,
                     drift_c_per_s=0.1, drift_sd_c_per_s=0.03, touches_per_material=3)
    emu = Emulator(load_profile("designkit"), SENSOR, [EmulatedMaterial("wood", 400.0)], noise_c=0.0,
                   sensor_temp_c=29.5, ambient_c=22.5, plan=plan, model=contact, force_noise_n=0.0, seed=4)
    fs = emu.profile.sample_rate_hz
    ramps = [emu.touch_ramp_s(j) for j in range(3)]
    drifts = [emu.touch_drift_c_per_s(j) for j in range(3)]
    assert len(set(ramps)) == 3 and all(0.3 <= r <= 0.9 for r in ramps) and len(set(drifts)) == 3
    assert emu.expected_time_offset_s == 0.0     # each share conducts from when the force puts it down
    for j in range(3):
        start = emu.touch(j).start_s
        k0 = int(round((start - 1.2) * fs))
        v = emu.values(k0, k0 + int(8 * fs))
        rel = np.arange(k0, k0 + int(8 * fs)) / fs - start
        # the force: a linear ramp of this touch's own pace to its plateau
        f = emu.plan.press_force_n
        assert v["force"] == pytest.approx(np.where(rel >= 0, f * np.clip(rel / ramps[j], 0.0, 1.0), 0.0), abs=1e-9)
        # the reading: the drifting baseline on the sensor's side, the area-weighted sum of step responses
        # (ForceRamp, checked against quadrature in test_force_ramp.py)
        fine = np.arange(0.0, ramps[j] + 0.0015, 0.001)
        first = float(fine[np.flatnonzero(fine / ramps[j] > 0.3)[0]])
        ramp = ForceRamp.from_force_profile(contact, fine, np.minimum(fine / ramps[j], 1.0), 0.3)
        u = np.zeros(rel.size)
        on = rel > first
        u[on] = ramp.response(rel[on] - first, [400.0], SENSOR)[0]
        base = 29.5 + drifts[j] * (rel + emu.plan.drift_lead_s)
        want = np.where(rel >= -emu.plan.drift_lead_s, base, 29.5) * (1 - u) + 22.5 * u
        assert v["sensor"] == pytest.approx(want, abs=2e-4)
    # a sensor file's force-ramp model plays its base model with the file's threshold
    file_model = ForceRamp(contact, (0.0, 0.5), (0.5, 1.0), force_fraction=0.25)
    emu2 = Emulator(load_profile("designkit"), SENSOR, [EmulatedMaterial("wood", 400.0)], plan=TouchPlan(
        touch_every_s=13.0), model=file_model)
    assert emu2.model == contact and emu2.plan.contact_force_fraction == 0.25


@pytest.mark.parametrize("case", list(CASES))
def test_round_trip_over_a_pty_recovers_every_identifiable_parameter(case, tmp_path):
    # the area cases read the area from the measured force: its noise, clipped at the plateau, biases
    # e_o/e_s by a few tenths of a percent (docs/sensor-models.md); here the force is clean, and they
    # have 10 + 10 touches as in the benchmark (c's 95 % interval is about +-2 % with them)
    area = "area" in case
    touches = 10 if area else 6
    r = round_trip(case, seed=0, folder=tmp_path, touches=touches, force_noise_n=0.0 if area else 0.02)
    assert r.n_trials == 2 * touches and (tmp_path / "index.csv").is_file()   # recorded from the pty
    for name in r.rows:
        assert r.covered(name), (name, r.rows[name])
        assert r.rel_error(name) <= 0.02, (name, r.rows[name])
    truth, lo, hi = r.es
    assert lo <= truth <= hi
    t_off, est, lo, hi = r.offset
    assert abs(est - t_off) <= 0.005   # the detected onset defines the truth to one sample (5 ms)
    summ = summarize([r])
    assert set(summ) == set(r.rows) | {"e_s", "time_offset_s"} and summ["e_s"]["coverage"] == 1.0


def test_unknown_case_is_named():
    with pytest.raises(InputError, match="unknown round-trip case 'slab'"):
        round_trip("slab", 0)


def test_varied_presses_span_quick_and_slow_touches():
    """The protocol that identifies c within 2 % presses at widely varied pace (docs/sensor-models.md)."""
    from designkit_lab.roundtrip import CHAIN_PLAN, VARIED_PRESS

    case = CASES["contact+drift+area"]
    ramps = {}
    for press in (None, VARIED_PRESS):
        emu = Emulator(load_profile("designkit"), SENSOR, [EmulatedMaterial("wood", 400.0)],
                       plan=TouchPlan(**case.plan(10, press)), model=get_model(dict(case.model)), seed=7)
        ramps[press] = [emu.touch_ramp_s(j) for j in range(10)]
    mean, spread = CHAIN_PLAN["ramp_s"], CHAIN_PLAN["ramp_spread"]
    lo, hi = mean * (1 - spread), mean * (1 + spread)
    assert all(lo <= r <= hi for r in ramps[None])
    assert min(ramps[VARIED_PRESS]) < lo and max(ramps[VARIED_PRESS]) > hi
