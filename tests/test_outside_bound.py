"""Bounds at the edges: outside a table's grid, and above a search's bracket.

A question outside a table's grid: no SVM answer, but the ideal observer's bound where it has a closed form.

The table cannot answer outside its axes (nothing is extrapolated), but the ideal observer's
bound needs no table where its F1 has a closed form. Each bound is checked here against its
definition on the ideal observer's F1 (computed by :func:`designkit.recognition.ideal.ideal_pair`,
the closed form's public entry), not against the function that produced it; the array route
must give the scalar route's values; and a table without a closed form leaves the bound out.
"""

from __future__ import annotations

import numpy as np
import pytest

from designkit import query
from designkit.recognition.ideal import ideal_pair
from designkit.scene import Scene
from designkit.sensor import SENSORS

PAPER = SENSORS["paper"]
W = 80.0  # the shipped tables' class width (500 intervals over 40,000)


def _ideal_f1(lo, hi, contact, noise, dt=10.0):
    scene = Scene.from_delta_t(contact_s=contact, noise_c=noise, delta_t_c=dt)
    return ideal_pair((lo, lo + W), (hi, hi + W), PAPER, scene).f1


def test_min_contact_outside_the_noise_axis_states_the_closed_form_bound():
    a = query.min_contact(35000, 20000, noise_c=1.0, delta_t_c=10.0)  # sigma/dT 0.1, the table stops at 0.05
    assert a.value is None and a.in_grid["noise_ratio"] is False
    t = a.ideal_bound.value
    assert a.ideal_bound.method == "closed-form" and t is not None
    # the first sample time at which the ideal observer separates them (200 Hz)
    assert _ideal_f1(20000, 35000, t, 1.0) >= 0.9 > _ideal_f1(20000, 35000, t - 1 / PAPER.sample_rate_hz, 1.0)


def test_max_noise_and_min_delta_t_outside_the_contact_axis_state_the_bound():
    mn = query.max_noise(35000, 20000, contact_s=20.0, delta_t_c=10.0)  # the table stops at 10 s
    assert mn.value is None and mn.in_grid["contact_s"] is False and mn.ideal_bound.method == "closed-form"
    noise = mn.ideal_bound.value
    assert _ideal_f1(20000, 35000, 20.0, noise * 0.999) >= 0.9 > _ideal_f1(20000, 35000, 20.0, noise * 1.001)
    dt = query.min_delta_t(35000, 20000, contact_s=20.0, noise_c=0.05).ideal_bound.value
    assert _ideal_f1(20000, 35000, 20.0, 0.05, dt * 1.001) >= 0.9 > _ideal_f1(20000, 35000, 20.0, 0.05, dt * 0.999)


def test_delta_e_outside_the_contact_axis_states_both_sides_bounds():
    d = query.delta_e(20000, contact_s=20.0, noise_c=0.05, delta_t_c=10.0)
    assert d.value is None and d.in_grid["contact_s"] is False
    lower, upper = d.details["lower"]["ideal"], d.details["upper"]["ideal"]
    assert d.ideal_bound.value == min(lower, upper) and d.ideal_bound.method == "closed-form"
    # the reference class [20000, 20080) against one whose lower edge lies delta away (bisected to 0.5)
    assert _ideal_f1(20000, 20000 + upper + 0.5, 20.0, 0.05) >= 0.9 > _ideal_f1(20000, 20000 + upper - 1.0, 20.0, 0.05)
    assert _ideal_f1(20000 - lower - 0.5, 20000, 20.0, 0.05) >= 0.9 > _ideal_f1(20000 - lower + 1.0, 20000, 20.0, 0.05)
    # a reference outside the table's effusivity range: the range bounds the search, so no bound is stated
    far = query.delta_e(50000, contact_s=2.0)
    assert far.ideal_bound.value is None and far.details["upper"]["ideal"] is None


def test_distinguishable_outside_states_the_ideal_f1():
    d = query.distinguishable(35000, 20000, contact_s=20.0)
    assert d.value is None and d.details["distinguishable"] is None
    assert d.details["ideal_f1"] == pytest.approx(_ideal_f1(20000, 35000, 20.0, 0.05), abs=1e-9)
    assert d.details["ideal_distinguishable"] is True


def test_the_array_route_states_the_bounds_outside_the_grid():
    e2 = np.array([20000.0, 25000.0, 20000.0])
    noise = np.array([1.0, 0.05, 2.0])  # outside, inside, outside the noise axis
    arr = query.min_contact(35000, e2, noise_c=noise)
    assert arr.in_grid.tolist() == [False, True, False] and np.isnan(arr.value[[0, 2]]).all()
    # the closed form needs no table: 7.22 s at 1 degC; none within its 10 s at 2 degC
    assert arr.ideal[0] == pytest.approx(7.22, rel=0.01) and np.isnan(arr.ideal[2])
    contact = np.array([20.0, 2.0, 15.0])
    for ask, kw in ((query.max_noise, {}), (query.min_delta_t, {"noise_c": 0.05}), (query.distinguishable, {})):
        arr = ask(35000, e2, contact_s=contact, **kw)
        assert arr.in_grid.tolist() == [False, True, False] and np.isfinite(arr.ideal).all()
    arr = query.delta_e(np.array([20000.0, 20000.0]), contact_s=np.array([20.0, 2.0]), noise_c=np.array([0.05, 1.0]))
    assert not arr.in_grid.any() and np.isfinite(arr.ideal).all()


def test_without_a_closed_form_the_bound_is_left_out_as_the_answer_is():
    # the varied table (the sensor temperature drawn per touch): its bound would be a Monte Carlo run
    # (route="table": the varied table holds dT 7.5 degC only, so the default route computes dT 10 for the pair)
    a = query.min_contact(35000, 20000, noise_c=1.0, sensor_temp_spread_c=2.5, route="table")
    assert a.table == "svm-paper-varied" and a.value is None
    assert a.ideal_bound.value is None and a.ideal_bound.method == "none"


def test_the_cli_prints_the_bound_and_still_exits_3(cli):
    r = cli("min-contact", "--e1", "35000", "--e2", "20000", "--noise", "1")
    assert r.exit_code == 3
    assert "no answer" in r.output and "(closed-form; no classifier does better)" in r.output
    r = cli("distinguishable", "--e1", "35000", "--e2", "20000", "--contact", "20")
    assert r.exit_code == 3 and "ideal observer bound: F1 1.000 (closed-form)" in r.output
    r = cli("delta-e", "--e", "20000", "--contact", "20")
    assert r.exit_code == 3 and "outside table svm-fine's" in r.output.splitlines()[3]
    r = cli("delta-e", "--e", "20000", "--contact", "20", "--explain")
    assert r.exit_code == 3 and "no answer from the table, or" in r.output


def test_the_exact_route_searches_up_to_the_ideal_bound_above_its_bracket():
    """At 10 s the ideal observer separates 500 from 39,000 up to sigma/dT 4.6: the SVM's max-noise is searched
    below that, not cut at the bracket's sigma/dT 1 (10 degC at dT 10, where the answer was the bracket's end)."""
    from designkit.query import exact_max_noise

    a = exact_max_noise(500, 39000, contact_s=10.0, delta_t_c=10.0, trials=30, repeats=1, jobs=1)
    assert a.ideal_bound.value == pytest.approx(46.4, rel=0.01)
    assert 10.0 < a.value < a.ideal_bound.value
    assert a.interval[1] <= a.ideal_bound.value  # the interval is held to the bound, as below the bracket


@pytest.mark.parametrize("contact", [1e4, 1e30])
def test_beyond_the_closed_forms_sample_limit_the_bound_is_left_out_not_an_error(contact):
    """A touch of more than 1e6 samples (every route's limit) is outside the table and beyond what the closed
    form computes: the answer stays "outside" with no bound, on both routes (an absurd contact once reached the
    sample-index arithmetic and failed inside it)."""
    for ask, kw in ((query.max_noise, {}), (query.min_delta_t, {"noise_c": 0.05}), (query.distinguishable, {})):
        a = ask(35000, 20000, contact_s=contact, **kw)
        assert a.value is None and a.in_grid["contact_s"] is False and a.ideal_bound.value is None
        arr = ask(35000, np.array([20000.0, 20000.0]), contact_s=np.array([contact, 2.0]), **kw)
        assert np.isnan(arr.ideal[0]) and np.isfinite(arr.ideal[1])
    d = query.delta_e(20000, contact_s=contact)
    assert d.value is None and d.ideal_bound.value is None
    assert np.isnan(query.delta_e(np.array([20000.0]), contact_s=np.array([contact])).ideal[0])


def test_a_noiseless_or_instant_touch_answers_without_numpy_warnings():
    """sigma 0 or a contact before the second sample: the closed form's noise per unit signal is 0/0 there;
    the answer says 'no information yet' without a RuntimeWarning reaching the caller."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert query.min_contact(35000, 20000, noise_c=0.0).ideal_bound.value == pytest.approx(0.005)
        d = query.delta_e(20000, contact_s=1e-6, noise_c=0.0)
        assert d.value is None and d.ideal_bound.value is None
