"""Two-sensor recognition: the heated sensor and the passive thermistor at room temperature (issue 14)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.special import erfc

from designkit import SENSORS, InputError, Scene
from designkit.objects import object_class
from designkit.recognition.features import feature_matrix
from designkit.recognition.two_sensor import (TouchClass, simulate_two_sensor, two_sensor_features,
                                              two_sensor_pair_f1)
from designkit.simulation import simulate_class

PAPER = SENSORS["paper"]
SCENE = Scene(contact_s=2.0, noise_c=0.05, sensor_temp_c=29.5, ambient_temp_c=22.5)


def _closed_form(t, e_o, ts0, to):
    """Paper eqs. 1-2 written out: Ts0 + (To - Ts0) e_o / (e_s + e_o) erfc(sqrt(tau / t))."""
    g = np.zeros_like(t)
    g[t > 0] = erfc(np.sqrt(PAPER.tau_s / t[t > 0]))
    return ts0 + (to - ts0) * e_o / (PAPER.effusivity + e_o) * g


def test_both_channels_follow_the_paper_model_from_their_own_initial_temperatures():
    quiet = Scene(contact_s=2.0, noise_c=0.0, sensor_temp_c=29.5, ambient_temp_c=22.5)
    tr = simulate_two_sensor(TouchClass(object_class(400, width=1e-9), 15.0), 3, PAPER, quiet, seed=0)
    e = tr.effusivity[:, None]
    assert np.allclose(tr.heated_c, _closed_form(tr.time_s, e, 29.5, 15.0), atol=1e-12, rtol=0)
    assert np.allclose(tr.passive_c, _closed_form(tr.time_s, e, 22.5, 15.0), atol=1e-12, rtol=0)
    room = simulate_two_sensor(TouchClass(object_class(400)), 3, PAPER, quiet, seed=0)
    assert np.all(room.passive_c == 22.5) and room.object_temp_c == 22.5   # nothing to see at room temperature


def test_the_heated_channel_is_the_one_sensor_simulation_and_the_passive_noise_is_its_own():
    obj = object_class(20000)
    two = simulate_two_sensor(TouchClass(obj, 22.5), 50, PAPER, SCENE, seed=[4, 0])
    one = simulate_class(obj, 50, PAPER, SCENE, seed=[4, 0])
    assert np.array_equal(two.heated_c, one.temperature_c)
    noise_h, noise_p = two.heated_c - two.heated_c.mean(axis=0), two.passive_c - 22.5
    assert abs(np.corrcoef(noise_h.ravel(), noise_p.ravel())[0, 1]) < 0.01
    assert np.std(noise_p) == pytest.approx(0.05, rel=0.02)


def test_the_second_sensor_resolves_what_one_cannot_and_adds_nothing_to_an_identical_pair():
    metal = TouchClass(object_class(17530, width=10), 22.5, "metal")
    cold_wood = TouchClass(object_class(400, width=10), 7.985, "cold wood")   # the heated sensor sees metal's amplitude
    r = two_sensor_pair_f1(metal, cold_wood, PAPER, SCENE, trials=60, seed=1)
    assert r.one_sensor.f1 < 0.8 and r.two_sensors.f1 > 0.97 and r.resolves
    d = r.to_dict()
    assert d["second_sensor_resolves"] and d["classes"] == ["metal", "cold wood"]
    same = two_sensor_pair_f1(metal, TouchClass(object_class(17530, width=10), 22.5), PAPER, SCENE, trials=60)
    assert same.two_sensors.f1 < 0.8 and not same.resolves


def test_features_and_bad_inputs():
    x = two_sensor_features(np.zeros((2, 50)), np.ones((2, 50)), 200.0)
    assert np.array_equal(x[:, :100], feature_matrix(np.zeros((2, 50)), 200.0))
    with pytest.raises(InputError, match="same shape"):
        two_sensor_features(np.zeros((2, 50)), np.zeros((2, 49)), 200.0)
    spread = Scene(contact_s=1.0, sensor_temp_spread_c=1.0)
    with pytest.raises(InputError, match="fixed initial temperatures"):
        simulate_two_sensor(TouchClass(object_class(400)), 5, PAPER, spread, seed=0)
    with pytest.raises(InputError, match="effusivity alone"):
        simulate_two_sensor(TouchClass(object_class(400, diffusivity_m2_s=1e-7)), 5, PAPER, SCENE, seed=0,
                            model="slab:thickness_m=0.003")


def test_cli_f1_two_sensor_says_whether_the_passive_thermistor_resolves_the_pair(cli):
    args = ("f1", "--e1", "17530", "--e2", "400", "--width", "10", "--delta-t", "7", "--ambient", "22.5",
            "--object-temp2", "7.985", "--trials", "60", "--seed", "1")
    res = cli(*args, "--two-sensor", "--json")
    assert res.exit_code == 0, res.output
    d = json.loads(res.stdout)
    assert d["second_sensor_resolves"] and not d["one_sensor_distinguishes"]
    assert d["passive_sensor"]["initial_temp_c"] == 22.5
    text = cli(*args, "--two-sensor")
    assert "the second sensor resolves this pair" in text.stdout
    bad = cli(*args)
    assert bad.exit_code == 2 and "go with --two-sensor" in bad.output


def test_real_recordings_the_passive_channel_as_second_sensor(robot_data_dir):
    """Train and test on real touches (3 folds x 3 shuffles): the passive channel makes cold wood plain."""
    from designkit.recognition.svm import f1_from_features
    from designkit_lab.reproduce.robot import load_real

    touches = load_real(robot_data_dir)
    assert touches.object_c.shape == touches.sensor_c.shape and np.isfinite(touches.object_c).all()

    def f1(pair, two):
        feats = [two_sensor_features(touches.sensor_c[touches.material == m], touches.object_c[touches.material == m],
                                     200.0) if two else feature_matrix(touches.sensor_c[touches.material == m], 200.0)
                 for m in pair]
        return np.mean([f1_from_features(*feats, seed=[0, r]).f1 for r in range(3)])

    for pair in (("wood", "cold_wood"), ("metal", "cold_wood")):
        assert f1(pair, True) >= 0.95 and f1(pair, True) >= f1(pair, False) - 0.01, pair
