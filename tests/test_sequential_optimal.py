"""The optimal sequential test (backward induction): Wald's SPRT where information accrues at a constant
rate, and on the guideline pair a recursion whose figures simulated touches confirm."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from designkit import SENSORS
from designkit._validation import InputError
from designkit.objects import ObjectClass
from designkit.recognition.sequential import SequentialTest, run_batch
from designkit_lab.sequential_bound import optimal_stopping, optimal_test, run_boundaries
from designkit.scene import Scene
from designkit.simulation import simulate_class

PAPER = SENSORS["paper"]
LOW, HIGH = ("20000", (20000.0, 20080.0)), ("35000", (35000.0, 35080.0))


def test_constant_information_gives_walds_sprt():
    # i.i.d. samples: the SPRT is optimal (Wald and Wolfowitz 1948), with constant boundaries, and for a
    # Brownian LLR its mean information at the decision is 2 (1 - 2 eps) log((1 - eps) / eps) exactly;
    # discrete steps of 0.1 add a little overshoot
    eps, iota = 0.01, 0.1
    o = optimal_stopping(np.full(500, iota), [-0.5, 0.5], [0.0, 0.0], [False, True], 1.0, eps,
                         sprt_threshold=math.log((1 - eps) / eps), step=0.05, nodes=10, iterations=12)
    wald = 2 * (1 - 2 * eps) * math.log((1 - eps) / eps)
    assert wald * 0.995 < iota * o.bound_s < wald * 1.04
    assert abs(o.error - eps) < 5e-4 and o.bound_s <= o.expected_time_s + 1e-9
    assert o.bound_s < o.sprt_time_s  # Wald's thresholds (overshoot ignored) spend more for fewer errors
    bulk = o.upper[:150]  # far from the horizon the optimal boundaries do not move
    assert np.ptp(bulk) < 0.2 and abs(bulk.mean() + o.lower[:150].mean()) < 0.1


@pytest.fixture(scope="module")
def guideline():
    eps = 0.05
    test = SequentialTest([LOW, HIGH], PAPER, noise_c=0.05, sensor_temp_c=35.0, ambient_temp_c=25.0,
                          error_rate=eps, max_contact_s=2.5)
    o = optimal_test(test, points=1, step=0.04, nodes=10, iterations=12)
    n = 2000
    touches = [simulate_class(ObjectClass("x", r), n, PAPER, Scene(contact_s=2.5), seed=[21, i]).temperature_c
               for i, (_, r) in enumerate((LOW, HIGH))]
    return eps, test, o, touches


def _measured(results, n):
    errors = [int(np.sum(r.decided != i)) for i, r in enumerate(results)]
    times = np.concatenate([r.time_s for r in results])
    return errors, times.mean(), times.std() / math.sqrt(times.size)


def test_recursion_predicts_what_simulated_touches_do(guideline):
    eps, test, o, touches = guideline
    n = touches[0].shape[0]
    for results, want_t, want_e in (([run_batch(test, y) for y in touches], o.sprt_time_s, o.sprt_error),
                                    ([run_boundaries(test, y, o.upper, o.lower) for y in touches],
                                     o.expected_time_s, o.error)):
        errors, mean_t, se = _measured(results, n)
        assert abs(mean_t - want_t) < 4 * se + 0.002, (mean_t, want_t, se)
        lo, hi = stats.binomtest(sum(errors), 2 * n).proportion_ci(0.999)
        assert lo <= want_e <= hi, (errors, want_e)
        assert stats.binomtest(sum(errors), 2 * n, eps, alternative="greater").pvalue > 1e-3


def test_the_bound_is_below_the_sprt_and_the_fixed_contact(guideline):
    eps, test, o, _ = guideline
    assert o.bound_s <= o.expected_time_s + 1e-12 < test.plan.fixed_contact_s
    assert o.bound_s < o.sprt_time_s
    # the evidence arrives late: the optimal boundaries widen with time where the decisions fall
    k = (np.array([0.6, 0.9, 1.2]) * PAPER.sample_rate_hz).astype(int)
    assert np.all(np.diff(o.upper[k]) > 0) and np.all(np.diff(o.lower[k]) < 0)


def test_bad_input_is_named():
    with pytest.raises(InputError, match="information per sample"):
        optimal_stopping([0.1, -1.0], [-0.5, 0.5], [0.0, 0.0], [False, True], 1.0, 0.01)
    three = SequentialTest([LOW, HIGH, ("5000", (5000.0, 5080.0))], PAPER, noise_c=0.05, sensor_temp_c=35.0,
                           ambient_temp_c=25.0, max_contact_s=2.0)
    with pytest.raises(InputError, match="two candidates"):
        optimal_test(three)
    with pytest.raises(InputError, match="two candidates"):
        run_boundaries(three, np.zeros((1, 10)), np.zeros(10), np.zeros(10))
