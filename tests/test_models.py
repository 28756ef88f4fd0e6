"""The forward-model seam: registry, limits of each model, and the contact model against
an independent reference (mpmath's numerical inverse Laplace transform)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from designkit import SENSORS, InputError
from designkit.models import MODELS, ForwardModel, get_model, model_names
from designkit.models.contact import Contact
from designkit.models.semi_infinite import SemiInfinite
from designkit.objects import ObjectClass, object_class

PAPER = SENSORS["paper"]


def test_registry_names_every_model_and_round_trips_through_to_dict():
    assert model_names() == tuple(MODELS) and {"semi-infinite", "slab", "contact"} <= set(MODELS)
    for name in MODELS:
        params = {"slab": {"thickness_m": 0.003}, "contact": {"conductance_w_m2k": 1500.0}}.get(name, {})
        m = get_model(name, **params)
        assert isinstance(m, ForwardModel) and m.name == name
        assert get_model(m.to_dict()) == m  # a table header's record gives the same model back
    for m in (get_model("contact", conductance_w_m2k=math.inf), get_model("slab", thickness_m=math.inf)):
        assert get_model(m.to_dict()) == m  # infinity is written as null (JSON) and read back


@pytest.mark.parametrize("spec, params, words", [
    ("nosuch", {}, "unknown forward model 'nosuch'"),
    ("contac", {}, "did you mean 'contact'"),
    ("contact", {"thickness_m": 1.0}, "has no parameter thickness_m"),
    ({"conductance_w_m2k": 3.0}, {}, "a model needs a name"),
    ("contact", {"conductance_w_m2k": -1.0}, "interface conductance"),
    ("contact", {"conductance_w_m2k": float("nan")}, "interface conductance"),
])
def test_bad_model_specs_are_one_line_errors(spec, params, words):
    with pytest.raises(InputError, match=words):
        get_model(spec, **params)


def test_shared_shape_models_answer_amplitude_times_shape():
    t = PAPER.times_s(4.0)
    e = np.array([0.0, 30.0, 892.0, 20000.0, np.inf])
    u = SemiInfinite().response(t, e, PAPER)
    assert u.shape == (5, t.size) and np.all(u[0] == 0) and np.all(np.diff(u[-1]) >= 0)
    assert np.allclose(u, SemiInfinite().weight(e, PAPER)[:, None] * SemiInfinite().shape(t, PAPER)[None, :],
                       rtol=0, atol=0)
    with pytest.raises(InputError, match="no shared response shape"):
        Contact(1000.0).shape(t, PAPER)


@pytest.mark.parametrize("e_o", [30.0, 892.0, 20000.0, 1e9])
def test_contact_tends_to_the_semi_infinite_model_as_conductance_grows(e_o):
    t = PAPER.times_s(10.0)
    semi = SemiInfinite().response(t, [e_o], PAPER)
    dt = 10.0  # degC: the paper's sensor-object difference
    dev = [float(np.max(np.abs(Contact(h).response(t, [e_o], PAPER) - semi))) * dt for h in (1e9, 1e12, 1e15)]
    assert dev[0] > dev[1] > dev[2] or dev[0] == 0
    assert dev[2] <= 1e-9  # the target: 1e-9 degC


def _contact_mpmath(t, e_o, h, sensor) -> float:
    """u(t) by numerical inverse Laplace of w beta exp(-a sqrt(p)) / (p (sqrt(p) + beta)) (Talbot)."""
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 30
    e_s = sensor.effusivity
    w = e_o / (e_s + e_o)
    beta = h * (1.0 / e_s + 1.0 / e_o)
    a = 2.0 * math.sqrt(sensor.tau_s)  # x / sqrt(alpha_s)
    f = lambda p: w * beta * mpmath.exp(-a * mpmath.sqrt(p)) / (p * (mpmath.sqrt(p) + beta))  # noqa: E731
    return float(mpmath.invertlaplace(f, t, method="talbot"))


@pytest.mark.parametrize("e_o, h", [(400.0, 300.0), (20000.0, 3000.0), (892.0, 50.0), (36000.0, 1e5)])
def test_contact_matches_an_independent_inverse_laplace_reference(e_o, h):
    times = [0.05, 0.5, 2.0, 8.0]
    ours = Contact(h).response(times, [e_o], PAPER)[0]
    ref = [_contact_mpmath(t, e_o, h, PAPER) for t in times]
    assert np.allclose(ours, ref, rtol=1e-9, atol=1e-13)


def test_contact_is_stable_at_the_extremes():
    t = np.array([0.0, 1e-12, 0.005, 1.0, 1e4])
    for sensor in (PAPER, PAPER.replace(depth_m=0.0)):
        for h in (1e-6, 1.0, 2000.0, 1e30, math.inf):
            u = Contact(h).response(t, [0.0, 1e-300, 892.0, 1e12, np.inf], sensor)
            assert np.all(np.isfinite(u)) and np.all((u >= 0) & (u <= 1))
            assert np.all(u[0] == 0)  # a perfect insulator changes nothing
    # a lag that grows as contact worsens: at 1 s, worse contact, lower reading
    r = [float(Contact(h).response([1.0], [20000.0], PAPER)[0, 0]) for h in (100.0, 1000.0, 1e4, math.inf)]
    assert r == sorted(r)


def test_slab_model_needs_diffusivity_and_tends_to_semi_infinite_when_thick():
    slab = get_model("slab", thickness_m=1.0, backing="steel")
    t = PAPER.times_s(2.0)
    with pytest.raises(InputError, match="diffusivity"):
        slab.response(t, [600.0], PAPER)
    u = slab.response(t, [600.0], PAPER, diffusivity_m2_s=[1e-7], tolerance=1e-12)
    assert np.max(np.abs(u - SemiInfinite().response(t, [600.0], PAPER))) < 1e-10
    objs = (object_class(600, diffusivity_m2_s=1e-7), object_class(700, diffusivity_m2_s=1e-7))
    assert slab.equivalent_shared_shape(objs, PAPER, contact_s=2.0, tolerance=1e-6) == SemiInfinite()
    thin = get_model("slab", thickness_m=0.0005, backing="steel")
    assert thin.equivalent_shared_shape(objs, PAPER, contact_s=6.0, tolerance=1e-6) is None
    check = thin.check(objs, PAPER, contact_s=6.0, noise_c=0.05, delta_t_c=10.0)
    assert check.holds and not check.details["semi_infinite_holds"]


def test_object_classes_refuse_what_a_model_needs_but_they_lack():
    with pytest.raises(InputError, match="no diffusivity"):
        ObjectClass("x", (1.0, 2.0)).require(("effusivity", "diffusivity_m2_s"))
    wood = object_class(material="wood")
    assert wood.material and wood.diffusivity_range_m2_s is not None and wood.e_range[0] < wood.e_range[1]
    with pytest.raises(InputError, match="either as an effusivity or as a material"):
        object_class()
