"""The live sequential test: error rates within the requested ones, the object and the batch agree,
hopeless pairs and mismatched streams are named."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from designkit import SENSORS
from designkit._validation import InputError
from designkit.objects import ObjectClass
from designkit.recognition.ideal import ideal_pair
from designkit.recognition.sequential import (
    KEEP_TOUCHING, NO_DECISION, NOT_SEPARABLE, SequentialTest, candidate_pieces,
    log_marginals, min_fixed_contact_s, run_batch,
)
from designkit.scene import Scene
from designkit.simulation import simulate_class

PAPER = SENSORS["paper"]
LOW, HIGH = ("20000", (20000.0, 20080.0)), ("35000", (35000.0, 35080.0))


def _test(eps=0.05, cands=(LOW, HIGH), **kw):
    kw = {"noise_c": 0.05, "sensor_temp_c": 35.0, "ambient_temp_c": 25.0, "max_contact_s": 3.0, **kw}
    return SequentialTest(list(cands), PAPER, error_rate=eps, **kw)


def _touches(rng_, n, seed, contact=3.0, noise=0.05):
    return simulate_class(ObjectClass("x", rng_), n, PAPER, Scene(contact_s=contact, noise_c=noise), seed=seed)


@pytest.mark.parametrize("eps", [0.05, 0.01])
def test_error_rates_within_requested_on_seeded_touches(eps):
    test = _test(eps)
    n = 2000
    for i, (_, rng_) in enumerate((LOW, HIGH)):
        r = run_batch(test, _touches(rng_, n, [11, i]).temperature_c)
        wrong = int(np.sum(r.decided != i))
        # one-sided binomial test at 0.1 %: the observed errors are consistent with a rate <= eps
        assert stats.binomtest(wrong, n, eps, alternative="greater").pvalue > 1e-3, (eps, wrong)
        assert np.all(r.decided >= 0)  # all decided well before 3 s
        # and the test stops before the fixed contact the ideal observer needs for these error rates
        assert r.time_s.mean() < test.plan.fixed_contact_s


def test_object_and_batch_give_identical_decisions():
    test = _test(0.01)
    tr = _touches(HIGH[1], 40, [5, 1], noise=0.2)  # noisy: decisions late and some wrong
    batch = run_batch(test, tr.temperature_c)
    for row in range(40):
        test.reset()
        for t, y in zip(tr.time_s, tr.temperature_c[row]):
            d = test.update(t, y)
            if d.final:
                break
        idx = -1 if d.state != "decided" else [c.name for c in test.candidates].index(d.material)
        assert idx == batch.decided[row]
        assert math.isclose(d.time_s, batch.time_s[row])


def test_log_marginal_of_a_point_is_gaussian_and_a_wide_class_its_mixture():
    es = PAPER.effusivity
    v, s = 0.9, 0.01
    pt = SequentialTest([("a", 20000.0), ("b", 35000.0)], PAPER, noise_c=0.05, sensor_temp_c=35,
                        ambient_temp_c=25, max_contact_s=2)
    ll = log_marginals(v, s, pt.candidates)
    w = np.array([20000 / (es + 20000), 35000 / (es + 35000)])
    expect = stats.norm.logpdf(v, w, s)
    assert np.allclose(ll, expect, rtol=0, atol=1e-12)
    # a wide class: against direct quadrature of the uniform-in-e mixture
    wide = SequentialTest([("wood", (331.0, 506.46)), ("metal", (12767.0, 25972.0))], PAPER, noise_c=0.05,
                          sensor_temp_c=35, ambient_temp_c=25, max_contact_s=2)
    e = np.linspace(12767.0, 25972.0, 200001)
    for v in (0.9, 0.95, 0.97):
        direct = np.log(np.trapezoid(stats.norm.pdf(v, e / (es + e), 0.005), e) / (25972.0 - 12767.0))
        got = log_marginals(v, 0.005, wide.candidates)[1]
        assert abs(got - direct) < 0.05  # the piecewise prior: density within 10 % per piece


def test_pieces_cover_the_range_with_bounded_density_ratio():
    edges, lm = candidate_pieces(331.0, 38000.0, 892.0)
    e = 892.0 * edges / (1 - edges)
    assert math.isclose(e[0], 331.0) and math.isclose(e[-1], 38000.0, rel_tol=1e-12)
    assert math.isclose(np.exp(lm).sum(), 1.0, rel_tol=1e-12)
    assert np.all(((892.0 + e[1:]) / (892.0 + e[:-1])) ** 2 <= 1.1 + 1e-9) or len(lm) == 32


def test_fixed_time_reference_matches_the_ideal_observer():
    # at the fixed contact where both error rates reach eps, the ideal Bayes accuracy is at least 1 - eps
    t = min_fixed_contact_s(LOW[1], HIGH[1], 0.05, 0.05, PAPER, 0.005, 10.0)
    acc = ideal_pair(LOW[1], HIGH[1], PAPER, Scene(contact_s=t)).accuracy
    before = ideal_pair(LOW[1], HIGH[1], PAPER, Scene(contact_s=t - 0.02)).accuracy
    assert acc >= 0.95 - 1e-9 and before < 0.95 + 0.01
    assert min_fixed_contact_s(LOW[1], HIGH[1], 0.05, 0.05, PAPER, 0.005, t - 0.005) is None  # the shortest


def test_hopeless_pair_says_so_before_the_first_sample():
    test = _test(0.01, cands=(("a", (20000.0, 20080.0)), ("b", (20100.0, 20180.0))), max_contact_s=3.0)
    assert not test.plan.separable and "no contact time up to 3 s" in test.plan.reason
    d = test.update(0.0, 35.0)
    assert d.state == NOT_SEPARABLE and d.final
    # overlapping ranges can never be separated
    assert not _test(0.05, cands=(("a", (100.0, 500.0)), ("b", (400.0, 900.0)))).plan.separable


def test_truncation_gives_no_decision_with_the_most_likely_material():
    test = _test(0.001, max_contact_s=1.2)  # separable only in 1.58 s by a fixed test: refused
    assert not test.plan.separable
    test = _test(0.05, max_contact_s=1.2, noise_c=0.05)
    tr = _touches(LOW[1], 1, [9, 0], contact=1.2, noise=0.5)  # ten times noisier than assumed
    for t, y in zip(tr.time_s, tr.temperature_c[0]):
        d = test.update(t, y)
    assert d.final and (d.state == NO_DECISION) == (d.state != "decided")


def test_three_materials():
    cands = (("a", (20000.0, 20080.0)), ("b", (35000.0, 35080.0)), ("c", (5000.0, 5080.0)))
    test = _test(0.02, cands=cands)
    for i, (_, rng_) in enumerate(cands):
        r = run_batch(test, _touches(rng_, 500, [3, i]).temperature_c)
        assert stats.binomtest(int(np.sum(r.decided != i)), 500, 0.02, alternative="greater").pvalue > 1e-3


def test_stream_at_the_wrong_rate_is_refused_in_one_line():
    test = _test(0.05)
    test.update(0.0, 35.0)
    with pytest.raises(InputError, match="stream sample rate does not match the sensor's 200 Hz.*1000 Hz"):
        test.update(0.001, 35.0)
    assert test.update(0.005, 35.0).state == KEEP_TOUCHING
    with pytest.raises(InputError, match="two candidate"):
        SequentialTest([LOW], PAPER, noise_c=0.05, sensor_temp_c=35, ambient_temp_c=25)
    with pytest.raises(InputError, match="error rate"):
        _test(0.7)
    with pytest.raises(InputError, match="must differ"):
        _test(0.05, ambient_temp_c=35.0)


def test_scalar_path_agrees_with_the_vectorized_one():
    from scipy import special

    from designkit.recognition import sequential as seq

    x = np.r_[np.linspace(-60, 12, 2001), -30.0, -29.999, -20.0, 6.0, 6.001]
    mine = np.array([seq._log_ndtr_1(float(v)) for v in x])
    ref = special.log_ndtr(x)
    assert np.allclose(mine, ref, rtol=1e-13, atol=1e-300)
    test = SequentialTest([("wood", (331.0, 506.46)), ("acrylic", (550.0, 650.0)), ("metal", (12767.0, 25972.0))],
                          PAPER, noise_c=0.05, sensor_temp_c=35, ambient_temp_c=25, max_contact_s=2)
    rng = np.random.default_rng(0)
    for v, s in zip(rng.uniform(0.1, 1.0, 200), 10 ** rng.uniform(-5, 0, 200)):
        a = seq._log_marginals_1(float(v), float(s), test.candidates)
        b = log_marginals(v, s, test.candidates)
        assert np.allclose(a, b, rtol=0, atol=1e-6)  # the central shortcut: relative error < 1e-7
