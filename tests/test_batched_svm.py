"""The batched SVM (recognition.batched_svm) against the reference scikit-learn path.

A smaller version of benchmarks/bench_svm.py's agreement run, with the same assertions:
same folds, F1 equal to ``f1_from_features`` except where a test prediction is a near-tie,
differing predictions at most 0.1 % of all and each a near-tie.
"""

from __future__ import annotations

import numpy as np
import pytest

from designkit import InputError, Scene
from designkit._validation import as_generator
from designkit.objects import ObjectClass
from designkit.recognition.batched_svm import LIBSVM_EPS, batched_cv_f1, solve_svc_duals, stratified_test_folds
from designkit.recognition.features import feature_matrix
from designkit.recognition.svm import f1_from_features

NEAR_TIE = 0.02  # |decision| below this (the functional margin is 1) counts as a near-tie


def _pair(sensor, e_low, e_high, contact, ratio, seed, trials=100):
    from designkit.simulation import simulate_class

    scene = Scene(contact_s=contact, noise_c=ratio, sensor_temp_c=26.0, ambient_temp_c=25.0)
    lo = simulate_class(ObjectClass("low", (e_low, e_low + 80.0)), trials, sensor, scene, [seed, 0])
    hi = simulate_class(ObjectClass("high", (e_high, e_high + 80.0)), trials, sensor, scene, [seed, 1])
    return feature_matrix(lo.temperature_c, 200.0), feature_matrix(hi.temperature_c, 200.0)


def _reference_decisions(lo, hi, seed):
    import sklearn
    from sklearn.model_selection import StratifiedKFold, cross_val_predict

    from designkit.recognition.svm import make_classifier

    X = np.vstack([lo, hi])
    y = np.r_[np.zeros(len(lo), dtype=int), np.ones(len(hi), dtype=int)]
    cv = StratifiedKFold(3, shuffle=True, random_state=int(as_generator(seed).integers(0, 2**31 - 1)))
    with sklearn.config_context(assume_finite=True, skip_parameter_validation=True):
        return cross_val_predict(make_classifier(), X, y, cv=cv, method="decision_function")


@pytest.mark.parametrize("n_low,n_high,folds", [(100, 100, 3), (7, 11, 3), (30, 20, 5), (4, 4, 2)])
@pytest.mark.parametrize("seed", [0, 17, [3, 2], [123, 4, 2]])
def test_folds_are_scikit_learns_stratified_kfold(n_low, n_high, folds, seed):
    from sklearn.model_selection import StratifiedKFold

    y = np.r_[np.zeros(n_low, dtype=int), np.ones(n_high, dtype=int)]
    cv = StratifiedKFold(folds, shuffle=True, random_state=int(as_generator(seed).integers(0, 2**31 - 1)))
    ref = np.empty(y.size, dtype=int)
    for f, (_, test) in enumerate(cv.split(np.zeros((y.size, 1)), y)):
        ref[test] = f
    np.testing.assert_array_equal(stratified_test_folds(n_low, n_high, seed, folds), ref)


def _libsvm(K, y01):
    from sklearn.svm import SVC

    s = SVC(kernel="precomputed", C=1.0).fit(K, y01)
    a = np.zeros(len(y01))
    a[s.support_] = np.abs(s.dual_coef_[0])
    return a, s


@pytest.mark.parametrize("case", ["separable", "overlapping", "rank-deficient"])
def test_dual_solution_meets_libsvms_optimum(case):
    rng = np.random.default_rng({"separable": 1, "overlapping": 2, "rank-deficient": 3}[case])
    n, d = 40, {"separable": 60, "overlapping": 3, "rank-deficient": 10}[case]
    y01 = np.r_[np.zeros(n // 2, dtype=int), np.ones(n // 2, dtype=int)]
    shift = {"separable": 0.3, "overlapping": 0.4, "rank-deficient": 0.5}[case]
    X = rng.normal(size=(n, d)) + shift * y01[:, None]
    K = X @ X.T
    y_lib = np.where(y01 == 0, 1.0, -1.0)  # libsvm: the smaller label is +1
    a, rho, info = solve_svc_duals(K[None], y_lib)
    assert info["kkt_gap"][0] < LIBSVM_EPS
    assert np.all((a >= 0) & (a <= 1.0)) and abs(float(a[0] @ y_lib)) < 1e-9
    a_ref, svc = _libsvm(K, y01)

    def dual(v):
        q = v * y_lib
        return 0.5 * q @ K @ q - v.sum()

    # both are optimal to libsvm's tolerance; ours is at least as good
    assert dual(a[0]) <= dual(a_ref) + 1e-9 * max(1.0, abs(dual(a_ref)))
    Xt = rng.normal(size=(200, d)) + shift * rng.integers(0, 2, 200)[:, None]
    dec_ours = -((Xt @ X.T) @ (a[0] * y_lib) - rho[0])  # scikit-learn's sign convention
    dec_ref = svc.decision_function(Xt @ X.T)
    np.testing.assert_allclose(dec_ours, dec_ref, atol=0.05 * max(1.0, np.abs(dec_ref).max()))


def test_problems_libsvm_solves_end_at_the_exact_optimum_even_where_it_stops_at_its_cap():
    """Overlapping, rank-deficient classes: the active set cannot solve them from all-free,
    libsvm can (to eps 1e-3, or stopped by its step cap, as on the calibrated rig); its free
    and bounded sets then give the exact optimum (``solver`` 2), whatever libsvm's step cap."""
    rng = np.random.default_rng(3)
    n, d = 40, 10
    y01 = np.r_[np.zeros(n // 2, dtype=int), np.ones(n // 2, dtype=int)]
    X = rng.normal(size=(n, d)) + 0.5 * y01[:, None]
    K = X @ X.T
    y_lib = np.where(y01 == 0, 1.0, -1.0)
    a_ref, _ = _libsvm(K, y01)  # libsvm without a cap: 386 steps, KKT gap just under 1e-3
    _, _, info_ref = solve_svc_duals(K[None], y_lib, smo_max_iter=10**6)
    a, rho, info = solve_svc_duals(K[None], y_lib)
    a_cap, rho_cap, info_cap = solve_svc_duals(K[None], y_lib, smo_max_iter=150)
    assert info_cap["iterations"][0] == 150 < info_ref["iterations"][0]  # stopped by the cap
    assert info["solver"][0] == info_cap["solver"][0] == 2
    assert info["kkt_gap"][0] < 1e-6 and info_cap["kkt_gap"][0] < 1e-6  # libsvm stops at 1e-3

    def dual(v):
        q = v * y_lib
        return 0.5 * q @ K @ q - v.sum()

    assert dual(a[0]) < dual(a_ref)
    np.testing.assert_allclose(a_cap, a, atol=1e-9)
    np.testing.assert_allclose(rho_cap, rho, atol=1e-9)


def test_batched_f1_equals_the_reference_except_on_near_ties(paper_sensor):
    rng = np.random.default_rng(12)
    specs = []
    for k in range(60):
        contact = float(rng.choice([0.5, 1.0, 2.0, 3.0, 4.0], p=[0.2, 0.25, 0.25, 0.15, 0.15]))
        ratio = float(np.exp(rng.uniform(np.log(0.001), np.log(0.05))))
        e_low = 80.0 * int(rng.integers(0, 450))
        gap = 80.0 * int(np.clip(round(np.exp(rng.uniform(0, np.log(200)))), 1, 499 - e_low / 80.0))
        specs.append((contact, ratio, e_low, e_low + gap, 1000 + k))
    n_pred = 0
    differing = []
    f1_differs = []
    for contact in sorted({s[0] for s in specs}):
        group = [s for s in specs if s[0] == contact]
        feats = [_pair(paper_sensor, e1, e2, c, r, k) for c, r, e1, e2, k in group]
        seeds = [[k, 2] for *_, k in group]
        ours = batched_cv_f1([f[0] for f in feats], [f[1] for f in feats], seeds=seeds)
        assert np.all(ours.kkt_gap < LIBSVM_EPS)
        for i, (lo, hi) in enumerate(feats):
            ref = f1_from_features(lo, hi, seed=seeds[i])
            dec = _reference_decisions(lo, hi, seeds[i])
            diff = np.flatnonzero((dec >= 0) != (ours.predictions[i] == 1))
            n_pred += dec.size
            differing += [(abs(dec[j]), abs(ours.decision[i, j])) for j in diff]
            if ref.f1 != ours.f1[i]:
                f1_differs.append((group[i], diff.size))
            else:
                assert ours.result(i) == ref  # every field, bit for bit
            # decision values agree to libsvm's accuracy everywhere
            assert np.max(np.abs(dec - ours.decision[i])) < 0.05
    assert len(differing) <= 0.001 * n_pred, differing
    assert all(min(dr, dn) < NEAR_TIE for dr, dn in differing), differing
    assert all(nd > 0 for _, nd in f1_differs), f1_differs  # F1 differs only through such predictions


@pytest.mark.parametrize("contact,gap", [(0.5, 160.0), (2.0, 800.0), (2.0, 80.0)])
def test_a_starting_guess_changes_the_path_not_the_solution(paper_sensor, contact, gap):
    """The folds after the first start from the states the earlier folds found (batched_cv_f1); any
    guess, however wrong, must give the all-free start's solution bit for bit."""
    from sklearn.preprocessing import StandardScaler

    lo, hi = _pair(paper_sensor, 20000.0, 20000.0 + gap, contact, 0.01, 3)
    X = StandardScaler().fit_transform(np.vstack([lo[:67], hi[:67]]))
    K = (X @ X.T)[None]
    y = np.r_[np.ones(67), -np.ones(67)]
    a0, rho0, info0 = solve_svc_duals(K, y)
    rng = np.random.default_rng(0)
    for _ in range(4):
        state = rng.integers(0, 3, size=(1, y.size))
        a, rho, info = solve_svc_duals(K, y, start=(state == 1, state == 2))
        np.testing.assert_array_equal(a, a0)
        np.testing.assert_array_equal(rho, rho0)
    free = (a0 > 0) & (a0 < 1.0)
    a, _, info = solve_svc_duals(K, y, start=(free, a0 >= 1.0))  # the right guess: one solve
    np.testing.assert_array_equal(a, a0)
    assert info["iterations"][0] == 1 < info0["iterations"][0]


def test_float64_gram_list_input_and_chunking_give_the_same_answers(paper_sensor):
    feats = [_pair(paper_sensor, 20000.0, 20000.0 + g, 1.0, 0.01, k, trials=40) for k, g in enumerate([80, 800, 8000])]
    seeds = [0, [1, 2], 7]
    a = batched_cv_f1(np.stack([f[0] for f in feats]), np.stack([f[1] for f in feats]), seeds=seeds)
    b = batched_cv_f1([f[0] for f in feats], [f[1] for f in feats], seeds=seeds, gram_dtype="float64", chunk_size=1)
    np.testing.assert_array_equal(a.f1, b.f1)
    np.testing.assert_allclose(a.decision, b.decision, atol=1e-4)
    for i, (lo, hi) in enumerate(feats):
        assert b.result(i) == f1_from_features(lo, hi, seed=seeds[i])


def test_bad_input_is_refused():
    lo = np.zeros((2, 10, 4))
    with pytest.raises(InputError, match="one seed per pair"):
        batched_cv_f1(lo, lo + 1, seeds=[0])
    with pytest.raises(InputError, match="same batch"):
        batched_cv_f1(lo, np.ones((3, 10, 4)), seeds=[0, 1])
    with pytest.raises(InputError, match="folds"):
        batched_cv_f1(lo, lo + 1, seeds=[0, 1], folds=1)
    with pytest.raises(InputError, match="at least the number of folds"):
        batched_cv_f1(lo[:, :2], lo[:, :2] + 1, seeds=[0, 1])
    bad = lo.copy()
    bad[0, 0, 0] = np.nan
    with pytest.raises(InputError, match="NaN"):
        batched_cv_f1(bad, lo + 1, seeds=[0, 1])
    with pytest.raises(InputError, match="gram_dtype"):
        batched_cv_f1(lo, lo + 1, seeds=[0, 1], gram_dtype="float16")
    with pytest.raises(InputError, match="shaped"):
        batched_cv_f1(np.zeros(5), np.zeros(5), seeds=[0])


@pytest.mark.parametrize("case", ["separable", "overlapping", "rank-deficient"])
def test_the_array_api_path_is_the_same_solver(case, paper_sensor):
    """The code a GPU library runs (every ``xp is not np`` branch: bordered LU steps, no LAPACK
    loop) on numpy arrays through array_api_compat's wrapper namespace: the same duals and the
    same F1 as numpy's own fast path."""
    xnp = pytest.importorskip("array_api_compat.numpy", reason="array-api-compat is in the test and gpu extras")
    rng = np.random.default_rng(40)
    n, d = 40, {"separable": 60, "overlapping": 3, "rank-deficient": 10}[case]
    y_lib = np.r_[np.ones(n // 2), -np.ones(n // 2)]
    X = rng.normal(size=(n, d)) + 0.4 * (y_lib < 0)[:, None]
    K = np.stack([X @ X.T, (2 * X) @ (2 * X).T])
    a_np, rho_np, info_np = solve_svc_duals(K, y_lib)
    a_xp, rho_xp, info_xp = solve_svc_duals(xnp.asarray(K), xnp.asarray(y_lib), xp=xnp)
    assert np.all(np.asarray(info_xp["kkt_gap"]) < LIBSVM_EPS)
    np.testing.assert_array_equal(np.asarray(info_xp["solver"]), info_np["solver"])
    scale = max(1.0, float(np.abs(rho_np).max()))
    np.testing.assert_allclose(np.asarray(a_xp), a_np, atol=1e-6)
    np.testing.assert_allclose(np.asarray(rho_xp), rho_np, atol=1e-6 * scale)
    if case == "separable":  # and the whole cross-validation on simulated touches
        feats = [_pair(paper_sensor, 20000.0, 20000.0 + g, 1.0, 0.01, k, trials=30) for k, g in enumerate([160, 4000])]
        lo, hi = [f[0] for f in feats], [f[1] for f in feats]
        ours, generic = batched_cv_f1(lo, hi, seeds=[0, 1]), batched_cv_f1(lo, hi, seeds=[0, 1], xp=xnp)
        np.testing.assert_array_equal(generic.f1, ours.f1)
        # numpy's own path reads float32 deviations from prepared features (decisions to about 1e-6 of
        # the functional margin; libsvm itself stops at a KKT gap of 1e-3), the generic one float64
        np.testing.assert_allclose(generic.decision, ours.decision, atol=1e-5)


def test_the_array_api_path_gives_each_pair_the_same_arithmetic_whatever_the_stack(paper_sensor):
    """A GPU sweep stacks a whole batch of pairs (sweep/scorer.py), numpy's fast path 8: a pair's
    decision values must not depend on how many pairs are solved beside it, bit for bit."""
    xnp = pytest.importorskip("array_api_compat.numpy", reason="array-api-compat is in the test and gpu extras")
    feats = [_pair(paper_sensor, 20000.0, 20000.0 + g, 1.0, 0.01, k, trials=30)
             for k, g in enumerate([160, 400, 900, 2000, 4000])]
    lo, hi = [f[0] for f in feats], [f[1] for f in feats]
    one = batched_cv_f1(lo, hi, seeds=list(range(5)), xp=xnp, chunk_size=1)
    all_ = batched_cv_f1(lo, hi, seeds=list(range(5)), xp=xnp, chunk_size=5)
    np.testing.assert_array_equal(all_.decision, one.decision)
    np.testing.assert_array_equal(all_.f1, one.f1)
