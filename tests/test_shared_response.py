"""Touches read from a scene's panels of a few effusivities (designkit.models.shared) and the ramp's sum as a convolution.

The interpolated readings are checked against the model read directly at every touch's effusivity
(the independent reference: no interpolation), within the tolerance the simulation asks; the draws
(seeds, noise) are the same as before, so the same seed still gives the same touches bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from designkit import Scene
from designkit.models import get_model
from designkit.models.ramp import ForceRamp
from designkit.models.shared import SceneResponse, class_readings, start_level
from designkit.sensor import Sensor
from designkit.simulation import draw_trials, render_trials, response_tolerance

SENSOR = Sensor(1980.74, 8.8e-9, depth_m=8e-5, name="rig")
LAYERED = get_model("layered", film_thickness_m=2.2e-4, backing_effusivity_ws05_m2k=5000.0, conductance_w_m2k=18000.0,
                    lag_s=0.8, smoothing_window=99, smoothing_order=3)
TP = np.arange(-10, 40) * 0.02
RAMP = ForceRamp.from_force_profile(LAYERED, TP, np.clip(0.1 + 0.9 * (TP + 0.2) / 0.9, 0, 1), 0.2)


@pytest.mark.parametrize("model", [LAYERED, RAMP], ids=["layered", "force-ramp"])
@pytest.mark.parametrize("e_range", [(331.0, 506.0), (2252.0, 2750.0), (20.0, 30000.0)])
def test_interpolated_class_readings_agree_with_direct_evaluation(model, e_range):
    t = np.arange(201) / 200.0
    e = np.random.default_rng(7).uniform(*e_range, 60)
    tol = 1e-6   # what a simulation asks at 0.5 % noise and a few seconds (response_tolerance)
    got = class_readings(model, t, e, SENSOR, tolerance=tol)
    want = model.response(t, e, SENSOR)
    assert np.max(np.abs(got - want)) <= tol
    scene = SceneResponse(model, t, SENSOR, tol)
    w = e / (SENSOR.effusivity + e)
    again = np.clip(scene.readings(e, start_level(w.min(), w.max())), 0.0, 1.0)
    np.testing.assert_array_equal(again, got)   # the cached scene's panels and a fresh one's: the same bits
    assert all(p.error <= tol for p in scene.panels)
    if e_range[1] / e_range[0] < 2:   # a class of the sweep's grid: one or two panels of 5 readings, maybe halved once
        assert scene.model_readings <= 20


def test_a_scene_reads_each_panel_once_and_a_class_reads_the_same_whatever_came_before():
    """Classes of one scene (neighbouring intervals, repeats) share panels; a class's readings do not depend on
    which classes were read first (a sweep's split or order changes no bit)."""
    t = np.arange(301) / 200.0
    edges = np.linspace(331.0, 506.0, 11)
    scene = SceneResponse(RAMP, t, SENSOR, 1e-6)
    first = {}
    for k in range(10):
        for seed in (1, 2):
            e = np.random.default_rng([seed, k]).uniform(edges[k], edges[k + 1], 40)
            w = e / (SENSOR.effusivity + e)
            first[k, seed] = scene.readings(e, start_level(w.min(), w.max()))
            assert np.max(np.abs(first[k, seed] - RAMP.response(t, e, SENSOR))) <= 1e-6
    assert scene.model_readings < 20 * 5 / 2        # fewer than one panel per class and repeat
    fresh = SceneResponse(RAMP, t, SENSOR, 1e-6)
    for k in (7, 2):                                # another order, another process's cache
        e = np.random.default_rng([2, k]).uniform(edges[k], edges[k + 1], 40)
        w = e / (SENSOR.effusivity + e)
        np.testing.assert_array_equal(fresh.readings(e, start_level(w.min(), w.max())), first[k, 2])


def test_render_trials_is_within_the_asked_tolerance_and_keeps_the_draws():
    scene = Scene(contact_s=1.5, noise_c=0.05)
    m = SENSOR.times_s(scene.contact_s).size
    draws = draw_trials(331.0, 506.0, 50, m, [3, 1])
    a = render_trials(draws, SENSOR, scene, RAMP)
    again = render_trials(draw_trials(331.0, 506.0, 50, m, [3, 1]), SENSOR, scene, RAMP)
    other = render_trials(draw_trials(331.0, 506.0, 50, m, [3, 2]), SENSOR, scene, RAMP)
    np.testing.assert_array_equal(a.temperature_c, again.temperature_c)          # seeds honoured, bit for bit
    assert not np.array_equal(a.temperature_c, other.temperature_c)
    dT = scene.ambient_temp_c - scene.sensor_temp_c
    u = (a.temperature_c - scene.sensor_temp_c - scene.noise_c * draws.noise) / dT
    direct = RAMP.response(a.time_s, draws.effusivity, SENSOR)
    assert np.max(np.abs(u - direct)) <= response_tolerance(scene.noise_ratio, m) + 1e-12


def test_few_distinct_objects_or_a_per_touch_diffusivity_are_read_directly():
    t = np.arange(101) / 200.0
    e = np.array([400.0, 400.0, 2500.0, 400.0])
    np.testing.assert_array_equal(class_readings(LAYERED, t, e, SENSOR, tolerance=1e-6),
                                  LAYERED.response(t, np.unique(e), SENSOR)[[0, 0, 1, 0]])
    semi = get_model()
    np.testing.assert_array_equal(class_readings(semi, t, e, SENSOR, tolerance=1e-6), semi.response(t, e, SENSOR))


def test_a_ramp_off_the_sample_grid_is_the_sum_of_shifted_step_responses():
    """Shares starting between samples (phase 0.4 of a sample) on a uniform grid: the convolution's phases. The
    convolution is an FFT's: exact to rounding relative to the reading's scale (1e-15 of ``|Ts0 - Ta|``), not
    relative to each tiny reading before the slow shares' heat arrives."""
    base = get_model("contact", conductance_w_m2k=2500.0)
    dt = 1 / 200.0
    ramp = ForceRamp(base, (0.0, 0.012, 0.05, 0.2), (0.1, 0.3, 0.7, 1.0))
    t = np.arange(-5, 200) * dt
    want = np.zeros((2, t.size))
    for tj, da in zip(ramp.ramp_time_s, np.diff(ramp.ramp_area, prepend=0.0)):
        lag = t - tj
        pos = lag > 0
        want[:, pos] += da * base.response(lag[pos], [400.0, 9000.0], SENSOR)
    np.testing.assert_allclose(ramp.response(t, [400.0, 9000.0], SENSOR), want, rtol=1e-13, atol=1e-15)


def test_the_layered_transform_is_its_object_independent_parts_divided_per_object():
    from designkit.models.layered import laplace_parts, laplace_reading, talbot_points

    p, _ = talbot_points(np.array([0.1, 1.0]))
    kw = LAYERED._laplace_kwargs(SENSOR)
    A, B, C = laplace_parts(p, **kw)
    U = laplace_reading(p, np.array([400.0, np.inf]), **kw)
    np.testing.assert_allclose(U[0], C / (A + B / 400.0), rtol=1e-14)
    np.testing.assert_allclose(U[1], C / A, rtol=1e-14)


def test_the_same_seed_gives_the_same_ramp_touches_in_another_process():
    """No alignment-, thread- or process-dependent sum enters the interpolated readings (tables stay bit for bit)."""
    import json
    import os
    import subprocess
    import sys

    code = ("import json, numpy as np; exec(open('tests/test_shared_response.py').read().split('@pytest')[0]);"
            "from designkit.simulation import draw_trials, render_trials; from designkit import Scene;"
            "d = draw_trials(331.0, 506.0, 30, 161, [4, 2]);"
            "print(json.dumps(render_trials(d, SENSOR, Scene(contact_s=0.8), RAMP).temperature_c.tolist()))")
    env = dict(os.environ, PYTHONHASHSEED="321", OPENBLAS_NUM_THREADS="1")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True,
                         cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    here = render_trials(draw_trials(331.0, 506.0, 30, 161, [4, 2]), SENSOR, Scene(contact_s=0.8), RAMP)
    assert np.array_equal(np.array(json.loads(out.stdout)), here.temperature_c)


def test_a_class_s_touches_read_every_touch_ramp_from_panels_of_one_step_response():
    """Touches each pressing as one of a calibrated sensor's touch ramps (a rig table's touches) are read from the
    scene's panels of all touch ramps at once: a panel node reads the base model once (one step response shared by
    every ramp, the Duhamel sums as convolutions), each touch interpolates its own ramp's; within the tolerance of
    the touches read directly, the same bits whatever was read before, and render_trials reads them so."""
    from designkit.models import shared
    from designkit.models.layered import Layered

    reads = []

    class Counting(Layered):
        def response(self, time_s, e_object, sensor, **kw):
            reads.append(np.size(e_object))
            return super().response(time_s, e_object, sensor, **kw)

    base = Counting(film_thickness_m=2.2e-4, backing_effusivity_ws05_m2k=5000.0, conductance_w_m2k=18000.0,
                    lag_s=0.8, smoothing_window=99, smoothing_order=3)
    ramp = ForceRamp.from_force_profile(base, TP, np.clip(0.1 + 0.9 * (TP + 0.2) / 0.9, 0, 1), 0.2,
                                        touch_force_rel=[np.clip(0.1 + 0.9 * (TP + d) / w, 0, 1) for d, w in
                                                         ((0.1, 0.5), (0.2, 0.9), (-0.1, 0.7), (0.0, 1.1))])
    t = 0.3 + np.arange(160) / SENSOR.sample_rate_hz
    tol = 1e-6
    e = np.random.default_rng(5).uniform(331.0, 506.0, 40)
    touch = np.random.default_rng(6).integers(0, 4, e.size)
    shared._cached_touch_scene.cache_clear()
    got = class_readings(ramp, t, e, SENSOR, tolerance=tol, touch=touch)
    scene = shared.scene_response(ramp, t, SENSOR, tolerance=tol, touches=True)
    assert scene.panels and reads == [5] * len(scene._panels)       # one base reading per panel, not one per ramp
    direct = ramp.touch_readings(t, e, touch, SENSOR)
    assert np.max(np.abs(got - direct)) <= tol
    for k in range(e.size):                                         # each touch as its own ramp reads it
        one, delay = ramp.touch(touch[k])
        assert np.max(np.abs(got[k] - one.response(t - delay, e[k:k + 1], SENSOR)[0])) <= tol
    shared._cached_touch_scene.cache_clear()
    class_readings(ramp, t, np.random.default_rng(7).uniform(20.0, 30000.0, 40), SENSOR, tolerance=tol,
                   touch=touch)                                     # other panels read first
    np.testing.assert_array_equal(class_readings(ramp, t, e, SENSOR, tolerance=tol, touch=touch), got)
    scene = Scene(contact_s=1.1, noise_c=0.0, onset_s=0.3)
    draws = draw_trials(331.0, 506.0, 40, t.size, [1])
    temps = render_trials(draws, SENSOR, scene, ramp, None, touch).temperature_c
    u = class_readings(ramp, t, draws.effusivity, SENSOR, touch=touch,
                       tolerance=response_tolerance(scene.noise_ratio, t.size))
    np.testing.assert_array_equal(temps, scene.sensor_temp_c + (scene.ambient_temp_c - scene.sensor_temp_c) * u)
