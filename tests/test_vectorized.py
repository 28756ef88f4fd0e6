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


def _check_elementwise(arr: ArrayAnswer, scalar, inputs: dict, *, ideal_rtol=1e-12):
    """Every element of ``arr`` against the scalar call with that element's inputs."""
    b = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in inputs.values()))
    assert arr.shape == b[0].shape
    for idx in np.ndindex(arr.shape):
        one = scalar(**{k: float(v[idx]) for k, v in zip(inputs, b)})
        where = f"{idx} {[float(v[idx]) for v in b]}"
        assert _same(float(arr.value[idx]), _num(one.value), 1e-12), where
        assert _same(float(arr.low[idx]), _num(one.interval[0]), 1e-12), where
        assert _same(float(arr.high[idx]), _num(one.interval[1]), 1e-12), where
        assert _same(float(arr.coverage[idx]), _num(one.interval_coverage), 1e-12), where  # what it claims
        assert _same(float(arr.ideal[idx]), _num(one.ideal_bound.value), ideal_rtol), where
        assert bool(arr.in_grid[idx]) == all(one.in_grid.values()), where
        if one.question == "delta-e":
            for side in ("lower", "upper"):
                assert _same(float(arr.details[side][idx]), _num(one.details[side]["value"]), 1e-12), where
                assert _same(float(arr.details[f"{side}_ideal"][idx]), _num(one.details[side]["ideal"]), 1e-12)
                if f"{side}_low" in arr.details:  # each direction's interval (table route)
                    for end, got in zip(("low", "high"), one.details[side]["interval"]):
                        assert _same(float(arr.details[f"{side}_{end}"][idx]), _num(got), 1e-12), where
        if one.question == "distinguishable" and "min_contact_s" in arr.details:  # the answer it compared with
            want = _num(one.computation.get("min_contact_s"))
            assert _same(float(arr.details["min_contact_s"][idx]), want, 1e-12), where


RNG = np.random.default_rng(16)
# effusivities inside the shipped grids, plus one below and one above them (no answer there)
E1 = np.concatenate([RNG.uniform(500, 39000, 7), [-0.0 + 10.0, 45000.0]])


@pytest.mark.parametrize("table", ["svm-paper", "ideal-paper"])
def test_min_contact_broadcasts_and_equals_scalar_calls(table):
    e1 = E1[:, None]                              # (9, 1)
    e2 = np.array([[3000.0, 21000.0, 36000.0]])   # (1, 3)
    noise = np.array([0.05, 0.1, 0.05])            # (3,): the last scene a grid point, one between
    a = min_contact(e1, e2, noise_c=noise, delta_t_c=10.0, table=table)
    assert isinstance(a, ArrayAnswer) and a.shape == (9, 3) and a.unit == "s"
    assert np.isfinite(a.value).sum() >= 8 and not a.in_grid[-1].any()
    _check_elementwise(a, lambda **k: min_contact(**k, table=table), {"e1": e1, "e2": e2, "noise_c": noise})


def test_ratio_questions_equal_scalar_calls():
    e1, e2 = E1[:6], np.array([[21000.0], [9000.0]])
    contact = np.array([1.0, 1.7, 4.0, 2.0, 10.0, 0.3])  # grid points, between, and one below the grid
    a = max_noise(e1, e2, contact_s=contact, delta_t_c=np.array([[10.0], [-5.0]]))
    assert a.shape == (2, 6) and a.quantity == "noise_c"
    _check_elementwise(a, max_noise, {"e1": e1, "e2": e2, "contact_s": contact,
                                      "delta_t_c": np.array([[10.0], [-5.0]])}, ideal_rtol=1e-9)
    b = min_delta_t(e1, e2, contact_s=contact, noise_c=0.02)
    _check_elementwise(b, min_delta_t, {"e1": e1, "e2": e2, "contact_s": contact, "noise_c": 0.02},
                       ideal_rtol=1e-9)


def test_distinguishable_and_delta_e_equal_scalar_calls():
    e1, e2 = E1[:6], 21000.0
    contact = np.array([[1.0], [2.5]])
    a = distinguishable(e1, e2, contact_s=contact, noise_c=0.05, delta_t_c=10.0)
    assert set(np.unique(a.value[np.isfinite(a.value)])) <= {0.0, 1.0}
    # the vectorized ideal F1 is the closed form of ideal_bound (agrees with scipy's route to 1e-9)
    _check_elementwise(a, distinguishable, {"e1": e1, "e2": e2, "contact_s": contact}, ideal_rtol=1e-8)
    d = delta_e(E1, contact_s=np.array([[1.0], [3.3]]), noise_c=0.05)
    assert d.shape == (2, 9) and set(d.details) == {"lower", "upper", "lower_ideal", "upper_ideal", "lower_low",
                                                    "lower_high", "upper_low", "upper_high"}
    _check_elementwise(d, delta_e, {"e": E1, "contact_s": np.array([[1.0], [3.3]]), "noise_c": 0.05})


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
