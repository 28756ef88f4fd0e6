"""The exact route's crossing estimate is not early on F1 curves that are not logit-linear (issue 34).

On the calibrated rig ``--exact`` min-contact answered early on 4 of 6 pairs checked against fresh-seed truth
(4.0-6.8 %; benchmarks/results/sensor_table_bias.txt): the SVM's F1 there is not logit-linear in log contact over
the fit's window (a factor of about 2, F1 from 0.72 to 0.98): its logit slope rises through the threshold, like a
complementary log-log curve, so a straight line through the points lies above the curve at the crossing. Here
curves of that shape, ``cloglog(2 F1 - 1) = a + b v + c v^2`` in ``v = log(x / x*)`` with the slope and curvature
fitted to the rig's measured F1 (b 2.2-3.4, c 0-1.3), are read as the route reads the SVM: the mean of 4 seeds,
each the curve plus the seed-to-seed spread measured on the rig (SD 0.085 sqrt(1 - F1), clipped at 1), each seed
with a fold-style error of its own F1 (:class:`~designkit.query.crossing.SeedDraws`: the route's pooled error model).
The search starts where the ideal observer would (0.7 x*) and ends at 10 x*, as min-contact's does.

The error model (issue 34): a seed's own cross-validation error leaves out its training set's variation, so the
seeds' F1 scatter more (on the rig 1.15x pooled, 1.3-1.5x above F1 0.93); an evaluation's error was the larger of
its seeds' own errors and their spread, over 2, the spread of 4 seeds having 3 degrees of freedom: the fit's
weights were random. The pooled model (``kappa`` over the search's evaluations) is checked below on curves whose
seeds scatter 1.4x their own errors.
"""

from __future__ import annotations

import math

import numpy as np

from designkit.query.crossing import SeedDraws, estimate_crossing, t_of_coverage
from designkit.recognition.svm import f1_standard_error


def _curve(b: float, c: float):
    """F1(x / x*) crossing 0.9 at 1, monotone over the search (the quadratic's slope b + 2 c v held above b / 4)."""
    y0 = math.log(-math.log(0.2))  # cloglog(0.8): 2 * 0.9 - 1

    def mean_f1(r: float) -> float:
        v = math.log(r)
        eta = y0 + b * v + c * v * v if b + 2 * c * v > b / 4 else y0 + b * v  # beyond the fold: the line
        return 0.5 + 0.5 * (1.0 - math.exp(-math.exp(min(eta, 30.0))))

    return mean_f1


def _replays(curvature: bool, n: int = 400, seed: int = 34) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    errors, held = [], []
    for _ in range(n):
        x_star = float(np.exp(rng.uniform(math.log(0.5), math.log(5.0))))
        mean_f1 = _curve(rng.uniform(2.2, 3.4), rng.uniform(0.0, 1.3))

        def f(x, mean_f1=mean_f1, x_star=x_star):
            m = mean_f1(x / x_star)
            draws = np.minimum(m + 0.085 * math.sqrt(1.0 - m) * rng.standard_normal(4), 1.0)
            return SeedDraws(draws, 0.07 * np.sqrt(1.0 - draws))  # a seed's own fold error shrinks as F1 nears 1

        e = estimate_crossing(f, 0.7 * x_star, 10.0 * x_star, 0.9, curvature=curvature)
        assert e.value is not None and e.low is not None and e.high is not None
        errors.append(math.log(e.value / x_star))
        held.append(e.low <= x_star <= e.high)
    return np.array(errors), np.array(held)


def test_crossing_of_curves_steepening_through_the_threshold_is_not_early():
    errors, held = _replays(curvature=True)
    # now: +0.04 % (median of 400), 49 % of the answers early, 97 % of the 90 % intervals hold x* (conservative
    # here: the interval is never narrower than the straight line's, whose lack of fit the bend inflates); the
    # straight line (the estimator before issue 34, curvature=False): -1.2 %, 73 % early (91 % held: its
    # lack-of-fit widening absorbs part of it here; on the rig's own resampled draws -2.0 % and 74 % held)
    assert abs(np.median(errors)) < 0.004, np.median(errors)
    assert 0.4 <= np.mean(errors < 0) <= 0.6, np.mean(errors < 0)
    assert 0.85 <= held.mean() <= 0.98, held.mean()
    old_errors, _ = _replays(curvature=False)
    assert np.median(old_errors) < -0.008 and np.mean(old_errors < 0) > 0.65, np.median(old_errors)


def test_crossing_of_logit_linear_curves_is_still_unbiased():
    """On logistic curves in log x (the straight line's own model, as the paper's SVM curves are taken to be) the
    curvature term costs no bias and keeps the coverage."""
    rng = np.random.default_rng(7)
    errors, held = [], []
    for _ in range(300):
        k = rng.uniform(2.0, 8.0)
        x_star = float(np.exp(rng.uniform(math.log(0.5), math.log(5.0))))
        x50 = x_star / 4.0 ** (1.0 / k)

        def f(x, k=k, x50=x50):
            m = 0.5 + 0.5 / (1.0 + (x / x50) ** -k)
            se1 = 0.085 * math.sqrt(1.0 - m)
            draws = np.minimum(m + se1 * rng.standard_normal(4), 1.0)
            return float(draws.mean()), max(se1, float(np.std(draws, ddof=1))) / 2

        e = estimate_crossing(f, 0.05, 10.0, 0.9)
        errors.append(math.log(e.value / x_star))
        held.append(e.low <= x_star <= e.high)
    assert abs(np.median(errors)) < 0.006, np.median(errors)
    assert 0.85 <= np.mean(held) <= 0.98, np.mean(held)


def _own_error(m: float) -> float:
    """A seed's own (test-set) standard error at F1 ``m``, 100 touches per class."""
    return f1_standard_error(min(1.0, m), max(0.0, 1.0 - m), 100)


def _searches(pooled: bool, n: int = 120, kappa: float = 1.4, seed: int = 33):
    """Searches on logistic curves whose 4 seeds per evaluation scatter ``kappa`` times their own errors; per logged
    informative evaluation (z of its mean against the curve in its stated error, log of stated over true error), and
    per search whether its 90 % interval holds the crossing. The same draws for both error models."""
    rng = np.random.default_rng(seed)
    z, ratio, held = [], [], []
    for _ in range(n):
        k = rng.uniform(2.0, 8.0)
        x_star = float(np.exp(rng.uniform(math.log(0.5), math.log(5.0))))
        x50 = x_star / 4.0 ** (1.0 / k)
        draws_rng = np.random.default_rng(rng.integers(2 ** 31))

        def mean_f1(x, k=k, x50=x50):
            return 0.5 + 0.5 / (1.0 + (x / x50) ** -k)

        def f(x, mean_f1=mean_f1, draws_rng=draws_rng):
            m = mean_f1(x)
            draws = np.clip(m + kappa * _own_error(m) * draws_rng.standard_normal(4), 0.0, 1.0)
            d = SeedDraws(draws, [_own_error(v) for v in draws])
            return d if pooled else (d.mean, d.standard_error())

        e = estimate_crossing(f, 0.05, 10.0, 0.9)
        q = t_of_coverage(0.9, e.error_dof)
        for ev in e.evaluations:
            m = mean_f1(ev["x"])
            if 0.75 < ev["svm_f1"] < 0.97:  # where the crossing is fitted
                z.append(abs(ev["svm_f1"] - m) / (q * ev["standard_error"]))
                ratio.append(math.log(ev["standard_error"] / (kappa * _own_error(m) / 2.0)))
        held.append(e.low is not None and e.high is not None and e.low <= x_star <= e.high)
    return np.array(z), np.array(ratio), np.array(held)


def test_an_evaluations_stated_error_covers_its_seeds_scatter():
    """Each evaluation's error as the fit weighs it, where the crossing is fitted (F1 0.75-0.97): the pooled model
    states it to within about 16 % (sd of the log ratio to the true error; its kappa rests on about 27 degrees of
    freedom) and its band at Student's t holds the curve's mean about 90 % of the time; each evaluation's own error
    (4 seeds: 3 degrees of freedom, the model before) was off by 28 %, so the fit's weights were random."""
    z, ratio, held = _searches(pooled=True)
    # now (584 evaluations of 120 searches): 87 % inside, log ratio sd 0.16, 91 % of the intervals held
    assert 0.85 <= np.mean(z <= 1.0) <= 0.94, np.mean(z <= 1.0)
    assert np.std(ratio) < 0.2, np.std(ratio)
    assert 0.85 <= held.mean() <= 0.98, held.mean()
    _, ratio_old, held_old = _searches(pooled=False)  # the same draws: log ratio sd 0.28, 89 % held
    assert np.std(ratio_old) > 0.25, np.std(ratio_old)
