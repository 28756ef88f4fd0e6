"""Thin samples, numerics: the finite-volume solver's order of convergence, agreement with
the image series, energy conservation, stiffness (explicit fails, implicit does not),
extremes, and the entry point's fallback to it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from designkit import SENSORS, InputError
from designkit.models import fv
from designkit.models.semi_infinite import object_weight, response_shape
from designkit.models.slab import FV_DEFAULTS, Backing, slab_response
from designkit_lab import explicit_euler

SENSOR = SENSORS["paper"]
COPPER = (36800.0, 1.17e-4)
FOAM = (30.5, 6.0e-7)
ACRYLIC = (583.25, 1.18e-7)
FOAM_BACK = Backing("rigid foam", *FOAM)
COPPER_BACK = Backing("copper", *COPPER)


def sensor_layer():
    return fv.Layer(SENSOR.effusivity, SENSOR.diffusivity_m2_s, math.inf, 0.0)


def stack(e, alpha, L, backing=None):
    body = [fv.Layer(e, alpha, L, 1.0)]
    if backing is not None:
        body.append(fv.Layer(backing.effusivity, backing.diffusivity_m2_s, math.inf, 1.0))
    return body


def fitted_order(n, err):
    slope = np.polyfit(np.log(np.asarray(n, float)), np.log(np.asarray(err)), 1)[0]
    return -slope


def test_space_converges_at_second_order_to_the_semi_infinite_answer():
    """A 100 mm acrylic block is semi-infinite within 4 s: the grid is refined (cells in
    every layer doubled) with time integration far more accurate than space (BDF,
    rtol 1e-10), and the error against eq. 2 falls as n^-2 (cell-centred FV)."""
    e, a = ACRYLIC
    t = np.array([0.5, 1.0, 2.0, 4.0])
    exact = object_weight(SENSOR.effusivity, e) * response_shape(t, SENSOR.tau_s)
    ns, errs = [16, 32, 64], []
    for n in ns:
        grid = fv.build_grid(sensor_layer(), stack(e, a, 0.1), SENSOR.depth_m, 4.0, n, time_min_s=0.075)
        u = fv.integrate_bdf(grid, t, rtol=1e-10, atol=1e-13)[0]
        errs.append(float(np.max(np.abs(u - exact))))
    order = fitted_order(ns, errs)
    assert 1.8 < order < 2.3, (errs, order)
    assert errs[-1] < 1e-4


def test_crank_nicolson_converges_at_second_order_in_time():
    """Same grid, time step ratio halved: the error against a tight BDF solution of the
    same semi-discrete system (so that space errors cancel) falls as (dt/t)^2."""
    grid = fv.build_grid(sensor_layer(), stack(*COPPER, 1e-3, FOAM_BACK), SENSOR.depth_m, 4.0, 24,
                         time_min_s=0.075)
    t = np.array([0.5, 1.0, 2.0, 4.0])
    ref = fv.integrate_bdf(grid, t, rtol=1e-11, atol=1e-14)[0]
    ratios, errs = [0.2, 0.1, 0.05], []
    for r in ratios:
        u = fv.integrate_crank_nicolson(grid, t, step_ratio=r)[0]
        errs.append(float(np.max(np.abs(u - ref))))
    order = np.polyfit(np.log(ratios), np.log(errs), 1)[0]
    assert 1.8 < order < 2.3, (errs, order)


THIN = [
    ("acrylic 1 mm on wood, 10 s", *ACRYLIC, 1e-3, "wood", 10.0),
    ("copper 1 mm on foam, 4 s", *COPPER, 1e-3, FOAM_BACK, 4.0),
    ("foam 1 mm on copper, 10 s", *FOAM, 1e-3, COPPER_BACK, 10.0),
    ("copper foil 0.1 mm on wood, 4 s", *COPPER, 1e-4, "wood", 4.0),
    ("acrylic 2 mm insulated, 60 s", *ACRYLIC, 2e-3, "insulated", 60.0),
]


@pytest.mark.parametrize("label,e,a,L,back,contact", THIN, ids=[s[0] for s in THIN])
def test_finite_volume_matches_image_series_for_thin_slabs(label, e, a, L, back, contact):
    t = SENSOR.times_s(contact)
    series = slab_response(t, e, a, L, back, tolerance=1e-12, method="image-series")
    assert series.fourier_number > 0.05  # the slab matters here
    num = slab_response(t, e, a, L, back, method="finite-volume")
    assert num.method == "finite-volume" and num.details["integrator"] == FV_DEFAULTS["integrator"]
    err = float(np.max(np.abs(num.response - series.response)))
    assert err < 1e-4  # 1e-3 degC at a 10 degC difference: the default's design target
    # the Richardson estimate it reports is of the right size
    assert 0.5 * err <= num.error_bound <= 2.0 * err + 1e-7


def test_bdf_integrator_agrees():
    t = SENSOR.times_s(4.0)
    series = slab_response(t, *COPPER, 1e-3, FOAM_BACK, tolerance=1e-12, method="image-series")
    num = slab_response(t, *COPPER, 1e-3, FOAM_BACK, method="finite-volume", integrator="bdf")
    assert num.details["integrator"] == "bdf"
    assert np.max(np.abs(num.response - series.response)) < 1e-4


@pytest.mark.parametrize("integrator", ["crank-nicolson", "bdf"])
def test_heat_is_conserved_with_insulated_ends(integrator):
    """Every outer face of the truncated stack is insulated: the total heat of sensor,
    slab and backing stays what it was, to rounding, through a stiff 4 s run."""
    grid = fv.build_grid(sensor_layer(), stack([36800.0, 20000.0], COPPER[1], 1e-3, FOAM_BACK),
                         SENSOR.depth_m, 4.0, 64)
    t = SENSOR.times_s(4.0)
    e0 = fv.heat_content(grid, np.broadcast_to(grid.initial, grid.capacity.shape))
    if integrator == "bdf":
        _, u_end, _ = fv.integrate_bdf(grid, t, return_state=True)
    else:
        _, u_end, levels = fv.integrate_crank_nicolson(grid, t, return_state=True)
        assert levels.size > 100
    drift = np.abs(fv.heat_content(grid, u_end) - e0) / e0
    assert np.all(drift < 1e-12), drift
    # and heat did move: the sensor warmed by a visible fraction of the total
    sensor_cells = grid.layer_index == 0
    assert np.all(np.sum((grid.heat_capacities() * u_end)[:, sensor_cells], axis=1) > 1e-3 * e0)


def test_explicit_step_limit_matches_dense_eigenvalues():
    grid = fv.build_grid(sensor_layer(), stack(*COPPER, 1e-4, FOAM_BACK), SENSOR.depth_m, 4.0, 8)
    m = grid.heat_capacities()[0]
    g = grid.conductances()[0]
    n = m.size
    a = np.zeros((n, n))
    for i in range(n - 1):
        a[i, i] += g[i]
        a[i + 1, i + 1] += g[i]
        a[i, i + 1] -= g[i]
        a[i + 1, i] -= g[i]
    lam = np.max(np.linalg.eigvals(a / m[:, None]).real)
    assert explicit_euler.explicit_step_limit_s(grid)[0] == pytest.approx(2.0 / lam, rel=1e-9)


def test_explicit_stepping_is_unstable_where_implicit_is_not():
    """Copper foil on polymer foam with sub-micrometre cells near the contact: forward
    Euler is stable only below a step of ~1e-8 s (2e8 steps for a 4 s touch). Just above
    its limit it leaves the physical range [0, 1] within tens of steps; Crank-Nicolson
    with steps up to 5 % of t (hundreds of millions of times the limit) stays in range
    and accurate."""
    grid = fv.build_grid(sensor_layer(), stack(*COPPER, 1e-4, FOAM_BACK), SENSOR.depth_m, 4.0,
                         FV_DEFAULTS["cells_per_layer"])
    limit = float(explicit_euler.explicit_step_limit_s(grid)[0])
    assert grid.widths_m.min() < 1e-6
    assert limit < 1e-7
    bad = explicit_euler.integrate_explicit(grid, 1.1 * limit, 3000)
    assert bad.diverged and bad.steps_taken < 3000
    good = explicit_euler.integrate_explicit(grid, 0.9 * limit, 3000)
    assert not good.diverged
    assert np.nanmax(good.max_abs) <= 1.0 + 1e-12  # the maximum principle holds
    t = SENSOR.times_s(4.0)
    u, _, levels = fv.integrate_crank_nicolson(grid, t, return_state=True)
    assert np.max(np.diff(levels)) > 1e5 * limit
    assert np.all(u >= -1e-12) and np.all(u <= 1.0 + 1e-12)
    ref = slab_response(t, *COPPER, 1e-4, FOAM_BACK, tolerance=1e-12, method="image-series").response
    assert np.max(np.abs(u - ref)) < 1e-4


EXTREMES = [
    # label, e, alpha, L, backing, contact, monotone in t (backing at least as effusive, or semi-infinite)
    ("copper on foam", *COPPER, 1e-3, FOAM_BACK, 4.0, False),
    ("foam on copper", *FOAM, 1e-3, COPPER_BACK, 4.0, True),
    ("0.1 mm copper foil on foam", *COPPER, 1e-4, FOAM_BACK, 4.0, False),
    ("0.1 mm foam foil on copper", *FOAM, 1e-4, COPPER_BACK, 4.0, True),
    ("100 mm acrylic block", *ACRYLIC, 0.1, "insulated", 4.0, True),
    ("contact 0.01 s", *ACRYLIC, 1e-3, "steel", 0.01, True),
    ("contact 60 s, copper 1 mm on foam", *COPPER, 1e-3, FOAM_BACK, 60.0, False),
    ("contact 60 s, foam 1 mm on copper", *FOAM, 1e-3, COPPER_BACK, 60.0, True),
]


@pytest.mark.parametrize("label,e,a,L,back,contact,monotone", EXTREMES, ids=[s[0] for s in EXTREMES])
def test_extremes_stay_finite_bounded_and_monotone(label, e, a, L, back, contact, monotone):
    t = SENSOR.times_s(contact)
    for method in ("auto", "finite-volume"):
        r = slab_response(t, e, a, L, back, method=method)
        u = r.response[0]
        assert np.all(np.isfinite(u)), (label, method)
        assert np.all(u >= -1e-9) and np.all(u <= 1.0 + 1e-9), (label, method)
        if monotone:
            assert np.all(np.diff(u) >= -1e-9), (label, method)
        if method == "auto":
            auto = u
    assert np.max(np.abs(u - auto)) < 1e-4
    if contact <= 0.01:
        # far too short for heat to reach an 80 um deep thermistor (erfc(sqrt(134)) ~ 1e-60)
        assert np.max(np.abs(u)) < 1e-12


def test_insulated_copper_rises_then_falls():
    # a 1 mm copper plate on an insulated back is soon heated through: the reading peaks
    # and then returns towards the sensor's temperature
    t = SENSOR.times_s(60.0)
    u = slab_response(t, *COPPER, 1e-3, "insulated", method="finite-volume").response[0]
    k = int(np.argmax(u))
    assert 0 < k < t.size - 1
    assert np.all(np.diff(u[: k + 1]) >= -1e-9) and np.all(np.diff(u[k:]) <= 1e-9)


def test_auto_falls_back_to_finite_volume_when_the_series_is_too_long():
    t = SENSOR.times_s(4.0)
    ref = slab_response(t, *COPPER, 1e-4, "wood", tolerance=1e-12, method="image-series")
    assert ref.n_terms > 100
    r = slab_response(t, *COPPER, 1e-4, "wood", max_terms=20)
    assert r.method == "finite-volume" and r.details["cells"] > 0
    assert np.max(np.abs(r.response - ref.response)) < 1e-4
    with pytest.raises(InputError, match="more than 20 terms"):
        slab_response(t, *COPPER, 1e-4, "wood", max_terms=20, method="image-series")


def test_stacked_effusivities_equal_separate_runs():
    t = SENSOR.times_s(4.0)
    e = np.array([300.0, 3000.0, 30000.0])
    both = slab_response(t, e, 1e-6, 1e-3, "steel", method="finite-volume")
    for k in range(e.size):
        one = slab_response(t, e[k], 1e-6, 1e-3, "steel", method="finite-volume")
        np.testing.assert_allclose(both.response[k], one.response[0], rtol=0, atol=1e-12)


def test_fv_bad_input():
    with pytest.raises(InputError, match="effusivity"):
        fv.Layer(-1.0, 1e-7, 1e-3)
    with pytest.raises(InputError, match="diffusivity"):
        fv.Layer(500.0, 0.0, 1e-3)
    with pytest.raises(InputError, match="only the last"):
        fv.build_grid(sensor_layer(), [fv.Layer(500.0, 1e-7, math.inf), fv.Layer(500.0, 1e-7, 1e-3)],
                      SENSOR.depth_m, 1.0)
    with pytest.raises(InputError, match="property sets"):
        fv.build_grid(sensor_layer(), [fv.Layer([1.0, 2.0], 1e-7, 1e-3), fv.Layer([1.0, 2.0, 3.0], 1e-7, 1.0)],
                      SENSOR.depth_m, 1.0)
    with pytest.raises(InputError, match="buried thermistor"):
        slab_response([0.0, 1.0], 500.0, 1e-7, 1e-3, "steel", SENSOR.replace(depth_m=0.0), method="finite-volume")
    with pytest.raises(InputError, match="positive, finite"):
        slab_response([0.0, 1.0], [0.0, 500.0], 1e-7, 1e-3, "steel", method="finite-volume")
