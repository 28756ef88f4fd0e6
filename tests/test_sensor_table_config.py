"""What a calibrated sensor's table holds (issues 34 and 35): a contact grid on the sensor's own time scale and the
classifier's overlapping-class fits by libsvm itself. Fast: no table is built here (benchmarks/bench_sensor_table.py
builds one and measures its coverage)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from designkit.sensor import load_sensor


@pytest.fixture(scope="module")
def rig(data_dir_path="tests/data/rig_sensor.yaml"):
    from pathlib import Path

    return load_sensor(str(Path(__file__).parent / "data" / "rig_sensor.yaml"))


def test_the_contact_grid_runs_on_the_rigs_time_scale_from_settled_to_capped(rig):
    from designkit.rig import model_start_s
    from designkit.sweep.for_sensor import CONTACT_RATIO, contact_grid, time_scale_s

    scale = time_scale_s(rig)
    assert scale == pytest.approx(0.7525)  # the ramp's rise (the noise's correlation, 0.68 s, is shorter)
    onset, model = contact_grid(rig)
    # one time scale to eight (not 0.1 s: nothing separates before the touch has settled), at most 1.35 apart
    assert onset[0] == pytest.approx(scale, abs=1e-3) and onset[-1] == pytest.approx(8 * scale, abs=1e-3)
    assert onset.size == 8 and np.all(onset[1:] / onset[:-1] <= CONTACT_RATIO + 1e-3)
    assert model == pytest.approx(onset - model_start_s(rig))  # stored as the model counts (0.643 s later)


def test_a_sensor_whose_scale_is_long_is_capped_at_the_exact_routes_longest_contact(rig):
    from designkit.rig import model_start_s
    from designkit.sweep.for_sensor import MAX_CONTACT_S, contact_grid

    cond = {**rig.conditions, "contact_ramp": {"rise_s": 3.0, "to_share": 0.9}}
    _, model = contact_grid(rig.replace(conditions=cond))
    assert model[-1] == pytest.approx(MAX_CONTACT_S, abs=1e-3) and model[0] == pytest.approx(3.0 - model_start_s(rig))


def test_the_table_config_is_the_rigs_one_noise_its_span_and_two_repeats(rig):
    from designkit.sweep.for_sensor import effusivity_span, rig_noise_ratio, sensor_sweep_config

    cfg = sensor_sweep_config(str(rig.source) if getattr(rig, "source", None) else "tests/data/rig_sensor.yaml",
                              span=effusivity_span(material_set="paper12"))
    assert cfg.noise_ratio == (pytest.approx(0.030596403240682815 / 6.9353),) == (rig_noise_ratio(rig),)
    assert (cfg.e_min, cfg.intervals, cfg.max_repeats, len(cfg.contact_s), cfg.rig_scene) == (80.0, 460, 2, 8, True)


def test_the_tables_touches_are_read_in_the_recorders_window_as_the_exact_routes():
    """A sensor table's touch at model contact c is read from the rig's onset to c, the window the exact route's
    touches have (simulate_class), not c seconds from the onset on (0.64 s more for the rig: answers that early)."""
    from designkit.simulation import window_times_s
    from designkit.sweep.for_sensor import effusivity_span, sensor_sweep_config
    from designkit.sweep.scorer import PairScorer

    cfg = sensor_sweep_config("tests/data/rig_sensor.yaml", span=effusivity_span(e_range=(240.0, 400.0)))
    sensor = cfg.resolved_sensor()
    scene = cfg.scene((0,), cfg.contact_s[0])
    assert scene.onset_s == pytest.approx(0.6427, abs=1e-4)
    n = PairScorer(cfg, sensor, scene).n_samples
    assert n == window_times_s(sensor, scene).size == round((cfg.contact_s[0] - scene.onset_s) * 200) + 1
    assert PairScorer(cfg, sensor, scene).features(0, 0).shape == (cfg.trials, 2 * n)


def test_the_tables_touches_press_as_the_calibration_touches_did_as_the_exact_routes():
    """Each of a sensor table's touches plays one calibration touch's press (a force ramp's ``touch_ramps``), from
    the stream simulate_class picks from: the same touches as the exact route's for the same seed."""
    from designkit.objects import ObjectClass
    from designkit.recognition.features import feature_matrix
    from designkit.simulation import simulate_class
    from designkit.sweep.for_sensor import effusivity_span, sensor_sweep_config
    from designkit.sweep.scorer import PairScorer

    cfg = sensor_sweep_config("tests/data/rig_sensor.yaml", span=effusivity_span(e_range=(240.0, 400.0)),
                              trials=12)
    sensor = cfg.resolved_sensor()
    assert len(cfg.model.touch_ramps) == 24
    scene = cfg.scene((0,), cfg.contact_s[0])
    k = 1
    ref = simulate_class(ObjectClass("k", (cfg.edges[k], cfg.edges[k + 1])), cfg.trials, sensor, scene,
                         [cfg.seed, k, 0], cfg.model)
    ours = PairScorer(dataclasses.replace(cfg, solver="sklearn"), sensor, scene).features(k, 0)
    np.testing.assert_allclose(ours, feature_matrix(ref.temperature_c, sensor.sample_rate_hz), rtol=1e-12, atol=1e-12)
