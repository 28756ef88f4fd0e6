"""The coverage machinery (designkit_lab.accuracy.coverage, issue 13): small seeded runs, real code paths.

The full benchmark (100 cases per question) is benchmarks/bench_coverage.py; here: the crossing
estimator covers a known truth near nominal, the ideal bound is never above the exact ideal
observer, the stated intervals have the schema and bad coverage is refused.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from designkit import query
from designkit._validation import InputError
from designkit_lab.accuracy.coverage import coverage_case, diluted_coverage, draw_case, summarize, synthetic_coverage
from designkit.query.crossing import estimate_crossing
from designkit.query.ideal_bound import exact_ideal_max_ratio, exact_ideal_min_contact
from designkit.recognition.ideal import ideal_pair
from designkit.objects import ObjectClass
from designkit.scene import Scene
from designkit.sensor import load_sensor


def test_synthetic_curves_are_covered_near_nominal():
    # known truth: the crossing of a logistic-in-log-x curve with the SVM's binomial noise
    s = synthetic_coverage(200, seed=11)
    assert s["none"] == 0
    assert 0.85 <= s["coverage"] <= 0.97, s
    assert s["median_rel"] < 0.05, s


@pytest.mark.parametrize("increasing", [True, False])
def test_independent_points_cover_and_common_random_numbers_do_not(increasing):
    # issue 13's root cause on a known truth: the fit assumes independent design points. Rising (contact,
    # delta-e) and falling (sigma/dT) curves alike are covered near nominal when they are; with the
    # seed-to-seed correlation the exact route once had between neighbouring points (~0.85 on the
    # sigma/dT and delta-e axes) the stated intervals are too narrow: 1.7x and ~68 % covered with the straight-line
    # fit, 1.2x and 82-84 % with the curvature fit (issue 34; its interval is never narrower than the line's,
    # whose lack of fit the correlated draws inflate), against 0.9x and 92-93 % for independent points
    ok = synthetic_coverage(300, seed=21, increasing=increasing)
    assert ok["none"] == 0 and 0.85 <= ok["coverage"] <= 0.97, ok
    assert 0.8 <= ok["z_sd"] <= 1.15, ok
    crn = synthetic_coverage(300, seed=21, increasing=increasing, correlation=0.85)
    assert crn["coverage"] < ok["coverage"] - 0.05 and crn["z_sd"] > 1.15, crn


def test_exact_route_draws_fresh_touches_at_every_evaluation():
    # the same scene asked twice within one question is two independent Monte Carlo estimates (no common
    # random numbers across a crossing's design points), and a question is still reproducible from its seed
    from designkit.query.exact import _Run

    def run():
        return _Run.make(sensor=None, model=None, threshold=0.9, width=80.0, trials=30, folds=3, seed=4, repeats=2,
                         z=2.0, jobs=1, n_mc=10, solver="batched")

    a, b = ObjectClass("a", (20000.0, 20080.0)), ObjectClass("b", (35000.0, 35080.0))
    scene = Scene.from_delta_t(contact_s=1.0, noise_c=0.004, delta_t_c=1.0)
    r1 = run()
    first, second = r1.svm((a, b), scene), r1.svm((a, b), scene)
    assert first != second
    r2 = run()
    assert (r2.svm((a, b), scene), r2.svm((a, b), scene)) == (first, second)


def test_decreasing_curve_crossing_and_its_ends():
    f = lambda x: (0.5 + 0.5 / (1.0 + (x / 0.01) ** 4.0), 0.004)  # noqa: E731 - falls with x, 0.9 at ~0.0063
    truth = 0.01 * (1 / 4) ** 0.25
    est = estimate_crossing(f, 1e-5, 1.0, 0.9, increasing=False)
    assert est.method == "wls-logit-log"
    assert est.low < truth < est.high and abs(est.value - truth) / truth < 0.02
    # reaches the threshold even at the top of the range: the answer is at least x_hi, open above
    est = estimate_crossing(lambda x: (1.0, 0.004), 1e-5, 1.0, 0.9, increasing=False)
    assert (est.value, est.low, est.high) == (1.0, 1.0, None)
    est = estimate_crossing(lambda x: (0.6, 0.004), 1e-5, 1.0, 0.9, increasing=False)
    assert est.value is None


@pytest.mark.parametrize("increasing", [True, False])
def test_a_steep_curve_is_bracketed_around_its_crossing_not_answered_by_the_coarse_brackets_middle(increasing):
    """F1 jumps from 0.84 to 1 over a few percent of x (a pair of very different materials at short contacts):
    too few points are informative for the fit. The answer was the middle of the coarse bracket (0.5 s for a
    crossing at 0.43 s); now the bracket is narrowed around the crossing, to at most fine_ratio."""
    truth, k = 0.43, 40.0

    def f(x):  # the fit's own family (logit linear in log x), so steep that F1 is 0.5 or 1 a few % away
        r = x / truth if increasing else truth / x
        return (0.5 + 0.5 / (1.0 + 0.25 * r ** -k), 0.005)  # 0.9 at the truth

    est = estimate_crossing(f, 0.41, 10.0, 0.9, increasing=increasing)
    assert est.low <= truth <= est.high, (est.low, est.high)
    assert abs(est.value - truth) / truth < 0.03
    if est.method == "bracket":
        assert est.high / est.low <= 1.05 + 1e-12


def test_a_nearly_flat_noisy_curve_gives_an_interval_clipped_to_the_range_not_an_overflow():
    """F1 creeps through 0.9 with standard errors of 0.2 (a few seeds on a flat curve): the fit's interval
    spans hundreds of e-folds of x; exp() of its ends overflowed (OverflowError) instead of answering."""
    import math

    est = estimate_crossing(lambda x: (0.9 + 1e-4 * math.log(x), 0.2), 1e-3, 1e3, 0.9)
    assert est.method == "wls-logit-log"
    assert 1e-3 <= est.low <= est.value <= est.high <= 1e3
    assert (est.low, est.high) == (1e-3, 1e3)  # the data say nothing: the whole range examined

def test_ideal_bound_never_above_the_exact_ideal_observer():
    # the query-time bound (math.erfc closed form) against an independent bisection on the scipy closed form
    sensor = load_sensor("paper")
    rng = np.random.default_rng(5)
    for _ in range(4):
        lo = float(rng.uniform(200, 30000))
        hi = lo + float(rng.uniform(400, 8000))
        ratio = float(rng.choice([0.001, 0.005, 0.01]))
        t = exact_ideal_min_contact(sensor, lo, hi, ratio, width=80.0)
        a, b = ObjectClass("a", (lo, lo + 80)), ObjectClass("b", (hi, hi + 80))

        def f1(c):
            return ideal_pair(a, b, sensor, Scene.from_delta_t(contact_s=c, noise_c=ratio, delta_t_c=1.0)).f1

        # the bound's contact reaches 0.9; 2 % less does not (it is the shortest, not just a short one)
        assert f1(float(t)) >= 0.9 - 1e-6
        assert f1(float(t) * 0.98) < 0.9
        r = exact_ideal_max_ratio(sensor, lo, hi, 2.0, width=80.0)
        f_r = ideal_pair(a, b, sensor, Scene.from_delta_t(contact_s=2.0, noise_c=float(r), delta_t_c=1.0)).f1
        assert f_r >= 0.9 - 1e-6


def test_one_case_of_each_route_states_its_interval():
    # tiny but real: 30 touches, 2 seeds against 4, batched reference
    rng = np.random.default_rng(3)
    case = draw_case("max-noise", rng)
    case.update(e1=30000.0, e2=12000.0, gap=18000.0, contact_s=2.0)
    r = coverage_case("max-noise", case, 0, repeats=2, ref_repeats=4, trials=30)
    for route in ("exact", "reference"):
        assert r[route]["coverage"] == 0.9 and r[route]["low"] < r[route]["value"] < r[route]["high"]
        assert r[route]["value"] <= r[route]["ideal"]  # the SVM tolerates no more noise than the ideal observer
    assert r["violation"] is False
    s = summarize([r], "max-noise", "exact")
    assert s["n_compared"] == 1 and s["violations"] == 0


def test_a_varied_case_asks_every_route_with_the_spread():
    """``sensor_temp_spread_c`` reaches the table (a varied table's answer) and both exact routes: their
    ideal bounds are the Monte Carlo observer's, later than the closed form's at fixed conditions."""
    case = {"e1": 1000.0, "e2": 600.0, "gap": 400.0, "noise_c": 0.05, "delta_t_c": 7.5, "contact_s": 1.0}
    r = coverage_case("min-contact", case, 0, repeats=2, ref_repeats=2, trials=30, table="svm-paper-varied",
                      sensor_temp_spread_c=2.5)
    fixed = query.ask("min-contact", route="table", e1=1000.0, e2=600.0, noise_c=0.05, delta_t_c=7.5).ideal
    for route in ("table", "exact", "reference"):
        assert r[route]["ideal"] > fixed, (route, r[route]["ideal"], fixed)
    # the varied table's min-contact estimate states its coverage (measured: bench_coverage_varied.py)
    assert r["table"]["method"] == "table-varied-estimate" and r["table"]["coverage"] == 0.9
    assert r["exact"]["coverage"] == 0.9


def test_stated_interval_schema_and_refusals():
    a = query.ask("min-contact", route="table", e1=3000, e2=1500)
    iv = a.to_dict()["interval"]
    assert set(iv) >= {"low", "high", "coverage", "method"}
    assert iv["method"] == "table-efficiency" and iv["coverage"] == 0.9
    assert iv["low"] < a.value < iv["high"] and iv["low"] >= a.ideal
    # wider for a higher coverage
    wide = query.ask("min-contact", route="table", e1=3000, e2=1500, coverage=0.99).interval
    assert wide[0] < iv["low"] and wide[1] > iv["high"]
    # the guideline pair's crossing follows a 'beyond the grid' neighbour: interpolation cannot state a
    # coverage there (the cell), the efficiency against the exact ideal observer can
    g = query.ask("min-contact", route="table", e1=35000, e2=20000)
    assert g.interval_kind == "table-efficiency" and g.interval_coverage == 0.9
    assert g.ideal <= g.interval[0] < g.value < g.interval[1] < g.computation["table_crossing_s"]
    # an ideal-observer table has no efficiency: the cell, coverage not stated
    c = query.ask("min-contact", route="table", e1=35000, e2=20000, table="ideal-paper").to_dict()["interval"]
    assert c["method"] in ("table-cell", "table-estimate") and (c["coverage"] is None) == (c["method"] == "table-cell")
    for bad in (0.0, 1.0, -0.1, 1.5, math.nan):
        with pytest.raises(InputError, match="coverage"):
            query.ask("min-contact", route="table", e1=3000, e2=1500, coverage=bad)


def test_calibration_z_is_one_for_calibrated_intervals_whatever_the_reference_error():
    # records drawn with known errors: answers' log-sd 0.05, references' 0.025 (a 4x-seeds reference);
    # coverage against the reference is diluted (~86 %), the z spread is not
    from designkit_lab.accuracy.coverage import calibration_z

    rng = np.random.default_rng(8)
    z90 = 1.6448536269514722

    def reading(truth, sd, s_true):
        v = truth * math.exp(s_true * rng.standard_normal())
        return {"value": v, "low": v * math.exp(-z90 * sd), "high": v * math.exp(z90 * sd), "coverage": 0.9}

    def records(s_answer):
        return [{"question": "max-noise", "exact": reading(t, 0.05, s_answer), "reference": reading(t, 0.025, 0.025)}
                for t in np.exp(rng.uniform(-5, 0, 3000))]

    ok = records(0.05)
    assert np.std(calibration_z(ok, "max-noise")) == pytest.approx(1.0, abs=0.05)
    assert summarize(ok, "max-noise", "exact")["coverage"] == pytest.approx(diluted_coverage(0.9, 0.5), abs=0.02)
    narrow = records(0.1)  # the answer's real spread twice what its interval states
    assert np.std(calibration_z(narrow, "max-noise")) > 1.6


def test_diluted_coverage():
    assert diluted_coverage(0.9, 0.0) == pytest.approx(0.9)
    assert diluted_coverage(0.9, 0.5) < 0.9


def test_normal_quantile_of_the_query_path_against_the_standard_library():
    from statistics import NormalDist

    from designkit.query.crossing import z_of_coverage

    for c in (0.5, 0.8, 0.9, 0.95, 0.99, 0.999):
        assert z_of_coverage(c) == pytest.approx(NormalDist().inv_cdf(0.5 + 0.5 * c), rel=1e-12)


def test_worst_regions_group_continuous_noise_by_band():
    from designkit_lab.accuracy.coverage import worst_regions

    def case(noise, e2, value, ref, cov=0.9):
        return {"question": "min-contact", "noise_c": noise, "e2": e2,
                "table": {"value": value, "low": value * 0.9, "high": value * 1.1, "coverage": cov},
                "reference": {"value": ref}}
    results = [case(0.012, 500.0, 1.0, 1.0), case(0.018, 900.0, 1.2, 1.0), case(0.03, 500.0, 2.0, 1.0),
               case(0.07, 30000.0, 1.0, 1.0)]
    got = worst_regions(results, "min-contact", "table", noise_bands=((0.01, 0.02), (0.02, 0.05), (0.05, 0.1)))
    assert [(g["noise_band"], g["e_band"], g["n"]) for g in got] == [
        ([0.02, 0.05], [0, 2000], 1), ([0.01, 0.02], [0, 2000], 2), ([0.05, 0.1], [20000, 40000], 1)]
    assert got[1]["median_rel"] == pytest.approx(0.1) and got[1]["coverage"] == 0.5  # 1.2 vs 1: not inside
    # the fixed levels as before (no case at exactly 0.01, 0.05 or 0.1 here)
    assert worst_regions(results, "min-contact", "table") == []
