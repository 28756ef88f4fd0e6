"""The layered sensor model: against mpmath's inverse Laplace transform, its limits, its extremes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from designkit import SENSORS, InputError
from designkit.models import get_model
from designkit.models.contact import Contact
from designkit.models.layered import Layered, savgol_smooth, talbot_invert
from designkit.models.semi_infinite import SemiInfinite

PAPER = SENSORS["paper"]
E_OBJECTS = np.array([0.0, 30.0, 400.0, 892.0, 20000.0, 1e9, np.inf])


def _reference(model: Layered, sensor, e_o: float, t: float) -> float:
    """mpmath (Talbot, 60 digits: the cosh/sinh form below cancels ~20 of them) on the film's transfer
    matrix, written independently of the reflection form the model uses."""
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 60
    ef, eb = mpmath.mpf(sensor.effusivity), mpmath.mpf(model.backing_effusivity_ws05_m2k)
    a = mpmath.mpf(sensor.diffusivity_m2_s)
    L, x, h, lag = (mpmath.mpf(v) for v in (model.film_thickness_m, sensor.depth_m, model.conductance_w_m2k,
                                             model.lag_s))

    def F(p):
        q = mpmath.sqrt(p / a)
        # transfer matrix of the film, backing admittance eb sqrt(p) at its back face
        c, s = mpmath.cosh(q * L), mpmath.sinh(q * L)
        kq, yb = ef * mpmath.sqrt(p), eb * mpmath.sqrt(p)
        Y = kq * (kq * s + yb * c) / (kq * c + yb * s)
        surface = 1 / (p * (1 + Y / (e_o * mpmath.sqrt(p)) + Y / h))
        inside = mpmath.cosh(q * x) - Y / kq * mpmath.sinh(q * x)
        return surface * inside / (1 + lag * p)

    return float(mpmath.invertlaplace(F, t, method="talbot"))


@pytest.mark.parametrize("model", [
    Layered(film_thickness_m=100e-6, backing_effusivity_ws05_m2k=300.0, conductance_w_m2k=3000.0, lag_s=0.2),
    Layered(film_thickness_m=200e-6, backing_effusivity_ws05_m2k=5e4, conductance_w_m2k=400.0),
])
def test_layered_matches_mpmath_inverse_laplace(model):
    for e_o in (400.0, 20000.0):
        for t in (0.02, 0.5, 3.0):
            ref = _reference(model, PAPER, e_o, t)
            got = float(model.conduction([t], [e_o], PAPER)[0, 0])
            assert abs(got - ref) <= 1e-9 * max(1.0, abs(ref)), (e_o, t, got, ref)


def test_limits_give_the_contact_and_semi_infinite_models():
    t = PAPER.times_s(8.0)
    semi = SemiInfinite().response(t, E_OBJECTS, PAPER)
    same = Layered(film_thickness_m=1e-3, backing_effusivity_ws05_m2k=PAPER.effusivity)
    assert np.max(np.abs(same.response(t, E_OBJECTS, PAPER) - semi)) <= 1e-9
    for h in (300.0, 3000.0):
        contact = Contact(h).response(t, E_OBJECTS, PAPER)
        for thin in (Layered(film_thickness_m=1e-4, backing_effusivity_ws05_m2k=PAPER.effusivity,
                             conductance_w_m2k=h),
                     Layered(film_thickness_m=1e-16, backing_effusivity_ws05_m2k=3000.0, conductance_w_m2k=h,
                             backing_diffusivity_m2_s=PAPER.diffusivity_m2_s)):
            ref = contact if thin.film_thickness_m > 1e-10 else \
                Contact(h).response(t, E_OBJECTS, PAPER.replace(effusivity=3000.0))
            assert np.max(np.abs(thin.response(t, E_OBJECTS, PAPER) - ref)) <= 1e-9
    # h_c -> inf: perfect contact
    film = dict(film_thickness_m=150e-6, backing_effusivity_ws05_m2k=400.0)
    perfect = Layered(**film).response(t, E_OBJECTS, PAPER)
    assert np.max(np.abs(Layered(**film, conductance_w_m2k=1e13).response(t, E_OBJECTS, PAPER) - perfect)) <= 1e-9


@pytest.mark.parametrize("model", [Layered(), Layered(conductance_w_m2k=10.0), Layered(lag_s=5.0),
                                   Layered(film_thickness_m=1e-9), Layered(backing_effusivity_ws05_m2k=1e-3),
                                   Layered(backing_effusivity_ws05_m2k=1e7), Layered(backing_thickness_m=2e-4),
                                   Layered(smoothing_window=99, smoothing_order=3)])
@pytest.mark.parametrize("depth_m", [0.0, 80e-6])
def test_finite_and_in_range_at_the_extremes(model, depth_m):
    sensor = PAPER.replace(depth_m=depth_m)
    t = np.arange(0, 401) / 200.0 if model.smoothing_window else np.array([0.0, 1e-9, 0.001, 0.005, 1.0, 100.0])
    u = model.response(t, E_OBJECTS, sensor)
    assert u.shape == (E_OBJECTS.size, t.size)
    assert np.all(np.isfinite(u)) and u.min() >= 0.0 and u.max() <= 1.0
    assert np.all(u[0] == 0.0)                      # a perfect insulator changes nothing
    # the sign of the effect: more effusive objects pull harder (at 2 s, away from the clipped ends)
    k = int(np.argmin(np.abs(t - min(t[-1], 1.0))))
    assert np.all(np.diff(u[:, k]) >= -1e-12)


def test_surface_thermistor_jumps_at_once_and_a_finite_backing_settles():
    s0 = PAPER.replace(depth_m=0.0)
    u0 = Layered(film_thickness_m=1e-3, backing_effusivity_ws05_m2k=PAPER.effusivity).response([0.0], [892.0], s0)
    assert u0[0, 0] == pytest.approx(0.5, abs=1e-15)
    held = Layered(film_thickness_m=100e-6, backing_effusivity_ws05_m2k=400.0, backing_thickness_m=200e-6)
    late = held.conduction([50.0, 100.0], [1e9], PAPER)[0]
    assert 0.0 < late[0] < 1.0 and late[1] == pytest.approx(late[0], rel=1e-3)   # a steady state below 1


def test_registry_validation_and_description():
    m = get_model("layered", film_thickness_m=1e-4, lag_s=0.5)
    assert get_model(m.to_dict()) == m and "film_thickness_m = 0.0001 m" in m.describe()
    for bad, words in [({"film_thickness_m": -1.0}, "film thickness"), ({"lag_s": -0.1}, "thermistor lag"),
                       ({"smoothing_window": 98}, "odd"), ({"smoothing_window": 2.5}, "whole number"),
                       ({"backing_effusivity_ws05_m2k": 0.0}, "backing effusivity")]:
        with pytest.raises(InputError, match=words):
            get_model("layered", **bad)
    with pytest.raises(InputError, match="uniformly sampled"):
        Layered(smoothing_window=5).response([0.0, 0.1, 0.3], [400.0], PAPER)


def test_talbot_and_smoothing_helpers():
    t = np.array([0.01, 1.0, 10.0])
    assert np.allclose(talbot_invert(lambda p: 1.0 / p ** 2, t), t, rtol=1e-10, atol=0)
    assert np.allclose(talbot_invert(lambda p: np.exp(-np.sqrt(p)) / p, t),
                       [math.erfc(1 / (2 * math.sqrt(v))) for v in t], rtol=0, atol=1e-11)
    step = np.r_[np.zeros(100), np.ones(100)]
    out = savgol_smooth(step, 99, 3)
    assert out.shape == step.shape and out.min() < 0  # the filter's overshoot before a step, as in the recordings
    assert np.allclose(savgol_smooth(step, 0, 3), step)


@pytest.mark.parametrize("shape, window, order", [((120, 1601), 99, 3), ((401,), 99, 3), ((3, 2, 99), 99, 3),
                                                  ((5, 100), 5, 2), ((1, 250), 21, 4), ((2, 30), 11, 0)])
def test_the_fast_smoothing_is_scipy_s_savgol_filter(shape, window, order):
    """savgol_smooth (FFT inside, end projections) against scipy.signal.savgol_filter(mode="interp")."""
    from scipy.signal import savgol_filter

    x = np.cumsum(np.random.default_rng(window + order).normal(size=shape), axis=-1)
    ref = savgol_filter(x, window, order, axis=-1, mode="interp")
    assert np.allclose(savgol_smooth(x, window, order), ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    padded = savgol_filter(np.concatenate([np.zeros(shape[:-1] + (7,)), x], axis=-1), window, order, axis=-1,
                           mode="interp")[..., 7:]
    assert np.allclose(savgol_smooth(x, window, order, pad_before=7), padded, rtol=0,
                       atol=1e-12 * np.abs(padded).max())
