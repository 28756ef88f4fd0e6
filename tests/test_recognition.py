"""The paper's recognition pipeline: features, SVM F1, invariances, and the ideal bound."""

from __future__ import annotations

import math

import numpy as np
import pytest

from designkit import InputError, Scene
from designkit.recognition.features import feature_matrix, local_slope
from designkit.recognition.ideal import ideal_pair
from designkit.recognition.svm import cross_validated_f1, f1_standard_error, interval_pair_f1


def test_slope_is_exact_on_quadratics_including_edges():
    fs = 200.0
    t = np.arange(300) / fs
    x = 3.0 - 2.0 * t + 0.7 * t**2
    np.testing.assert_allclose(local_slope(x, fs), -2.0 + 1.4 * t, rtol=0, atol=1e-9)


@pytest.mark.parametrize("m", [3, 4, 5, 50, 51, 52, 400, 2000])
def test_slope_is_scipys_savitzky_golay_derivative_to_rounding(m):
    """The cumulative-sum form (engine version 2) is the estimator scipy's savgol_filter(deriv=1,
    mode="interp") computes, window cut to the samples available, edges included; only its rounding
    differs (about 1e-11 of the slope's scale at 2,000 samples)."""
    from scipy.signal import savgol_filter

    rng = np.random.default_rng(m)
    x = 30.0 + np.cumsum(rng.normal(0, 0.05, (5, m)), axis=1) + rng.normal(0, 0.05, (5, m))
    win = max(3, min(51, m if m % 2 else m - 1))
    ref = savgol_filter(x, win, 2, deriv=1, delta=1 / 200.0, axis=-1, mode="interp")
    got = local_slope(x, 200.0)
    assert np.abs(got - ref).max() <= 1e-9 * np.abs(ref).max()
    np.testing.assert_array_equal(feature_matrix(x, 200.0), np.hstack([x, got]))
    np.testing.assert_array_equal(local_slope(x[0], 200.0), got[0])  # one touch: the same numbers


def test_slope_noise_matches_least_squares_theory():
    """Savitzky-Golay slope of white noise: Var = sigma^2 / (h^2 sum k^2), k = -m..m."""
    fs, sigma, n = 200.0, 0.05, 4000
    noise = np.random.default_rng(0).normal(0, sigma, (n, 201))
    slope = local_slope(noise, fs, window_s=0.25)[:, 100]  # interior sample, window 51
    m = 25
    theory = sigma / ((1 / fs) * math.sqrt(m * (m + 1) * (2 * m + 1) / 3))
    assert slope.std() == pytest.approx(theory, rel=0.05)
    gradient = np.gradient(noise, 1 / fs, axis=1)[:, 100]
    assert gradient.std() > 30 * slope.std()  # why the two-point difference drowns


def test_feature_matrix_shape():
    x = np.zeros((4, 401))
    assert feature_matrix(x, 200.0).shape == (4, 802)
    assert feature_matrix(np.zeros((4, 1)), 200.0).shape == (4, 2)


def test_gram_matrix_svm_equals_scikit_learns_linear_kernel_svm(paper_sensor):
    from sklearn.model_selection import StratifiedKFold, cross_val_predict
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler
    from sklearn.svm import SVC

    from designkit.recognition.svm import make_classifier
    from designkit.simulation import simulate_interval

    for (a, b), contact in [((35000, 20000), 1.0), ((500, 560), 2.0), ((1000, 1080), 4.0)]:
        lo = simulate_interval(a, a + 80, 60, paper_sensor, Scene(contact_s=contact), seed=[1, 0]).temperature_c
        hi = simulate_interval(b, b + 80, 60, paper_sensor, Scene(contact_s=contact), seed=[1, 1]).temperature_c
        X = feature_matrix(np.vstack([lo, hi]), 200.0)
        y = np.r_[np.zeros(60, int), np.ones(60, int)]
        cv = StratifiedKFold(3, shuffle=True, random_state=0)
        ref = cross_val_predict(make_pipeline(StandardScaler(), SVC(kernel="linear")), X, y, cv=cv)
        ours = cross_val_predict(make_classifier(), X, y, cv=cv)
        np.testing.assert_array_equal(ours, ref)


def test_far_pair_is_perfectly_separated_and_order_does_not_matter(paper_sensor):
    scene = Scene(contact_s=1.0)
    a = interval_pair_f1((500, 580), (20000, 20080), paper_sensor, scene, trials=30)
    b = interval_pair_f1((20000, 20080), (500, 580), paper_sensor, scene, trials=30)
    assert a.f1 == 1.0 and a.fold_f1 == (1.0, 1.0, 1.0)
    assert a == b


def test_noise_only_gives_chance(paper_sensor):
    # no temperature difference: the classes differ in nothing
    scene = Scene(contact_s=0.5, sensor_temp_c=25.0)
    r = interval_pair_f1((500, 580), (20000, 20080), paper_sensor, scene, trials=60, seed=1)
    assert abs(r.accuracy - 0.5) < 0.15


@pytest.mark.parametrize("pair,contact", [(((35000, 35080), (20000, 20080)), 1.0),
                                          (((1000, 1080), (1080, 1160)), 4.0)])
def test_f1_depends_on_noise_and_delta_t_only_through_their_ratio(paper_sensor, pair, contact):
    """DOMAIN.md: with standardized features, F1(sigma, dT) = F1(sigma/dT, 1)."""
    results = [
        interval_pair_f1(*pair, paper_sensor, Scene.from_delta_t(contact_s=contact, noise_c=s, delta_t_c=d), seed=3)
        for s, d in [(0.05, 10.0), (0.025, 5.0), (0.1, 20.0)]
    ]
    assert results[0].f1 == pytest.approx(results[1].f1, abs=1e-12)
    assert results[0].f1 == pytest.approx(results[2].f1, abs=1e-12)
    assert results[0].fold_f1 == pytest.approx(results[1].fold_f1, abs=1e-12)


def test_svm_never_beats_the_ideal_observer(paper_sensor):
    """Across easy, threshold and hopeless pairs; margin = 3 Monte Carlo standard errors."""
    cases = [
        ((35000, 35080), (20000, 20080), Scene(contact_s=1.0)),
        ((35000, 35080), (20000, 20080), Scene(contact_s=0.5)),
        ((1000, 1080), (1160, 1240), Scene(contact_s=2.0)),
        ((300, 380), (380, 460), Scene(contact_s=3.0, noise_c=0.1)),
        ((8000, 8080), (10000, 10080), Scene(contact_s=1.5)),
    ]
    for a, b, scene in cases:
        ideal = ideal_pair(a, b, paper_sensor, scene)
        svms = [interval_pair_f1(a, b, paper_sensor, scene, seed=k).f1 for k in range(3)]
        mean = float(np.mean(svms))
        se = float(np.std(svms, ddof=1) / np.sqrt(len(svms))) + f1_standard_error(0.5, 0.5, 300)
        assert mean <= ideal.f1 + 3 * se, (a, b, scene, mean, ideal.f1)


def test_svm_never_beats_the_ideal_observer_with_varied_initial_conditions(paper_sensor):
    scene = Scene(contact_s=1.5, sensor_temp_c=32.5, sensor_temp_spread_c=2.5)
    a, b = (1000, 1080), (1400, 1480)
    ideal = ideal_pair(a, b, paper_sensor, scene, n_mc=1500, seed=0)
    assert ideal.method == "monte-carlo"
    svm = interval_pair_f1(a, b, paper_sensor, scene, seed=0)
    assert svm.f1 <= ideal.f1 + 3 * math.hypot(svm.standard_error, ideal.standard_error)
    # varied conditions can only make the task harder than fixed ones
    fixed = ideal_pair(a, b, paper_sensor, Scene(contact_s=1.5, sensor_temp_c=32.5))
    assert ideal.accuracy <= fixed.accuracy + 3 * ideal.accuracy_standard_error


def test_binary_f1_equals_scikit_learn():
    from sklearn.metrics import f1_score

    from designkit.recognition.svm import binary_f1

    rng = np.random.default_rng(0)
    for n in (1, 2, 7, 50):
        for _ in range(50):
            y, p = rng.integers(0, 2, n), rng.integers(0, 2, n)
            assert binary_f1(y, p) == pytest.approx(f1_score(y, p, zero_division=0.0), abs=1e-15)
    assert binary_f1([0, 0], [0, 0]) == 0.0


def test_standard_error_is_sane():
    assert 0 < f1_standard_error(1.0, 0.0, 100) < 0.01
    assert 0.03 < f1_standard_error(0.7, 0.3, 100) < 0.08
    assert f1_standard_error(0.7, 0.3, 400) == pytest.approx(f1_standard_error(0.7, 0.3, 100) / 2, rel=0.05)


def test_recognition_rejects_bad_input(paper_sensor):
    scene = Scene(contact_s=1.0)
    with pytest.raises(InputError, match="identical"):
        interval_pair_f1((100, 180), (100, 180), paper_sensor, scene)
    with pytest.raises(InputError, match="positive width"):
        interval_pair_f1((100, 100), (200, 280), paper_sensor, scene)
    with pytest.raises(InputError, match="folds"):
        interval_pair_f1((100, 180), (200, 280), paper_sensor, scene, trials=2, folds=3)
    with pytest.raises(InputError, match="folds must be >= 2"):
        cross_validated_f1(np.zeros((5, 3)), np.ones((5, 3)), 200.0, folds=1)
    with pytest.raises(InputError, match="positive"):
        interval_pair_f1((-100, 180), (200, 280), paper_sensor, scene)
