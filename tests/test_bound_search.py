"""The closed-form bounds: the critical noise and the search over the sample count.

The ideal observer's min-contact (and the efficiency route's) is the first sample count at which a
monotone decision holds: the projection noise falls to the pair's critical noise. These tests check the
answers against the definition (the grid-maximized F1 fails one sample earlier and holds at the answer),
the critical noise against a plain bisection, and the sample search against a brute-force scan.
"""

import numpy as np
import pytest

from designkit.query import ideal_bound as ib
from designkit.recognition import ideal as cf
from designkit.sensor import load_sensor

PAPER = load_sensor("paper")


def _decides(lo, hi, ratio, n):
    cum = cf.cumulative_g2(float(PAPER.tau_s), float(PAPER.sample_rate_hz), 2000)
    with np.errstate(divide="ignore"):
        s = ratio / np.sqrt(cum[n])
    return bool(cf.separates(PAPER, np.array([lo]), np.array([hi]), 80.0, np.array([s]), 0.9)[0])


@pytest.mark.parametrize("seed", [0, 1])
def test_ideal_min_contact_is_the_first_sample_where_the_ideal_observer_separates(seed):
    rng = np.random.default_rng(seed)
    lo = rng.uniform(100.0, 39000.0, 12)
    hi = lo + rng.uniform(100.0, 15000.0, 12)
    ratio = 10.0 ** rng.uniform(-3.5, -1.5, 12)
    t = ib.exact_ideal_min_contact(PAPER, lo, hi, ratio)
    fs = float(PAPER.sample_rate_hz)
    checked = 0
    for i in np.nonzero(np.isfinite(t))[0]:
        n = int(round(t[i] * fs))
        assert _decides(lo[i], hi[i], ratio[i], n), (lo[i], hi[i], ratio[i], n)
        assert not _decides(lo[i], hi[i], ratio[i], n - 1), (lo[i], hi[i], ratio[i], n)
        checked += 1
    assert checked >= 6


def test_the_bisection_finds_the_first_count_where_a_decision_holds():
    rng = np.random.default_rng(3)
    switch = rng.integers(1, 2000, 400)  # the first count where each element's decision holds
    a = np.zeros(400, dtype=np.int64)
    b = np.full(400, 2000, dtype=np.int64)
    assert np.array_equal(ib._first_good_sample(lambda n, rows: n >= switch[rows], a, b), switch)
    # a decision that never holds below b answers b
    never = np.full(400, 5000)
    assert np.array_equal(ib._first_good_sample(lambda n, rows: n >= never[rows], a, b), b)


def test_the_critical_noise_is_where_the_best_f1_crosses_the_threshold():
    """Newton's root agrees with a plain bisection of the grid-maximized F1 (an independent maximizer)."""
    rng = np.random.default_rng(5)
    lo = rng.uniform(1.0, 39000.0, 300)
    width = rng.choice([80.0, 400.0, 2000.0], 300)
    hi = lo + width + rng.uniform(1.0, 15000.0, 300)
    star = cf.critical_noise(PAPER, lo, hi, width=width)
    assert np.all(np.isfinite(star))
    f1 = cf.ideal_f1(lo, hi, width, PAPER.effusivity, star)
    assert np.max(np.abs(f1 - 0.9)) < 1e-9
    plain = cf._bisect_noise(PAPER, lo, hi, np.ones(lo.size), width, 0.9, (1e-9, 10.0), 1e-10)
    np.testing.assert_allclose(star, plain, rtol=1e-8)


def test_classes_the_ideal_observer_cannot_order_have_no_critical_noise():
    # the "higher" class below the lower one: no threshold on v reaches F1 0.9 at any noise
    assert np.isnan(cf.critical_noise(PAPER, 35000.0, 20000.0))


def test_the_first_sample_is_the_first_count_whose_projection_noise_reaches_the_critical_one():
    rng = np.random.default_rng(6)
    cum = cf.cumulative_g2(float(PAPER.tau_s), float(PAPER.sample_rate_hz), 600)
    ratio = 10.0 ** rng.uniform(-4.0, -1.0, 500)
    star = 10.0 ** rng.uniform(-4.0, -1.0, 500)
    n = ib.first_sample_at(cum, ratio, star)
    with np.errstate(divide="ignore"):
        ok = ratio[:, None] / np.sqrt(cum[None, :]) <= star[:, None]
    ok[:, 0] = False  # the sample at contact carries no signal
    brute = np.where(ok.any(axis=1), np.argmax(ok, axis=1), np.nan)
    np.testing.assert_array_equal(n, brute)
    assert ib.first_sample_at(cum, 0.0, 1e-3) == 1 and np.isnan(ib.first_sample_at(cum, 0.01, np.nan))


def test_noise_k_contact_is_the_first_sample_where_the_classifier_separates():
    """The bisection (monotone k, many pairs) and the dense scan (steep k, or few pairs) give the definition's first sample."""
    rng = np.random.default_rng(5)
    m = 3000
    ratio, star = 10.0 ** rng.uniform(-3.5, -1.3, m), 10.0 ** rng.uniform(-3.0, -1.0, m)
    t_a = rng.choice([0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0], m)
    t_b = t_a * rng.choice([1.5, 2.0], m)
    ka = rng.uniform(0.0, 1.2, m)
    kb = ka + rng.uniform(-0.2, 0.5, m)  # slopes up to 1.2 per log t: both branches
    got = ib.noise_k_contact(PAPER, ratio, star, t_a, t_b, ka, kb, 10.0)
    fs = float(PAPER.sample_rate_hz)
    n = np.arange(1, 2001)
    cum = cf.cumulative_g2(float(PAPER.tau_s), fs, 2000)
    slope = (kb - ka) / np.log(t_b / t_a)
    log_k = np.maximum(ka[:, None] + slope[:, None] * (np.log(n / fs)[None, :] - np.log(t_a)[:, None]), 0.0)
    ok = log_k + np.log(ratio)[:, None] - 0.5 * np.log(cum[n])[None, :] <= np.log(star)[:, None]
    want = np.where(ok.any(axis=1), n[np.argmax(ok, axis=1)] / fs, np.nan)
    assert np.array_equal(got, want, equal_nan=True)
    assert (slope > 0.5).sum() > 100 and (slope <= 0.5).sum() > 100 and np.isnan(want).sum() > 10


def test_noise_k_contact_answers_a_pair_alone_as_in_a_crowd():
    rng = np.random.default_rng(6)
    m = 500
    args = (10.0 ** rng.uniform(-3.5, -1.3, m), 10.0 ** rng.uniform(-3.0, -1.0, m), np.full(m, 1.0), np.full(m, 2.0),
            rng.uniform(0.0, 1.0, m), rng.uniform(0.0, 1.2, m))
    crowd = ib.noise_k_contact(PAPER, *args, 10.0)  # > 64 pairs: bisection where k is not steep
    alone = np.array([float(ib.noise_k_contact(PAPER, *(a[i] for a in args), 10.0)) for i in range(0, m, 10)])
    assert np.array_equal(alone, crowd[::10], equal_nan=True)
