"""Physics layer (paper eqs. 1-4): against mpmath, at the limits, across the domain."""

from __future__ import annotations

import math
import warnings

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designkit import SENSORS, Scene, Sensor
from designkit.models.semi_infinite import (
    contact_temperature,
    effusivity,
    effusivity_from_conductivity_diffusivity,
    log_response_shape,
    object_weight,
    response_shape,
    sensor_temperature,
    temperature_change,
    time_constant,
)

mpmath.mp.dps = 50


def mp_change(t, e_o, ts0, ta, e_s, tau):
    """T(t) - Ts0 from paper eqs. 1-2, evaluated in 50-digit arithmetic."""
    t, e_o, ts0, ta, e_s, tau = (mpmath.mpf(float(v)) for v in (t, e_o, ts0, ta, e_s, tau))
    tc = (ts0 * e_s + ta * e_o) / (e_s + e_o)
    return (tc - ts0) * mpmath.erfc(mpmath.sqrt(tau / t))


def test_paper_tau():
    # tau = x^2 / (4 alpha_s) for 80 um and 1.19e-9 m^2/s (DOMAIN.md: about 1.34 s)
    assert SENSORS["paper"].tau_s == pytest.approx((80e-6) ** 2 / (4 * 1.19e-9), rel=1e-15)
    assert SENSORS["paper"].tau_s == pytest.approx(1.3445, abs=1e-4)


def test_noise_free_matches_mpmath_including_erfc_tail():
    rng = np.random.default_rng(7)
    tau = SENSORS["paper"].tau_s
    # times from 1e-3 tau (erfc(31.6) ~ 1e-436: underflows) to 1e3 tau, plus the
    # deep-but-representable tail down to erfc ~ 1e-300
    ratios = np.concatenate([10 ** rng.uniform(-3, 2.8, 300), [700.0, 650.0, 500.0, 100.0]])
    e_o = 10 ** rng.uniform(0, 5, ratios.size)
    ts0 = rng.uniform(20, 40, ratios.size)
    ta = rng.uniform(-10, 30, ratios.size)
    t = tau / ratios
    ours = temperature_change(t, e_o, ts0, ta, 892.0, tau)
    for i in range(ratios.size):
        ref = mp_change(t[i], e_o[i], ts0[i], ta[i], 892.0, tau)
        if abs(ref) < mpmath.mpf("1e-290"):  # below double precision's normal range
            assert abs(ours[i]) <= 1e-290
            continue
        assert abs(ours[i] - float(ref)) <= 1e-12 * abs(float(ref)), (t[i], e_o[i])
    full = sensor_temperature(t, e_o, ts0, ta, 892.0, tau)
    ref_full = np.array([float(mpmath.mpf(float(a)) + mp_change(*v, 892.0, tau))
                         for a, v in zip(ts0, zip(t, e_o, ts0, ta))])
    np.testing.assert_allclose(full, ref_full, rtol=1e-12, atol=0)


def test_log_shape_matches_mpmath_far_beyond_underflow():
    ratios = np.array([1e-6, 1e-2, 1.0, 10.0, 700.0, 1e3, 1e5, 1e8])
    ours = log_response_shape(1.0, ratios)
    for r, v in zip(ratios, ours):
        ref = mpmath.log(mpmath.erfc(mpmath.sqrt(mpmath.mpf(float(r)))))
        assert abs(v - float(ref)) <= 1e-12 * abs(float(ref)) + 1e-15, r
    # consistent with the direct form where that does not underflow
    np.testing.assert_allclose(np.exp(log_response_shape(1.0, ratios[:5])), response_shape(1.0, ratios[:5]),
                               rtol=1e-12)


def test_limits_are_exact_and_silent():
    tau = SENSORS["paper"].tau_s
    t = np.array([0.0, 1e-9, 0.005, 1.0, 10.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # t = 0: the buried thermistor has not moved
        assert sensor_temperature(0.0, 5000.0, 35.0, 25.0, 892.0, tau) == 35.0
        # x = 0 (tau = 0): surface at the contact temperature at once, also at t = 0
        tc = contact_temperature(35.0, 25.0, 892.0, 5000.0)
        np.testing.assert_array_equal(sensor_temperature(t, 5000.0, 35.0, 25.0, 892.0, 0.0), np.full(5, tc))
        # e_o = 0: a perfect insulator takes no heat
        np.testing.assert_array_equal(sensor_temperature(t, 0.0, 35.0, 25.0, 892.0, tau), np.full(5, 35.0))
        # e_o = inf: the surface takes the object's temperature
        assert object_weight(892.0, np.inf) == 1.0
        assert contact_temperature(35.0, 25.0, 892.0, np.inf) == 25.0
        np.testing.assert_allclose(sensor_temperature(t, np.inf, 35.0, 25.0, 892.0, tau),
                                   35.0 - 10.0 * response_shape(t, tau), rtol=0, atol=1e-15)
        # Ts0 = Ta: no signal
        np.testing.assert_array_equal(sensor_temperature(t, 5000.0, 25.0, 25.0, 892.0, tau), np.full(5, 25.0))
        # t << tau: exactly Ts0 in double precision, never NaN
        assert sensor_temperature(1e-300, 5000.0, 35.0, 25.0, 892.0, tau) == 35.0


def test_ten_kilohertz_for_ten_seconds_is_finite_and_monotone():
    sensor = Sensor(892.0, 1.19e-9, sample_rate_hz=10_000.0)
    t = sensor.times_s(10.0)
    assert t.size == 100_001
    temp = sensor_temperature(t, 20000.0, 35.0, 25.0, sensor.effusivity, sensor.tau_s)
    assert np.all(np.isfinite(temp))
    assert np.all(np.diff(temp) <= 0)  # a hot sensor only cools
    assert temp[0] == 35.0 and 25.0 < temp[-1] < 35.0


def test_contact_shorter_than_one_sample_has_the_contact_instant_only():
    s = SENSORS["paper"]
    assert s.times_s(0.001).tolist() == [0.0]
    assert s.times_s(2.0).size == 401  # 2 s at 200 Hz, both ends included


def test_effusivity_definitions_agree():
    k, rho, c = 401.0, 8960.0, 385.0  # copper
    alpha = k / (rho * c)
    assert effusivity(k, rho, c) == pytest.approx(effusivity_from_conductivity_diffusivity(k, alpha), rel=1e-14)
    # published effusivity of copper: about 37,000 J s^-1/2 K^-1 m^-2
    assert float(effusivity(k, rho, c)) == pytest.approx(37000.0, rel=0.01)


def test_time_constant_identifies_only_the_ratio():
    # doubling the depth and quadrupling the diffusivity gives the same curve
    t = np.linspace(0, 5, 11)
    a = response_shape(t, time_constant(80e-6, 1.19e-9))
    b = response_shape(t, time_constant(160e-6, 4 * 1.19e-9))
    np.testing.assert_array_equal(a, b)


temps = st.floats(-40, 150)


@settings(max_examples=300, deadline=None)
@given(
    t=st.floats(0, 1e4),
    e_o=st.one_of(st.floats(0, 1e7), st.just(math.inf)),
    e_s=st.floats(1e-3, 1e6),
    tau=st.floats(0, 1e3),
    ts0=temps,
    ta=temps,
)
def test_reading_stays_between_initial_temperatures(t, e_o, e_s, tau, ts0, ta):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        v = float(sensor_temperature(t, e_o, ts0, ta, e_s, tau))
    lo, hi = min(ts0, ta), max(ts0, ta)
    assert lo - 1e-9 <= v <= hi + 1e-9


@settings(max_examples=100, deadline=None)
@given(e_o=st.floats(1e-3, 1e6), tau=st.floats(1e-6, 1e2), dt=st.floats(0.1, 100))
def test_reading_is_monotone_in_time_and_effusivity(e_o, tau, dt):
    t = np.linspace(0, 60, 301)
    a = sensor_temperature(t, e_o, 25 + dt, 25.0, 892.0, tau)
    assert np.all(np.diff(a) <= 1e-12)
    b = sensor_temperature(t, e_o * 1.5, 25 + dt, 25.0, 892.0, tau)
    assert np.all(b <= a + 1e-12)  # a better conductor draws more heat


def test_scene_rejects_bad_input():
    from designkit import InputError

    for kwargs, match in [
        ({"contact_s": 0}, "contact time"),
        ({"contact_s": -1}, "contact time"),
        ({"contact_s": math.nan}, "contact time"),
        ({"noise_c": -0.1}, "noise"),
        ({"noise_c": math.inf}, "noise"),
        ({"sensor_temp_c": math.nan}, "sensor temperature"),
    ]:
        with pytest.raises(InputError, match=match):
            Scene(**kwargs)
    assert Scene(noise_c=0.0).noise_ratio == 0.0
    assert Scene(sensor_temp_c=25.0).noise_ratio == math.inf
    assert Scene.from_delta_t(delta_t_c=10, noise_c=0.05).noise_ratio == pytest.approx(0.005)


def test_sensor_yaml_round_trip(tmp_path):
    from designkit import InputError, load_sensor

    s = Sensor(1000.0, 2e-9, depth_m=1e-4, sample_rate_hz=100.0, name="mine", noise_c=0.03,
               provenance={"fit": "test"})
    path = s.to_yaml(tmp_path / "mine.yaml")
    back = load_sensor(path)
    assert back == s and back.tau_s == s.tau_s and back.provenance == {"fit": "test"}
    bad = tmp_path / "bad.yaml"
    bad.write_text("effusivity: -3\ndiffusivity_m2_s: 1e-9\n")
    with pytest.raises(InputError, match="sensor effusivity"):
        load_sensor(bad)
    bad.write_text("effusivity: 800\ndiffusivity_m2_s: 1e-9\ntau_s: 5\n")
    with pytest.raises(InputError, match="tau_s"):
        load_sensor(bad)
    bad.write_text("effusivity: [unclosed\n")
    with pytest.raises(InputError, match="not valid YAML"):
        load_sensor(bad)
    with pytest.raises(InputError, match="unknown sensor"):
        load_sensor("no-such-preset")
