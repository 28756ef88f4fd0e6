"""The ideal observer against independent references: mpmath, two-Gaussian closed forms,
its own Monte Carlo, and the planning figure in DOMAIN.md."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import optimize, stats

from designkit import Scene
from designkit.recognition.ideal import class_survival, ideal_pair, ideal_scores, ndtr, projection_noise
from designkit.models.semi_infinite import object_weight, response_shape

E_S = 892.0
mpmath.mp.dps = 30


def mp_survival(t, a, b, s):
    """The class survival by mpmath's quadrature at 20 digits: the 60 cases below round to the same doubles as at 30
    digits (half the time; they differ from the library's by up to 3e-12)."""
    with mpmath.workdps(20):
        t, a, b, s = (mpmath.mpf(float(v)) for v in (t, a, b, s))
        w = lambda e: e / (E_S + e)  # noqa: E731
        et = E_S * t / (1 - t) if t < 1 else b
        pts = sorted({a, b, *(p for p in (et - 20 * s * (E_S + et) ** 2 / E_S, et,
                                          et + 20 * s * (E_S + et) ** 2 / E_S) if a < p < b)})
        return mpmath.quad(lambda e: mpmath.ncdf((w(e) - t) / s), pts) / (b - a)


def test_class_survival_matches_mpmath():
    rng = np.random.default_rng(3)
    for _ in range(60):
        a = 10 ** rng.uniform(-1, 4.6)
        b = a + 10 ** rng.uniform(-1, 4.5)
        s = 10 ** rng.uniform(-9, 0)
        t = rng.uniform(object_weight(E_S, a) - 3 * s, object_weight(E_S, b) + 3 * s)
        ours = float(class_survival(t, a, b, E_S, s))
        assert abs(ours - float(mp_survival(t, a, b, s))) < 1e-10, (a, b, s, t)


def test_noise_free_limit_is_the_uniform_law():
    # s = 0: P(w(e) > t) = (b - e(t)) / (b - a) exactly
    a, b = 1000.0, 3000.0
    t = object_weight(E_S, 2500.0)
    assert float(class_survival(t, a, b, E_S, 0.0)) == pytest.approx(0.25, abs=1e-12)


def test_narrow_classes_reduce_to_two_gaussians():
    """Point-like classes: Bayes accuracy Phi(d / 2s); best F1 by scipy on the two-Gaussian ROC."""
    e1, e2, width, s = 2000.0, 2600.0, 1e-7, 0.01
    w1, w2 = object_weight(E_S, e1), object_weight(E_S, e2)
    f1, acc = ideal_scores(e1, e1 + width, e2, e2 + width, E_S, s)
    assert float(acc) == pytest.approx(stats.norm.cdf((w2 - w1) / (2 * s)), abs=1e-8)

    def neg_f1(t):
        tpr, fpr = stats.norm.sf((t - w2) / s), stats.norm.sf((t - w1) / s)
        return -2 * tpr / (1 + tpr + fpr)

    best = -optimize.minimize_scalar(neg_f1, bounds=(w1 - 5 * s, w2 + 5 * s), method="bounded",
                                     options={"xatol": 1e-12}).fun
    assert float(f1) == pytest.approx(best, abs=1e-8)


def test_limits():
    f1, acc = ideal_scores(100, 180, 40000, 40080, E_S, 0.0)
    assert (float(f1), float(acc)) == (1.0, 1.0)
    f1, acc = ideal_scores(100, 180, 40000, 40080, E_S, math.inf)
    assert float(acc) == 0.5 and float(f1) == pytest.approx(2 / 3)
    # no signal at all: no sample after contact or no temperature difference
    from designkit import SENSORS

    assert projection_noise(SENSORS["paper"], Scene(contact_s=1e-3)) == math.inf
    assert projection_noise(SENSORS["paper"], Scene(sensor_temp_c=25.0)) == math.inf
    assert projection_noise(SENSORS["paper"], Scene(noise_c=0.0)) == 0.0


def test_projection_noise_formula(paper_sensor):
    scene = Scene.from_delta_t(contact_s=2.0, noise_c=0.05, delta_t_c=10.0)
    g = response_shape(paper_sensor.times_s(2.0), paper_sensor.tau_s)
    assert projection_noise(paper_sensor, scene) == pytest.approx(0.005 / np.linalg.norm(g), rel=1e-14)


def test_domain_planning_figure(paper_sensor):
    """DOMAIN.md: ideal accuracy 0.87 at 1 s, ~1.0 at 2 s for 35,000 vs 20,000 (sigma 0.05, dT 10)."""
    at1 = ideal_pair((35000, 35080), (20000, 20080), paper_sensor, Scene(contact_s=1.0))
    at2 = ideal_pair((35000, 35080), (20000, 20080), paper_sensor, Scene(contact_s=2.0))
    assert at1.accuracy == pytest.approx(0.87, abs=0.01)
    assert at2.accuracy > 0.999


@pytest.mark.parametrize("contact", [0.75, 1.0, 1.5])
def test_closed_form_agrees_with_monte_carlo_on_the_full_likelihood(paper_sensor, contact):
    """Two independent routes: the 1-D projection vs simulated touches scored by the full likelihood."""
    a, b = (20000, 20080), (35000, 35080)
    closed = ideal_pair(a, b, paper_sensor, Scene(contact_s=contact))
    # a spread of 1e-9 degC forces the Monte Carlo path on an essentially fixed scene
    mc = ideal_pair(a, b, paper_sensor, Scene(contact_s=contact, sensor_temp_spread_c=1e-9), n_mc=3000, seed=1)
    assert mc.method == "monte-carlo" and closed.method == "closed-form"
    assert closed.accuracy == pytest.approx(mc.accuracy, abs=4 * mc.accuracy_standard_error + 1e-3)
    assert closed.f1 == pytest.approx(mc.f1, abs=4 * mc.standard_error + 0.01)


@settings(max_examples=40, deadline=None)
@given(e=st.floats(10, 30000), gap=st.floats(1, 5000), c1=st.floats(0.2, 5), dc=st.floats(0.05, 5),
       ratio=st.floats(1e-4, 0.05))
def test_more_contact_or_less_noise_never_hurts(paper_sensor, e, gap, c1, dc, ratio):
    low, high = (e, e + 80), (e + 80 + gap, e + 160 + gap)
    s = lambda c, r: projection_noise(paper_sensor, Scene.from_delta_t(contact_s=c, noise_c=r, delta_t_c=1.0))  # noqa: E731
    base_f1, base_acc = ideal_scores(*low, *high, E_S, s(c1, ratio))
    longer_f1, longer_acc = ideal_scores(*low, *high, E_S, s(c1 + dc, ratio))
    quieter_f1, quieter_acc = ideal_scores(*low, *high, E_S, s(c1, ratio / 2))
    assert longer_acc >= base_acc - 1e-9 and quieter_acc >= base_acc - 1e-9
    assert longer_f1 >= base_f1 - 1e-9 and quieter_f1 >= base_f1 - 1e-9


def test_vectorized_equals_scalar():
    lows = np.array([100.0, 5000.0, 30000.0])
    s = np.array([1e-3, 5e-3, 1e-4])
    f1, acc = ideal_scores(lows, lows + 80, lows + 400, lows + 480, E_S, s)
    for i in range(3):
        f, a = ideal_scores(lows[i], lows[i] + 80, lows[i] + 400, lows[i] + 480, E_S, s[i])
        assert f1[i] == f and acc[i] == a


def test_normal_cdf_of_the_closed_form_bounds_against_mpmath():
    """The normal CDF of the closed form (Hermite pieces in Horner form, numpy only)."""
    import mpmath

    rng = np.random.default_rng(7)
    z = np.concatenate([rng.normal(0.0, 3.0, 4000), [-9.0, 9.0, -9.5, 12.0, 0.0, -1e-300, 8.999999]])
    got = ndtr(z.reshape(-1, 1)).ravel()
    ref = np.array([float(mpmath.ncdf(mpmath.mpf(float(v)))) for v in z])
    assert np.max(np.abs(got - ref)) < 1e-13
    assert np.all(np.diff(ndtr(np.linspace(-9.0, 9.0, 20001))) >= -2.3e-16)  # monotone to an ulp of 1
