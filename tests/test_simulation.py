"""Simulated touches: reproducibility, the exact shortcuts the engine relies on, noise law."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from scipy import stats

from designkit import InputError, Scene
from designkit.models.semi_infinite import sensor_temperature
from designkit.simulation import draw_trials, render_trials, simulate_interval, simulate_trials


def test_same_seed_same_trials_different_seed_different(paper_sensor):
    scene = Scene(contact_s=1.0)
    a = simulate_interval(1000, 1080, 20, paper_sensor, scene, seed=3)
    b = simulate_interval(1000, 1080, 20, paper_sensor, scene, seed=3)
    c = simulate_interval(1000, 1080, 20, paper_sensor, scene, seed=4)
    np.testing.assert_array_equal(a.temperature_c, b.temperature_c)
    assert not np.array_equal(a.temperature_c, c.temperature_c)


def test_same_seed_same_trials_in_another_process(paper_sensor):
    """Nothing machine- or process-dependent (hash seeds, globals) enters the draws."""
    code = ("import json, designkit; from designkit.simulation import simulate_interval;"
            "t = simulate_interval(500, 580, 3, designkit.SENSORS['paper'], designkit.Scene(contact_s=0.1), seed=11);"
            "print(json.dumps(t.temperature_c.tolist()))")
    env = dict(os.environ, PYTHONHASHSEED="12345")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    here = simulate_interval(500, 580, 3, paper_sensor, Scene(contact_s=0.1), seed=11)
    assert np.array_equal(np.array(json.loads(out.stdout)), here.temperature_c)


def test_truncating_long_trials_equals_simulating_short_ones(paper_sensor):
    """The engine's 'generate once, truncate' shortcut is an identity, not an approximation."""
    long = simulate_interval(20000, 20080, 50, paper_sensor, Scene(contact_s=4.0), seed=9)
    short = simulate_interval(20000, 20080, 50, paper_sensor, Scene(contact_s=1.5), seed=9)
    np.testing.assert_array_equal(long.temperature_c[:, : short.time_s.size], short.temperature_c)
    np.testing.assert_array_equal(long.effusivity, short.effusivity)


def test_fixed_conditions_depend_on_noise_and_delta_t_only_through_their_ratio(paper_sensor):
    a = simulate_interval(3000, 3080, 10, paper_sensor, Scene(contact_s=1, noise_c=0.05, sensor_temp_c=35), seed=1)
    b = simulate_interval(3000, 3080, 10, paper_sensor, Scene(contact_s=1, noise_c=0.025, sensor_temp_c=30), seed=1)
    # (x - Ts0) / dT is the same dataset
    np.testing.assert_allclose((a.temperature_c - 35) / 10, (b.temperature_c - 30) / 5, rtol=0, atol=1e-13)


def test_noise_is_gaussian_with_the_asked_sigma(paper_sensor):
    scene = Scene(contact_s=4.0, noise_c=0.05)
    t = simulate_trials(20000, paper_sensor, scene, n_trials=200, seed=5)
    resid = t.temperature_c - sensor_temperature(t.time_s, 20000, 35, 25, paper_sensor.effusivity, paper_sensor.tau_s)
    n = resid.size
    # chi-square interval for the variance at 1e-6 two-sided
    lo, hi = stats.chi2.ppf([5e-7, 1 - 5e-7], n - 1) / (n - 1)
    assert lo < resid.var(ddof=1) / 0.05**2 < hi
    assert abs(resid.mean()) < 5.3 * 0.05 / np.sqrt(n)
    assert stats.normaltest(resid.ravel()).pvalue > 1e-6


def test_effusivities_uniform_in_the_class(paper_sensor):
    t = simulate_interval(100, 180, 4000, paper_sensor, Scene(contact_s=0.01), seed=2)
    assert t.effusivity.min() >= 100 and t.effusivity.max() < 180
    assert stats.kstest((t.effusivity - 100) / 80, "uniform").pvalue > 1e-6


def test_varied_initial_conditions(paper_sensor):
    scene = Scene(contact_s=0.5, sensor_temp_c=32.5, sensor_temp_spread_c=2.5, ambient_temp_spread_c=1.0)
    t = simulate_interval(1000, 1080, 500, paper_sensor, scene, seed=4)
    assert 30 <= t.sensor_temp_c.min() and t.sensor_temp_c.max() < 35
    assert 24 <= t.ambient_temp_c.min() and t.ambient_temp_c.max() < 26
    assert t.sensor_temp_c.std() > 1.0
    # first sample: the sensor's own initial temperature plus noise
    assert np.abs(t.temperature_c[:, 0] - t.sensor_temp_c).max() < 6 * scene.noise_c


def test_extreme_scenes_stay_finite(paper_sensor):
    for scene, e in [
        (Scene(contact_s=1e-4), 20000.0),          # shorter than one sample
        (Scene(noise_c=0.0), np.inf),              # noise-free, perfect conductor
        (Scene(noise_c=10.0), 0.0),                # huge noise, perfect insulator
        (Scene(sensor_temp_c=25.0), 5000.0),       # no temperature difference
    ]:
        t = simulate_trials(e, paper_sensor, scene, n_trials=3, seed=0)
        assert np.all(np.isfinite(t.temperature_c)), scene
    quiet = simulate_trials(5000.0, paper_sensor, Scene(noise_c=0.0, contact_s=2), n_trials=2, seed=0)
    np.testing.assert_array_equal(quiet.temperature_c[0], quiet.temperature_c[1])


def test_draws_reject_bad_input():
    with pytest.raises(InputError):
        draw_trials(-1, 10, 5, 5, seed=0)
    with pytest.raises(InputError):
        draw_trials(10, 5, 5, 5, seed=0)
    with pytest.raises(InputError):
        draw_trials(1, 5, 0, 5, seed=0)
    with pytest.raises(InputError, match="seed"):
        draw_trials(1, 5, 5, 5, seed=None)
    with pytest.raises(InputError):
        simulate_interval(np.nan, 5, 5, None, Scene(), seed=0)
    d = draw_trials(1, 5, 3, 10, seed=0)
    with pytest.raises(InputError):
        d.truncate(11)
    assert render_trials(d.truncate(4), __import__("designkit").SENSORS["paper"], Scene()).temperature_c.shape == (3, 4)


# ------------------------------------------------------------------ the rig's scene
def test_correlated_noise_keeps_prefixes_and_its_correlation_length(paper_sensor):
    """A rig's noise wanders (Matern-3/2 over the scene's length); truncating a touch is still exact."""
    from designkit.rig import residual_correlation_s

    scene = Scene(contact_s=3.0, noise_c=0.03, noise_correlation_s=0.5)
    long = simulate_interval(20000, 20080, 60, paper_sensor, scene, seed=2)
    short = simulate_interval(20000, 20080, 60, paper_sensor, scene.replace(contact_s=1.0), seed=2)
    np.testing.assert_allclose(long.temperature_c[:, :short.time_s.size], short.temperature_c, rtol=0, atol=1e-11)
    white = simulate_interval(20000, 20080, 60, paper_sensor, scene.replace(noise_correlation_s=0.0), seed=2)
    noise = long.temperature_c - sensor_temperature(long.time_s, long.effusivity[:, None], 35, 25,
                                                    paper_sensor.effusivity, paper_sensor.tau_s)
    assert np.std(noise) == pytest.approx(0.03, rel=0.15)
    assert residual_correlation_s(list(noise), paper_sensor.sample_rate_hz) == pytest.approx(0.5, rel=0.2)
    lag1 = np.mean(noise[:, 1:] * noise[:, :-1]) / np.mean(noise ** 2)
    assert lag1 > 0.99 and not np.array_equal(white.temperature_c, long.temperature_c)


def test_the_recorders_window_starts_at_its_onset(paper_sensor):
    """With onset_s the samples are those from the onset to contact_s: the tail of the touch from the first
    heat flow (the same curve, read later)."""
    full = simulate_interval(5000, 5080, 5, paper_sensor, Scene(contact_s=1.5, noise_c=0.0), seed=1)
    late = simulate_interval(5000, 5080, 5, paper_sensor, Scene(contact_s=1.5, noise_c=0.0, onset_s=0.5), seed=1)
    assert late.time_s[0] == 0.5 and late.time_s.size == full.time_s.size - 100
    np.testing.assert_allclose(late.temperature_c, full.temperature_c[:, 100:], rtol=0, atol=1e-12)
    before = Scene(contact_s=0.2, onset_s=0.5)        # contact ends before the onset: one sample, at the onset
    assert before.window_s() == 0.0 and "onset_s" in before.to_dict() and "onset_s" not in Scene().to_dict()


def test_a_contact_ending_before_the_onset_is_one_sample_at_the_onset(paper_sensor):
    t = simulate_interval(5000, 5080, 4, paper_sensor, Scene(contact_s=0.3, onset_s=0.5), seed=1)
    assert t.time_s.tolist() == [0.5] and t.temperature_c.shape == (4, 1)
