"""Thin samples, closed form: the image series against mpmath's Laplace inversion, limits,
error bounds, physical orderings, the entry point's choices, validity, and the CLI."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designkit import SENSORS, InputError
from designkit.models.semi_infinite import object_weight, response_shape, sensor_temperature
from designkit.models.slab import (
    Backing,
    fourier_number,
    image_series,
    material_validity,
    reflection_coefficients,
    resolve_backing,
    semi_infinite_deviation,
    semi_infinite_error_bound,
    semi_infinite_validity,
    slab_response,
)

SENSOR = SENSORS["paper"]
TAU = SENSOR.tau_s
ES = SENSOR.effusivity
COPPER = (36800.0, 1.17e-4)
FOAM = (30.5, 6.0e-7)
ACRYLIC = (583.25, 1.18e-7)


def laplace_reading(p, e_o, alpha_o, L, e_b):
    """U(p) of the normalized reading, solved directly from the Laplace-domain boundary
    value problem (not from the series): sensor A exp(q_s z) for z < 0, slab
    1/p + B exp(-q_o z) + C exp(q_o z), backing 1/p + D exp(-q_b (z - L)); continuity
    of temperature and of flux e sqrt(p) dU/dz at z = 0 and z = L, solved as a
    4x4 linear system in mpmath."""
    sp = mpmath.sqrt(p)
    qo = sp / mpmath.sqrt(alpha_o)
    ep, em = mpmath.exp(qo * L), mpmath.exp(-qo * L)
    # unknowns A, B, C, D; rows: T(0), flux(0), T(L), flux(L)
    M = mpmath.matrix([
        [1, -1, -1, 0],
        [ES, e_o, -e_o, 0],
        [0, em, ep, -1],
        [0, -e_o * em, e_o * ep, e_b],
    ])
    rhs = mpmath.matrix([1 / p, 0, 0, 0])
    A = mpmath.lu_solve(M, rhs)[0]
    return A * mpmath.exp(-2 * mpmath.sqrt(p * TAU))  # x sqrt(p / alpha_s) = 2 sqrt(p tau)


SCENES = [
    ("acrylic 3 mm on steel", *ACRYLIC, 3e-3, 13968.5),
    ("acrylic 1 mm insulated", *ACRYLIC, 1e-3, 0.0),
    ("copper 1 mm on foam", *COPPER, 1e-3, FOAM[0]),
    ("foam 1 mm on copper", *FOAM, 1e-3, COPPER[0]),
    ("sensor-matched slab (R_s = 0) on wood", ES, 2e-7, 5e-4, 418.7),
]


@pytest.mark.parametrize("label,e_o,alpha_o,L,e_b", SCENES, ids=[s[0] for s in SCENES])
def test_series_matches_mpmath_laplace_inversion(label, e_o, alpha_o, L, e_b):
    mpmath.mp.dps = 30
    times = np.array([0.3, 1.5, 6.0, 40.0])
    backing = Backing("b", e_b, 1e-6)
    ours = slab_response(times, e_o, alpha_o, L, backing, tolerance=1e-13, method="image-series")
    for t, u in zip(times, ours.response[0]):
        ref = mpmath.invertlaplace(lambda p: laplace_reading(p, e_o, alpha_o, L, e_b), t, method="talbot")
        assert abs(u - float(ref)) <= 1e-10, (label, t)
    # and the slab matters in these scenes (the check is not of the semi-infinite term alone)
    semi = object_weight(ES, e_o) * response_shape(times, TAU)
    assert np.max(np.abs(ours.response[0] - semi)) > 1e-3


def test_semi_infinite_limits_are_exact():
    t = np.linspace(0.0, 10.0, 201)
    e = np.array([0.0, 30.0, 892.0, 5000.0, np.inf])
    paper = object_weight(ES, e)[:, None] * response_shape(t, TAU)[None, :]
    thick = slab_response(t, e, 1e-7, math.inf, "steel")
    assert thick.method == "semi-infinite" and thick.error_bound == 0.0
    np.testing.assert_array_equal(thick.response, paper)
    # a backing of the object's own effusivity reflects nothing, at any thickness
    same = slab_response(t, 600.0, 1e-7, 1e-4, Backing("same", 600.0, 1e-7))
    assert same.method == "semi-infinite" and same.error_bound == 0.0
    np.testing.assert_allclose(same.response[0], object_weight(ES, 600.0) * response_shape(t, TAU), rtol=1e-15)
    # e_o = 0 (perfect insulator) and inf (perfect conductor) stay the paper's limits on any slab
    lim = slab_response(t, [0.0, np.inf], 1e-7, 1e-4, "insulated")
    np.testing.assert_array_equal(lim.response[0], 0.0)
    np.testing.assert_array_equal(lim.response[1], response_shape(t, TAU))


def test_temperature_matches_physics_for_thick_objects():
    t = SENSOR.times_s(4.0)
    r = slab_response(t, [400.0, 20000.0], 1e-6, 10.0, "wood")
    temps = r.temperature_c(35.0, 25.0)
    for k, e in enumerate([400.0, 20000.0]):
        np.testing.assert_allclose(temps[k], sensor_temperature(t, e, 35.0, 25.0, ES, TAU), atol=1e-12)


def test_reflection_coefficients():
    w, rs, rb = reflection_coefficients(np.array([892.0, 1e4]), 0.0, ES)
    np.testing.assert_allclose(rs, [0.0, (1e4 - ES) / (1e4 + ES)])
    np.testing.assert_array_equal(rb, [1.0, 1.0])  # insulated back
    np.testing.assert_allclose(w, [0.5, 1e4 / (1e4 + ES)])
    assert fourier_number(1e-7, 4.0, 2e-3) == pytest.approx(0.1)


@settings(max_examples=40, deadline=None)
@given(
    log_e=st.floats(1.0, 4.7), log_a=st.floats(-8.0, -4.0), log_L=st.floats(-5.0, -1.0),
    log_eb=st.one_of(st.just(-np.inf), st.floats(0.0, 4.7)), t_end=st.floats(0.05, 60.0),
    log_tol=st.floats(-9.0, -2.0),
)
def test_error_bound_is_honest(log_e, log_a, log_L, log_eb, t_end, log_tol):
    t = np.linspace(0.0, t_end, 97)
    e, a, L, eb, tol = 10 ** log_e, 10 ** log_a, 10 ** log_L, 10 ** log_eb, 10 ** log_tol
    back = Backing("b", eb, 1e-6)
    r = slab_response(t, e, a, L, back, tolerance=tol)
    ref = slab_response(t, e, a, L, back, tolerance=1e-15, method="image-series")
    assert r.method in ("semi-infinite", "image-series")
    assert r.error_bound <= tol
    assert np.max(np.abs(r.response - ref.response)) <= r.error_bound + 1e-14
    # the exact reading lies in [0, 1] (maximum principle); a truncated sum within its bound
    slack = r.error_bound + 1e-15
    assert np.all(np.isfinite(r.response))
    assert np.all(r.response >= -slack) and np.all(r.response <= 1 + slack)
    assert np.all(ref.response >= -1e-14) and np.all(ref.response <= 1 + 1e-14)


def test_physical_orderings():
    """Properties the physics guarantees, on a log-time grid to 1e4 s:
    (1) a more effusive backing draws more heat: the reading (normalized towards the
        object temperature) grows with e_b, the insulated back lowest;
    (2) a more effusive object (same alpha, L, backing) pulls harder;
    (3) on a backing at least as effusive as the object the reading only rises;
    (4) on an insulated back it rises, then falls back as the slab heats up."""
    rng = np.random.default_rng(3)
    t = np.geomspace(1e-2, 1e4, 1500)
    for _ in range(25):
        e, a, L = 10 ** rng.uniform(1, 4.7), 10 ** rng.uniform(-8, -4), 10 ** rng.uniform(-5, -1)
        ebs = np.sort(10 ** rng.uniform(0, 4.7, 4))
        curves = [slab_response(t, e, a, L, "insulated", tolerance=1e-12).response[0]]
        curves += [slab_response(t, e, a, L, Backing("b", eb, 1e-6), tolerance=1e-12).response[0] for eb in ebs]
        for lo, hi in zip(curves[:-1], curves[1:]):
            assert np.all(hi >= lo - 1e-12)
        for eb, u in zip(ebs, curves[1:]):
            if eb >= e:
                assert np.all(np.diff(u) >= -1e-12)
        steps = np.sign(np.diff(curves[0]))
        steps = steps[steps != 0]
        assert np.count_nonzero(steps[1:] != steps[:-1]) <= 1  # one maximum at most
        es = np.sort(10 ** rng.uniform(1, 4.7, 4))
        u = slab_response(t, es, a, L, Backing("b", ebs[1], 1e-6), tolerance=1e-12).response
        assert np.all(np.diff(u, axis=0) >= -1e-12)


def test_insulated_slab_long_time_limit():
    # a finite slab on an insulated back ends at the sensor temperature (u -> 0);
    # on a semi-infinite backing, at the sensor-backing contact weight w_b
    t = np.array([1e5, 1e7])
    u = slab_response(t, 600.0, 1e-6, 1e-4, "insulated", tolerance=1e-12).response[0]
    assert u[-1] < 1e-3 * object_weight(ES, 600.0)
    ub = slab_response(t, 600.0, 1e-6, 1e-4, Backing("b", 5000.0, 1e-6), tolerance=1e-12).response[0]
    assert ub[-1] == pytest.approx(float(object_weight(ES, 5000.0)), rel=1e-2)


def test_vectorized_over_effusivity_and_diffusivity():
    t = SENSOR.times_s(8.0)
    e = np.array([30.0, 600.0, 2500.0, 36800.0])
    a = np.array([6e-7, 1.2e-7, 1e-6, 1.17e-4])
    both = slab_response(t, e, a, 1e-3, "steel", tolerance=1e-9)
    for k in range(e.size):
        one = slab_response(t, e[k], a[k], 1e-3, "steel", tolerance=1e-9)
        np.testing.assert_allclose(both.response[k], one.response[0], atol=2e-9)
    shared = slab_response(t, e, 1.2e-7, 1e-3, "steel", tolerance=1e-9)
    assert shared.response.shape == (4, t.size)
    assert both.n_terms >= 1 and both.method == "image-series"
    # the same normalized shapes the simulation layer uses: T = Ts0 + (Ta - Ts0) u
    assert shared.temperature_c(np.array([35.0, 33.0, 31.0, 30.0]), 25.0).shape == (4, t.size)


def test_image_series_chunking_is_seamless():
    # a long time axis is processed in chunks; chunk borders must not show (beyond the
    # last-bit differences of a BLAS product over differently sized blocks)
    t = np.linspace(0.0, 60.0, 12001)
    u = image_series(t, [36800.0], 1.17e-4, 1e-4, 418.7, ES, TAU, n_terms=400)
    v = np.concatenate([image_series(t[:5000], [36800.0], 1.17e-4, 1e-4, 418.7, ES, TAU, n_terms=400),
                        image_series(t[5000:], [36800.0], 1.17e-4, 1e-4, 418.7, ES, TAU, n_terms=400)], axis=1)
    np.testing.assert_allclose(u, v, rtol=0, atol=1e-14)


@pytest.mark.parametrize("kwargs,match", [
    (dict(thickness_m=-1e-3), "thickness"),
    (dict(thickness_m=0.0), "thickness"),
    (dict(e_object=float("nan")), "effusivity"),
    (dict(e_object=-5.0), "effusivity"),
    (dict(alpha_object_m2_s=0.0), "diffusivity"),
    (dict(alpha_object_m2_s=[1e-7, 2e-7, 3e-7]), "diffusivity"),
    (dict(time_s=[-1.0, 1.0]), "times"),
    (dict(time_s=[0.0, float("inf")]), "times"),
    (dict(backing="unobtainium"), "backing"),
    (dict(method="magic"), "method"),
    (dict(tolerance=0.0), "tolerance"),
    (dict(max_terms=0, backing="steel", time_s=[0.0, 60.0]), "max_terms"),
])
def test_bad_input_is_one_line_input_error(kwargs, match):
    args = dict(time_s=[0.0, 1.0], e_object=[600.0, 700.0], alpha_object_m2_s=1e-7, thickness_m=1e-3,
                backing="insulated")
    args.update(kwargs)
    with pytest.raises(InputError, match=match) as info:
        slab_response(**args)
    assert "\n" not in str(info.value)


def test_bad_backing_is_refused_at_construction():
    with pytest.raises(InputError, match="effusivity of backing"):
        Backing("b", -3.0, 1e-6)
    with pytest.raises(InputError, match="diffusivity of backing"):
        Backing("b", 300.0, 0.0)


def test_backings_resolve():
    assert resolve_backing("insulated").insulated
    air = resolve_backing("AIR")
    assert air.effusivity == pytest.approx(math.sqrt(0.0263 * 1.1614 * 1007.0))
    steel = resolve_backing("steel")  # an alias of the database's low carbon steel
    assert 13000 < steel.effusivity < 15000 and steel.name == "Low carbon steel"
    assert 300 < resolve_backing("wood").effusivity < 520
    b = Backing("mine", 1234.0, 1e-6)
    assert resolve_backing(b) is b


# ----------------------------------------------------------------------------- validity
def test_validity_is_the_first_crossing():
    v = semi_infinite_validity(*ACRYLIC, 3e-3, "steel", delta_t_c=10.0, tolerance_c=0.01)
    assert 5.0 < v.time_s < 60.0
    # independent of the bracketing: a dense grid with many more series terms
    t = np.linspace(0.01, 60.0, 60000)
    dev = 10.0 * np.abs(semi_infinite_deviation(t, *ACRYLIC, 3e-3, "steel", tolerance=1e-14)[0])
    first = t[np.argmax(dev > 0.01)]
    assert v.time_s == pytest.approx(first, abs=2e-3)
    assert v.fourier_number == pytest.approx(ACRYLIC[1] * v.time_s / 9e-6)
    # the deviation grows with the temperature difference, so the validity shrinks
    v20 = semi_infinite_validity(*ACRYLIC, 3e-3, "steel", delta_t_c=20.0, tolerance_c=0.01)
    assert v20.time_s < v.time_s
    # a thicker sheet holds longer, roughly as L^2 once the slab's flight time dominates
    v6 = semi_infinite_validity(*ACRYLIC, 6e-3, "steel", delta_t_c=10.0, tolerance_c=0.01)
    assert 3.0 < v6.time_s / v.time_s < 4.5
    # no temperature difference, or no back face: nothing to deviate
    assert semi_infinite_validity(*ACRYLIC, 3e-3, "steel", delta_t_c=0.0).time_s == math.inf
    assert semi_infinite_validity(*ACRYLIC, math.inf, "steel").time_s == math.inf


def test_validity_of_a_very_thin_foil_is_short_and_bracketed_from_zero():
    v = semi_infinite_validity(*COPPER, 1e-6, "insulated", tolerance_c=0.01)
    assert 0 < v.time_s < 1.0
    dev = 10.0 * abs(semi_infinite_deviation([v.time_s], *COPPER, 1e-6, "insulated")[0, 0])
    assert dev == pytest.approx(0.01, rel=1e-6)


def test_material_validity_worst_case_is_not_longer_than_nominal():
    mv = material_validity("acrylic", 3e-3, "wood")
    assert mv.worst.time_s <= mv.nominal.time_s
    assert mv.worst.alpha_object_m2_s == pytest.approx(mv.material.diffusivity_max_m2_s)


def test_acrylic_on_wood_vs_steel_differs_only_for_long_contacts():
    """The closing-note evidence: a 3 mm acrylic sheet on wood vs on steel.

    The semi-infinite model gives one curve for both. The slab model separates them
    once the reflection off the back face has reached the thermistor: nothing at the
    paper's 1-4 s, more than the 0.05 degC noise after about half a minute."""
    t = np.arange(0.0, 60.0 + 1e-9, 0.005)
    wood = slab_response(t, *ACRYLIC, 3e-3, "wood", tolerance=1e-8).temperature_c(35.0, 25.0)[0]
    steel = slab_response(t, *ACRYLIC, 3e-3, "steel", tolerance=1e-8).temperature_c(35.0, 25.0)[0]
    semi = slab_response(t, *ACRYLIC, math.inf, "wood").temperature_c(35.0, 25.0)[0]
    diff = wood - steel
    assert np.max(np.abs(diff[t <= 4.0])) < 1e-6
    assert np.all(diff >= -1e-9)  # steel draws more heat: its reading is closer to ambient
    over = t[np.argmax(diff > 0.05)]
    assert 20.0 < over < 40.0
    assert diff[-1] > 0.3
    # neither is the semi-infinite curve late in the touch
    assert abs(steel[-1] - semi[-1]) > 0.2


# ----------------------------------------------------------------------------- CLI
def test_cli_validity_json_matches_library(cli):
    res = cli("validity", "--e", "583.25", "--alpha", "1.18e-7", "--thickness", "0.003", "--backing", "steel",
              "--json")
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    v = semi_infinite_validity(*ACRYLIC, 3e-3, "steel")
    assert out["valid_up_to_s"] == pytest.approx(v.time_s, rel=1e-9)
    assert out["nominal_valid_up_to_s"] == out["valid_up_to_s"]
    assert out["backing"]["name"] == "Low carbon steel"
    assert out["tolerance_c"] == 0.01 and out["delta_t_c"] == 10.0
    assert abs(out["deviation_c"]["4"]) < 1e-6 and out["deviation_c"]["60"] < -0.1  # steel cools it


def test_cli_validity_material_human_and_plot(cli, tmp_path):
    png = tmp_path / "dev.png"
    res = cli("validity", "--material", "acrylic", "--thickness", "0.003", "--plot", str(png))
    assert res.exit_code == 0, res.output
    assert "semi-infinite model within 0.01 °C over the material's ranges up to" in res.stdout
    assert "at the ranges' middle" in res.stdout
    assert png.stat().st_size > 1000
    res = cli("validity", "--material", "acrylic", "--thickness", "1e3", "--json")
    assert res.exit_code == 0 and json.loads(res.stdout)["valid_up_to_s"] is None  # beyond the horizon


@pytest.mark.parametrize("args,msg", [
    (["--material", "acrylic", "--e", "500", "--thickness", "0.003"], "not both"),
    (["--e", "500", "--thickness", "0.003"], "--alpha"),
    (["--material", "acrylic", "--thickness", "-1"], "thickness"),
    (["--material", "acrylic", "--thickness", "0.003", "--backing", "unobtainium"], "unknown backing"),
    (["--material", "nosuchthing", "--thickness", "0.003"], "unknown material"),
    (["--material", "acrylic", "--thickness", "0.003", "--tolerance", "0"], "tolerance"),
])
def test_cli_validity_bad_input(cli, args, msg):
    res = cli("validity", *args)
    assert res.exit_code == 2
    assert msg in res.stderr and res.stderr.startswith("Error: ")
    assert "Traceback" not in res.output


def test_cli_validity_console_script():
    exe = Path(sys.executable).parent / "designkit"
    if not exe.exists():
        pytest.skip(f"console script not installed next to {sys.executable}")
    proc = subprocess.run([str(exe), "validity", "--material", "acrylic", "--thickness", "0.003",
                           "--backing", "wood", "--json"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert 5.0 < out["valid_up_to_s"] <= out["nominal_valid_up_to_s"] < 60.0
    proc = subprocess.run([str(exe), "validity", "--thickness", "0.003"], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 2 and proc.stderr.startswith("Error: ") and "Traceback" not in proc.stderr


def test_cheap_error_bound_bounds_the_deviation():
    rng = np.random.default_rng(11)
    for _ in range(30):
        e, a, L = 10 ** rng.uniform(1, 4.7), 10 ** rng.uniform(-8, -4), 10 ** rng.uniform(-5, -1)
        back = Backing("b", 10 ** rng.uniform(0, 4.7), 1e-6) if rng.random() < 0.7 else "insulated"
        contact = 10 ** rng.uniform(-1, 2)
        t = np.linspace(0.0, contact, 400)
        dev = np.max(np.abs(semi_infinite_deviation(t, e, a, L, back, tolerance=1e-14)))
        bound = float(semi_infinite_error_bound(contact, e, a, L, back)[0])
        assert dev <= bound + 1e-15
        if dev > 1e-6:
            # conservative, not vacuous: the terms shrink at least geometrically (ratio
            # |R_b R_s| <= 0.953 here), so even an alternating sum keeps a share (1 - |r|)
            # of its first term, while the bound adds at most 1 / (1 - |r|): <= 1 / 0.047^2
            assert bound < 500 * dev
    assert semi_infinite_error_bound(4.0, 600.0, 1e-7, math.inf, "steel")[0] == 0.0
