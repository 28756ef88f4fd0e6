"""The Monte Carlo ideal observer for models without a shared shape, against the closed form
where both apply, and its dispatch from recognition.ideal.ideal_pair."""

from __future__ import annotations

import pytest

from designkit import SENSORS, InputError, Scene
from designkit.models import get_model
from designkit.objects import object_class
from designkit.recognition.ideal import ideal_pair
from designkit.recognition.ideal_mc import ideal_pair_mc
from designkit.recognition.svm import pair_f1

PAPER = SENSORS["paper"]


@pytest.mark.parametrize("contact_s, e1, e2", [(1.0, 20000, 35000), (0.6, 5000, 6000), (1.5, 1000, 1150)])
def test_monte_carlo_agrees_with_the_closed_form_where_the_model_has_a_shared_shape(contact_s, e1, e2):
    scene = Scene.from_delta_t(contact_s=contact_s, noise_c=0.05, delta_t_c=10.0)
    a, b = object_class(e1), object_class(e2)
    closed = ideal_pair(a, b, PAPER, scene)
    # a contact this good is the semi-infinite model to 1e-12: its Monte Carlo answer is the closed form's
    mc = ideal_pair_mc(a, b, PAPER, scene, model=get_model("contact", conductance_w_m2k=1e15), n_mc=2000, seed=1)
    assert closed.method == "closed-form" and mc.method == "monte-carlo"
    assert abs(mc.accuracy - closed.accuracy) <= 4 * mc.accuracy_standard_error + 1e-3
    assert abs(mc.f1 - closed.f1) <= 4 * mc.standard_error + 1e-3


def test_dispatch_uses_the_closed_form_where_the_extra_physics_is_invisible_and_monte_carlo_otherwise():
    scene = Scene.from_delta_t(contact_s=2.0, noise_c=0.05, delta_t_c=10.0)
    a, b = object_class(20000), object_class(35000)
    assert ideal_pair(a, b, PAPER, scene, model=get_model("contact", conductance_w_m2k=1e15)).method == "closed-form"
    poor = ideal_pair(a, b, PAPER, scene, model=get_model("contact", conductance_w_m2k=200.0), n_mc=300)
    assert poor.method == "monte-carlo" and poor.details["model"] == "contact"
    # a poor contact hides the object: no better than perfect contact (within Monte Carlo error)
    assert poor.accuracy <= ideal_pair(a, b, PAPER, scene).accuracy + 3 * poor.accuracy_standard_error


def test_the_ideal_observer_bounds_the_svm_under_a_model_without_shared_shape():
    scene = Scene.from_delta_t(contact_s=1.0, noise_c=0.05, delta_t_c=10.0)
    model = get_model("contact", conductance_w_m2k=2000.0)
    a, b = object_class(20000), object_class(35000)
    ideal = ideal_pair(a, b, PAPER, scene, model=model, n_mc=1000, seed=2)
    svm = pair_f1(a, b, PAPER, scene, model=model, seed=2)
    assert svm.f1 <= ideal.f1 + 3 * (ideal.standard_error + svm.standard_error)


def test_refusals_are_one_line():
    scene = Scene.from_delta_t(contact_s=1.0, noise_c=0.05, delta_t_c=10.0)
    a, b = object_class(20000), object_class(35000)
    with pytest.raises(InputError, match="at least 10"):
        ideal_pair_mc(a, b, PAPER, scene, model="contact", n_mc=3)
    varied = Scene(contact_s=1.0, sensor_temp_c=32.5, sensor_temp_spread_c=2.5)
    with pytest.raises(InputError, match="fixed initial conditions"):
        ideal_pair_mc(a, b, PAPER, varied, model="contact")
    with pytest.raises(InputError, match="no diffusivity"):
        ideal_pair_mc(a, b, PAPER, scene, model=get_model("slab", thickness_m=0.001))


def test_a_rig_scene_is_scored_on_whitened_readings_and_still_bounds_the_svm(paper_sensor):
    """Correlated noise and a recorder's window take the Monte Carlo route, which whitens the noise: the
    ideal F1 stays above the SVM's on the same touches, and differs from the white-noise answer."""
    from designkit import Scene
    from designkit.objects import object_class
    from designkit.recognition.ideal import ideal_method, ideal_pair
    from designkit.recognition.svm import pair_f1

    a, b = object_class(20000), object_class(5000)
    rig = Scene(contact_s=1.2, noise_c=0.05, sensor_temp_c=32.0, noise_correlation_s=0.5, onset_s=0.4)
    assert ideal_method(a.e_range, b.e_range, paper_sensor, rig) == "monte-carlo"
    ideal = ideal_pair(a, b, paper_sensor, rig, n_mc=300, seed=1)
    white = ideal_pair(a, b, paper_sensor, rig.replace(noise_correlation_s=0.0), n_mc=300, seed=1)
    svm = pair_f1(a, b, paper_sensor, rig, trials=100, seed=2)
    assert ideal.f1 >= svm.f1 - 2 * svm.standard_error and abs(ideal.f1 - white.f1) > 0.02
