"""The ideal bound where no closed form holds: a Monte Carlo estimate at query time, with its interval (issue 13).

The independent reference is the closed form in the limit of fixed conditions: a sensor temperature spread of
1e-5 degC changes the ideal observer's shortest contact by far less than one sample, so the Monte Carlo
estimate (varied-condition likelihood, simulated touches) must land on the closed form's answer.
"""

import json
import subprocess
import sys

import pytest

import designkit.query as q
from designkit.objects import ObjectClass
from designkit.query.ideal_bound import exact_ideal_delta, exact_ideal_min_contact
from designkit.query.ideal_mc_bound import mc_ideal_delta, mc_ideal_min_contact, remembered
from designkit.query.table import VARIED_TABLE
from designkit.sensor import SENSORS

PAPER = SENSORS["paper"]


@pytest.mark.parametrize("e_hi, e_lo, noise", [(35000, 20000, 0.05), (800, 600, 0.1)])
def test_the_monte_carlo_bound_lands_on_the_closed_form_in_the_fixed_limit(e_hi, e_lo, noise):
    closed = float(exact_ideal_min_contact(PAPER, e_lo, e_hi, noise / 10.0, width=80.0, threshold=0.9,
                                           max_contact_s=10.0))
    covered = 0
    for seed in range(6):  # a 90 % interval: most of six seeds
        r = mc_ideal_min_contact(ObjectClass("a", (e_lo, e_lo + 80.0)), ObjectClass("b", (e_hi, e_hi + 80.0)),
                                 PAPER, noise_c=noise, delta_t_c=10.0, sensor_temp_spread_c=1e-5, n_mc=1000,
                                 seed=seed)
        assert r.coverage == 0.9 and r.low <= r.value <= r.high
        covered += r.low <= closed <= r.high
        assert abs(r.value - closed) <= 2.0 * (r.high - r.low) + 0.0050001  # about 3 SDs, and a sample
        # reported on the sample grid, as the closed form
        for x in (r.value, r.low, r.high):
            assert abs(x * 200.0 - round(x * 200.0)) < 1e-9
    assert covered >= 4


@pytest.mark.parametrize("e, direction, contact, noise", [(20000.0, -1, 2.0, 0.05), (3000.0, +1, 1.0, 0.02)])
def test_the_monte_carlo_delta_lands_on_the_closed_form_in_the_fixed_limit(e, direction, contact, noise):
    closed = float(exact_ideal_delta(PAPER, e, contact, noise / 10.0, direction=direction))
    covered = 0
    for seed in range(6):
        r = mc_ideal_delta(ObjectClass("r", (e, e + 80.0)), direction, PAPER, contact_s=contact, noise_c=noise,
                           delta_t_c=10.0, sensor_temp_spread_c=1e-5, n_mc=1000, seed=seed)
        assert r.coverage == 0.9 and r.low <= r.value <= r.high
        covered += r.low <= closed <= r.high
        assert abs(r.value - closed) <= 2.0 * (r.high - r.low)  # about 3 SDs
    assert covered >= 4


def test_the_interval_narrows_with_the_asked_coverage_on_the_same_evaluations():
    kw = dict(noise_c=0.05, delta_t_c=7.5, sensor_temp_spread_c=2.5, n_mc=1000, seed=0)
    a, b = ObjectClass("a", (20000.0, 20080.0)), ObjectClass("b", (35000.0, 35080.0))
    wide = mc_ideal_min_contact(a, b, PAPER, coverage=0.99, **kw)
    narrow = mc_ideal_min_contact(a, b, PAPER, coverage=0.5, **kw)
    assert wide.evaluations == narrow.evaluations and wide.value == narrow.value
    assert wide.low <= narrow.low <= narrow.value <= narrow.high <= wide.high
    assert wide.high - wide.low > narrow.high - narrow.low


def test_a_pair_the_ideal_observer_cannot_separate_in_time_gets_no_bound():
    r = mc_ideal_min_contact(ObjectClass("a", (20000.0, 20080.0)), ObjectClass("b", (20100.0, 20180.0)), PAPER,
                             noise_c=0.1, delta_t_c=7.5, sensor_temp_spread_c=2.5, n_mc=200, max_contact_s=2.0)
    assert r.value is None and r.low is None and r.high is None and r.coverage is None
    assert r.evaluations and r.evaluations[-1]["f1"] < 0.9


def test_the_varied_table_computes_its_bound_at_query_time_not_from_its_grid():
    a = q.min_contact(35000, 20000, noise_c=0.05, delta_t_c=7.5, sensor_temp_spread_c=2.5)
    assert a.table == VARIED_TABLE and a.ideal_bound.method == "monte-carlo"
    low, high, cov = a.ideal_bound.interval
    assert cov == 0.9 and low <= a.ideal <= high
    mc = remembered(mc_ideal_min_contact, ObjectClass("a", (20000.0, 20080.0)), ObjectClass("b", (35000.0, 35080.0)),
                    PAPER, noise_c=0.05, delta_t_c=7.5, sensor_temp_spread_c=2.5)
    assert a.ideal == mc.value
    # the grid's own bound is kept beside it, and it is not the answer (the grid put it 0.2 s early)
    assert a.computation["table_ideal_s"] != a.ideal
    d = a.to_dict()["ideal"]
    assert d["interval"] == {"low": low, "high": high, "coverage": 0.9}
    # the SVM's interval never reaches below the bound's low end
    assert a.interval[0] >= low


def test_closed_form_bounds_carry_no_interval():
    d = q.min_contact(35000, 20000, noise_c=0.05, delta_t_c=10.0).to_dict()["ideal"]
    assert d["method"] == "closed-form" and "interval" not in d


def test_array_questions_get_the_same_monte_carlo_bound():
    arr = q.min_contact([35000, 30000], 20000, noise_c=0.05, delta_t_c=7.5, sensor_temp_spread_c=2.5)
    one = q.min_contact(30000, 20000, noise_c=0.05, delta_t_c=7.5, sensor_temp_spread_c=2.5)
    assert float(arr.ideal[1]) == one.ideal
    nan_is_none = lambda v: None if v != v else float(v)  # noqa: E731
    assert (nan_is_none(arr.low[1]), nan_is_none(arr.high[1])) == one.interval


@pytest.mark.slow
def test_the_cli_prints_the_bounds_interval():
    r = subprocess.run([sys.executable, "-m", "designkit", "min-contact", "--e1", "35000", "--e2", "20000",
                        "--delta-t", "7.5", "--sensor-temp-spread", "2.5"], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    line = next(x for x in r.stdout.splitlines() if "ideal observer bound" in x)
    assert "monte-carlo, 90% interval" in line and "no classifier does better" in line
    r = subprocess.run([sys.executable, "-m", "designkit", "min-contact", "--e1", "35000", "--e2", "20000",
                        "--delta-t", "7.5", "--sensor-temp-spread", "2.5", "--coverage", "0.8", "--json"],
                       capture_output=True, text=True, timeout=120)
    assert json.loads(r.stdout)["ideal"]["interval"]["coverage"] == 0.8


def test_the_varied_tables_delta_e_bound_is_monte_carlo_per_direction():
    a = q.delta_e(20000, contact_s=2.0, noise_c=0.05, delta_t_c=7.5, sensor_temp_spread_c=2.5)
    assert a.table == VARIED_TABLE and a.ideal_bound.method == "monte-carlo"
    ref = ObjectClass("r", (20000.0, 20080.0))
    for side, direction in (("lower", -1), ("upper", +1)):
        s = a.details[side]
        mc = mc_ideal_delta(ref, direction, PAPER, contact_s=2.0, noise_c=0.05, delta_t_c=7.5,
                            sensor_temp_spread_c=2.5)
        assert s["ideal"] == mc.value and s["ideal_interval"] == [mc.low, mc.high]
        # the grid's arrays hold an oracle's floor (told each touch's Ts0): below the varied observer's need
        assert s["table_ideal"] < mc.low
        assert s["interval"][0] >= mc.low and s["value"] >= s["ideal"]
    low, high, cov = a.ideal_bound.interval
    assert a.ideal == min(a.details["lower"]["ideal"], a.details["upper"]["ideal"]) and low <= a.ideal <= high


def test_array_delta_e_gets_the_same_monte_carlo_bound():
    arr = q.delta_e([20000, 10000], contact_s=2.0, noise_c=0.05, delta_t_c=7.5, sensor_temp_spread_c=2.5)
    one = q.delta_e(10000, contact_s=2.0, noise_c=0.05, delta_t_c=7.5, sensor_temp_spread_c=2.5)
    assert float(arr.ideal[1]) == one.ideal and float(arr.value[1]) == one.value
    assert (float(arr.low[1]), float(arr.high[1])) == one.interval


def test_the_monte_carlo_max_ratio_lands_on_the_closed_form_in_the_fixed_limit():
    from designkit import Scene
    from designkit.query.ideal_bound import exact_ideal_max_ratio
    from designkit.query.ideal_mc_bound import mc_ideal_max_ratio

    closed = float(exact_ideal_max_ratio(PAPER, 20000.0, 35000.0, 2.0, width=80.0, threshold=0.9))
    a, b = ObjectClass("a", (20000.0, 20080.0)), ObjectClass("b", (35000.0, 35080.0))
    covered = 0
    for seed in range(6):
        r = mc_ideal_max_ratio(a, b, PAPER, lambda x: Scene.from_delta_t(
            contact_s=2.0, noise_c=x * 10.0, delta_t_c=10.0, sensor_temp_spread_c=1e-5), 1e-4, 1.0, n_mc=1000,
            seed=seed)
        assert r.coverage == 0.9 and r.low <= r.value <= r.high
        covered += r.low <= closed <= r.high
        assert abs(r.value - closed) <= 2.0 * (r.high - r.low)
    assert covered >= 4


@pytest.mark.parametrize("question", ["max-noise", "min-delta-t"])
def test_the_exact_ratio_questions_with_a_spread_carry_the_bounds_interval(question):
    kw = dict(contact_s=2.0, sensor_temp_spread_c=2.5, exact=True, solver="batched")
    if question == "max-noise":
        a = q.max_noise(35000, 20000, delta_t_c=7.5, **kw)
        low, high, cov = a.ideal_bound.interval
        assert a.value <= a.ideal and a.interval[1] <= high  # nobody tolerates more noise than the ideal observer
    else:
        a = q.min_delta_t(35000, 20000, noise_c=0.05, **kw)
        low, high, cov = a.ideal_bound.interval
        assert a.value >= a.ideal and a.interval[0] >= low  # nobody needs a smaller dT than the ideal observer
    assert a.ideal_bound.method == "monte-carlo" and cov == 0.9 and low <= a.ideal <= high
