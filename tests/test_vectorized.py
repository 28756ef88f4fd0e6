"""Array calls of the design questions (issue 16): broadcasting like numpy, element i equal to the scalar call."""

from __future__ import annotations

import math

import numpy as np
import pytest

from designkit._validation import InputError
from designkit.query import ArrayAnswer, ask, delta_e, distinguishable, max_noise, min_contact, min_delta_t
from designkit.query.ideal_bound import clear_bound_cache, pair_critical_noise
from designkit.recognition.ideal import critical_noise
from designkit.sensor import load_sensor


def _num(v):
    return math.nan if v is None else float(v)


def _same(a, b, rtol):
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return math.isclose(a, b, rel_tol=rtol, abs_tol=1e-12)


RNG = np.random.default_rng(16)
# effusivities inside the shipped grids, plus one below and one above them (no answer there)
E1 = np.concatenate([RNG.uniform(500, 39000, 7), [-0.0 + 10.0, 45000.0]])


@pytest.mark.parametrize("table", ["svm-paper", "ideal-paper"])
def test_min_contact_broadcasts_each_scene_read_as_if_asked_alone(table):
    """One array call reads each distinct scene once for all its pairs: an element answers what it answers
    asked alone (a single answer is element 0 of a one-element call), whatever else is in the call."""
    e1 = E1[:, None]                              # (9, 1)
    e2 = np.array([[3000.0, 21000.0, 36000.0]])   # (1, 3)
    noise = np.array([0.05, 0.1, 0.05])            # (3,): the last scene a grid point, one between
    a = min_contact(e1, e2, noise_c=noise, delta_t_c=10.0, table=table)
    assert isinstance(a, ArrayAnswer) and a.shape == (9, 3) and a.unit == "s"
    assert np.isfinite(a.value).sum() >= 8 and not a.in_grid[-1].any()
    for idx in ((0, 0), (3, 1), (5, 2)):
        one = min_contact(float(E1[idx[0]]), float(e2[0, idx[1]]), noise_c=float(noise[idx[1]]), table=table)
        assert _same(float(a.value[idx]), _num(one.value), 1e-12) and _same(float(a.low[idx]), _num(one.interval[0]), 1e-12)
        assert _same(float(a.coverage[idx]), _num(one.interval_coverage), 1e-12)


def test_ratio_delta_e_and_distinguishable_arrays_hold_their_own_rules():
    e1, e2 = E1[:6], np.array([[21000.0], [9000.0]])
    contact = np.array([1.0, 1.7, 4.0, 2.0, 10.0, 0.3])  # grid points, between, and one below the grid
    a = max_noise(e1, e2, contact_s=contact, delta_t_c=np.array([[10.0], [-5.0]]))
    assert a.shape == (2, 6) and a.quantity == "noise_c" and not a.in_grid[:, -1].any()
    ok = np.isfinite(a.value) & np.isfinite(a.ideal)
    assert ok.sum() >= 4 and np.all(a.value[ok] <= a.ideal[ok] * (1 + 1e-12))  # no classifier beats the bound
    b = min_delta_t(e1, e2, contact_s=contact, noise_c=0.02)
    ok = np.isfinite(b.value) & np.isfinite(b.ideal)
    assert ok.sum() >= 4 and np.all(b.value[ok] >= b.ideal[ok] * (1 - 1e-12))
    d = distinguishable(e1, 21000.0, contact_s=np.array([[1.0], [2.5]]), noise_c=0.05, delta_t_c=10.0)
    assert set(np.unique(d.value[np.isfinite(d.value)])) <= {0.0, 1.0}
    m = d.details["min_contact_s"]  # the verdict is the contact against min-contact's answer
    sure = np.isfinite(m) & ~((d.details["min_contact_low"] <= np.array([[1.0], [2.5]]))
                              & (np.array([[1.0], [2.5]]) <= d.details["min_contact_high"]))
    assert np.array_equal(d.value[sure], (np.broadcast_to([[1.0], [2.5]], m.shape)[sure] >= m[sure]).astype(float))
    de = delta_e(E1, contact_s=np.array([[1.0], [3.3]]), noise_c=0.05)
    assert de.shape == (2, 9) and set(de.details) == {"lower", "upper", "lower_ideal", "upper_ideal", "lower_low",
                                                      "lower_high", "upper_low", "upper_high"}
    assert np.array_equal(de.value, np.fmin(de.details["lower"], de.details["upper"]), equal_nan=True)
    one = delta_e(float(E1[2]), contact_s=3.3, noise_c=0.05)
    assert _same(float(de.value[1, 2]), _num(one.value), 1e-12)


def test_lists_and_materials_and_exact_route_loop_over_scalar_calls():
    a = min_contact([35000, 30000], 20000)                 # a list is an array
    assert a.shape == (2,) and a.value[0] == min_contact(35000, 20000).value
    m = ask("max-noise", m1="copper", m2="wood", contact_s=[1.0, 2.0])  # names: one scalar call per element
    assert m.shape == (2,)
    for i, c in enumerate((1.0, 2.0)):
        assert _same(float(m.value[i]), _num(max_noise(m1="copper", m2="wood", contact_s=c).value), 1e-12)


def test_lists_of_material_names_broadcast_like_numbers():
    """The README's library call: lists of names answer one element per pair (issue 33), names and numbers
    broadcast together, element i the single call's answer."""
    a = min_contact(m1=["copper", "glass"], m2=["wood", "PVC"])
    assert isinstance(a, ArrayAnswer) and a.shape == (2,)
    for i, (m1, m2) in enumerate((("copper", "wood"), ("glass", "PVC"))):
        one = min_contact(m1=m1, m2=m2)
        assert float(a.value[i]) == one.value and float(a.low[i]) == one.interval[0]
    b = min_contact(m1=["copper", "glass"], m2="wood", noise_c=[[0.02], [0.05]])
    assert b.shape == (2, 2) and float(b.value[1, 1]) == min_contact(m1="glass", m2="wood", noise_c=0.05).value
    d = delta_e(m=["wood", "glass"], contact_s=2.0)
    assert d.shape == (2,) and float(d.value[1]) == delta_e(m="glass", contact_s=2.0).value
    with pytest.raises(InputError, match=r"m1\[1\] must be a name"):
        min_contact(m1=["copper", 3], m2="wood")
    with pytest.raises(InputError, match="do not broadcast"):
        min_contact(m1=["copper", "glass", "wood"], m2=["wood", "PVC"])


def test_bad_elements_are_named():
    with pytest.raises(InputError, match=r"e1\[2\] must be positive, got -5"):
        min_contact(np.array([35000.0, 30000.0, -5.0]), 20000)
    with pytest.raises(InputError, match=r"contact_s\[1, 0\]"):
        max_noise(35000, 20000, contact_s=np.array([[1.0], [np.nan]]))
    with pytest.raises(InputError, match=r"delta_t_c\[1\] is 0"):
        min_contact(35000, 20000, delta_t_c=[10.0, 0.0])
    with pytest.raises(InputError, match=r"equal at index \[1\]"):
        min_contact([35000, 20000], [20000, 20000])
    with pytest.raises(InputError, match="do not broadcast"):
        min_contact(np.ones(3) * 30000, np.ones(2) * 20000)
    with pytest.raises(InputError, match="numbers"):
        min_contact(["a", "b"], 20000)
    with pytest.raises(InputError, match="ideal_bound=False is for array inputs"):
        min_contact(35000, 20000, ideal_bound=False)


def test_ideal_bound_false_skips_the_bound_only():
    e1 = np.linspace(21000, 39000, 5)
    with_bound = min_contact(e1, 20000)
    without = min_contact(e1, 20000, ideal_bound=False)
    assert np.isnan(without.ideal).all() and np.array_equal(with_bound.value, without.value, equal_nan=True)


def test_bound_cache_returns_what_a_computation_returns():
    s = load_sensor("paper")
    lo, hi = np.array([20000.0, 9000.0, 20000.0]), np.array([35000.0, 9500.0, 35000.0])
    clear_bound_cache()
    first = pair_critical_noise(s, lo, hi)
    again = pair_critical_noise(s, lo[::-1], hi[::-1])  # hits, another order
    alone = [float(critical_noise(s, a, b)) for a, b in zip(lo, hi)]
    assert first.tolist() == alone and again.tolist() == alone[::-1]


def test_to_dict_is_json_ready():
    import json

    a = min_contact(np.array([35000.0, 45000.0]), 20000)
    d = json.loads(json.dumps(a.to_dict()))  # one record per element (docs/schema.md, "Records")
    assert len(d) == 2 and d[1]["value"] is None and d[0]["unit"] == "s" and d[0]["value"] > 0


def test_matrix_prefilled_bounds_equal_the_per_pair_bounds():
    from designkit.query.ideal_bound import clear_bound_cache
    from designkit.query.matrix import material_matrix

    clear_bound_cache()
    m = material_matrix(["copper", "glass", "wood", "granite"], multiclass=False)
    clear_bound_cache()
    for c in m.cells:
        if c.answer.limiting_pair:
            one = min_contact(m1=m.materials[c.i].qualified_name, m2=m.materials[c.j].qualified_name)
            clear_bound_cache()
            assert _same(_num(c.ideal), _num(one.ideal_bound.value), 0.0)
