"""Sensor files record their forward model, and every command that takes --sensor answers with it (issue 14)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from designkit import SENSORS, InputError
from designkit.models import get_model, load_sensor_model, sensor_model
from designkit.sensor import Sensor, load_sensor

CONTACT = {"name": "contact", "params": {"conductance_w_m2k": 3000.0}, "time_offset_s": 0.25,
           "contact_spread": {"metal": 1.5}, "object_temperature": {"metal": "passive", "wood": 21.5},
           "candidate": "contact"}


@pytest.fixture
def contact_file(tmp_path):
    path = tmp_path / "my-sensor.yaml"
    Sensor(1982.0, 1.1e-9, name="my-sensor", noise_c=0.005, model=CONTACT).to_yaml(path)
    return path


def test_a_sensor_file_gives_back_the_sensor_and_its_model(contact_file):
    sen, fm = load_sensor_model(contact_file)
    assert sen.effusivity == 1982.0 and sen.model["contact_spread"] == {"metal": 1.5}
    assert fm == get_model("contact", conductance_w_m2k=3000.0)
    assert sen.model_name == "contact" and sen.model["object_temperature"]["wood"] == 21.5
    # an explicit model overrides the file's; the file itself is unchanged by loading
    assert load_sensor_model(contact_file, "semi-infinite")[1].name == "semi-infinite"
    assert load_sensor(contact_file) == sen


def test_old_sensor_files_without_a_model_load_as_the_semi_infinite_model(tmp_path):
    path = tmp_path / "old.yaml"
    path.write_text("designkit_sensor: 1\nname: old\neffusivity: 900\ndiffusivity_m2_s: 1.2e-9\n")
    sen, fm = load_sensor_model(path)
    assert sen.model is None and fm.name == "semi-infinite" and sen.model_name == "semi-infinite"
    assert "model" not in sen.to_dict()          # an old file written back stays an old file
    assert sensor_model(SENSORS["paper"]).name == "semi-infinite"


def test_infinite_parameters_survive_the_file_as_null(tmp_path):
    layered = get_model("layered", film_thickness_m=2e-4, backing_effusivity_ws05_m2k=400.0, lag_s=0.5)
    assert layered.conductance_w_m2k == float("inf")
    path = tmp_path / "s.yaml"
    Sensor(1000.0, 1e-9, model={"name": "layered", "params": layered.parameters()}).to_yaml(path)
    assert "conductance_w_m2k: null" in path.read_text()
    assert load_sensor_model(path)[1] == layered


@pytest.mark.parametrize("block, message", [
    ("model: layered", "model: expected"),
    ("model: {params: {}}", "model.name: missing key"),
    ("model: {name: layered, colour: red}", "model.colour: unknown key"),
    ("model: {name: layered, params: [1, 2]}", "model.params"),
    ("model: {name: layered, time_offset_s: soon}", "model.time_offset_s: expected a number"),
])
def test_a_malformed_model_record_is_one_line_naming_the_key(tmp_path, block, message):
    path = tmp_path / "bad.yaml"
    path.write_text(f"effusivity: 900\ndiffusivity_m2_s: 1.2e-9\n{block}\n")
    with pytest.raises(InputError, match=message) as exc:
        load_sensor(path)
    assert "\n" not in str(exc.value) and str(path) in str(exc.value)


def test_a_record_naming_an_unknown_model_or_parameter_is_refused_when_used(tmp_path):
    for params, message in (({"name": "layerd"}, "did you mean 'layered'"),
                            ({"name": "contact", "params": {"thickness_m": 1}}, "has no parameter thickness_m")):
        path = tmp_path / "s.yaml"
        Sensor(900.0, 1e-9, name="s", model=params).to_yaml(path)
        with pytest.raises(InputError, match=message) as exc:
            load_sensor_model(path)
        assert "sensor 's'" in str(exc.value)


def test_an_identified_model_is_what_the_sensor_file_records():
    """identify -> Identification.sensor(): the record rebuilds the identified model exactly."""
    from designkit.calibration.identify import identify
    from designkit.calibration.trials import Trial

    rng = np.random.default_rng(0)
    truth = Sensor(1000.0, 1.5e-9)
    model = get_model("contact", conductance_w_m2k=2500.0)
    t = np.arange(-200, 1001) / 200.0
    trials = []
    for name, eo in (("wood", 400.0), ("granite", 2500.0)):
        u = np.zeros(t.size)
        u[t > 0] = model.response(t[t > 0], [eo], truth)[0]
        for i in range(3):
            y = 29.5 + (22.5 - 29.5) * u + rng.normal(0, 0.01, t.size)
            trials.append(Trial(t, y, np.full(t.size, 22.5), np.full(t.size, 4.5), name, source=f"{name}{i}"))
    res = identify(trials, "contact", ranges={"wood": (331.0, 506.46), "granite": (2252.32, 2749.87)})
    sen = res.sensor(name="fitted")
    assert sen.model["candidate"] == "contact" and sen.model["name"] == "contact"
    assert sen.model["object_temperature"] == {"granite": "passive", "wood": "passive"}
    assert sen.model["time_offset_s"] == pytest.approx(res.parameter("time_offset_s").value)
    again = Sensor.from_dict(json.loads(json.dumps(sen.to_dict())))   # plain data all through
    assert sensor_model(again) == res.model()
    assert sensor_model(again).conductance_w_m2k == pytest.approx(2500.0 * sen.effusivity / 1000.0, rel=0.05)


# ------------------------------------------------------------------ the commands
def _json(res):
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout)


def test_simulate_and_f1_answer_with_the_file_model_and_say_so(cli, contact_file):
    sim = _json(cli("simulate", "--e", "400", "--contact", "1", "--sensor", contact_file, "--json"))
    assert sim["model"]["name"] == "contact" and sim["model_source"] == "sensor file"
    direct = _json(cli("simulate", "--e", "400", "--contact", "1", "--sensor", contact_file, "--conductance",
                       "3000", "--json"))
    assert direct["temperature_c"] == sim["temperature_c"] and direct["model_source"] == "options"
    semi = _json(cli("simulate", "--e", "400", "--contact", "1", "--sensor", contact_file, "--model",
                     "semi-infinite", "--json"))
    assert semi["model"]["name"] == "semi-infinite" and semi["temperature_c"] != sim["temperature_c"]
    text = cli("f1", "--e1", "400", "--e2", "2000", "--contact", "1", "--trials", "20", "--sensor", contact_file)
    assert text.exit_code == 0, text.output
    assert "(recorded in sensor file my-sensor)" in text.stdout and "model contact" in text.stdout
    over = cli("simulate", "--e", "400", "--sensor", contact_file, "--model", "semi-infinite")
    assert "from the options; sensor my-sensor was identified with contact" in over.stdout


def test_questions_route_a_sensor_file_to_the_exact_route_and_say_why(cli, contact_file):
    ans = _json(cli("distinguishable", "--e1", "400", "--e2", "2000", "--contact", "1", "--sensor", contact_file,
                    "--trials", "20", "--repeats", "1", "--n-mc", "50", "--json"))
    assert ans["route"] == "exact" and ans["model"]["name"] == "contact"
    assert ans["sensor"]["name"] == "my-sensor" and ans["sensor"]["model"]["name"] == "contact"
    assert any("shipped tables are for the paper sensor, not my-sensor and the semi-infinite model, not contact"
               in n for n in ans["notes"])
    assert any("recorded in sensor file my-sensor" in n for n in ans["notes"])
    assert ans["route_reason"].startswith("the shipped tables are for the paper sensor, not my-sensor")


def test_a_table_built_for_another_sensor_never_answers_for_this_one(cli, contact_file):
    named = cli("min-contact", "--e1", "35000", "--e2", "20000", "--sensor", contact_file, "--table", "svm-paper")
    assert named.exit_code == 2 and "built for sensor 'paper', not 'my-sensor'" in named.output
    mat = cli("matrix", "--m", "copper", "--m", "glass", "--sensor", contact_file)
    assert mat.exit_code == 2 and "matrix reads tables only" in mat.output
    exp = cli("export", "--table", "svm-paper", "--sensor", contact_file, "--out", "x.json")
    assert exp.exit_code == 2 and "not sensor 'my-sensor' with the contact model" in exp.output
    same = cli("matrix", "--m", "copper", "--m", "glass", "--sensor", "paper", "--no-multiclass", "--json")
    assert same.exit_code == 0, same.output


def test_a_forced_sensor_file_is_named_each_time_it_is_used(cli, tmp_path):
    path = tmp_path / "forced.yaml"
    SENSORS["paper"].replace(name="forced", provenance={"problems": ["conflict: metal allows e_s in [87, 176]"]}
                             ).to_yaml(path)
    res = cli("simulate", "--e", "400", "--contact", "1", "--sensor", path, "--json")
    assert res.exit_code == 0
    assert "sensor forced: its calibration reported: conflict" in res.stderr
    json.loads(res.stdout)  # the warning stays off stdout


def test_a_sweep_config_takes_the_sensor_file_model(contact_file):
    from designkit.sweep.config import SweepConfig

    cfg = SweepConfig(sensor=str(contact_file), intervals=4, contact_s=(1.0,))
    assert cfg.model == get_model("contact", conductance_w_m2k=3000.0)
    assert SweepConfig(sensor=str(contact_file), intervals=4, contact_s=(1.0,), model="semi-infinite"
                       ).model.name == "semi-infinite"


# ------------------------------------------------ the rig as calibrated (issue 34): conditions and the onset
RIG = {"noise_c": 0.02, "noise_source": "test", "pre_contact_noise_c": 0.001, "residual_rms_c": 0.02,
       "sensor_temp_c": {"mean": 29.5, "sd": 0.1}, "object_temp_c": {"mean": 22.5, "sd": 0.3},
       "delta_t_c": {"mean": 7.0, "sd": 0.3}, "sensor_temp_spread_c": 0.52, "onset": "force above 2 N",
       "onset_offset_s": -0.3, "contact_ramp": {"rise_s": 0.75, "to_share": 0.9}, "n_touches": 24}


@pytest.fixture
def rig_file(tmp_path):
    path = tmp_path / "rig.yaml"
    Sensor(1500.0, 1.2e-9, name="rig", noise_c=0.001, conditions=RIG,
           model={"name": "semi-infinite", "params": {}, "time_offset_s": -0.3}).to_yaml(path)
    return path


def test_sensor_file_version_2_records_the_rigs_conditions_and_older_files_load(rig_file, tmp_path):
    text = rig_file.read_text()
    assert "designkit_sensor: 2" in text and "conditions:" in text
    assert load_sensor(rig_file).conditions["delta_t_c"] == {"mean": 7.0, "sd": 0.3}
    old = tmp_path / "old.yaml"
    old.write_text("designkit_sensor: 1\nname: old\neffusivity: 900\ndiffusivity_m2_s: 1.2e-9\n")
    assert load_sensor(old).conditions is None
    newer = tmp_path / "newer.yaml"
    newer.write_text("designkit_sensor: 3\nname: new\neffusivity: 900\ndiffusivity_m2_s: 1.2e-9\n")
    with pytest.raises(InputError) as exc:
        load_sensor(newer)
    assert "written by a newer designkit; upgrade designkit" in str(exc.value) and "\n" not in str(exc.value)
    with pytest.raises(InputError, match="unknown key.*humidity"):
        Sensor(900.0, 1.2e-9, conditions={"humidity": 0.4})


def test_a_question_takes_the_rigs_conditions_unless_given_and_says_where_each_came_from(rig_file):
    from designkit.rig import resolve_scene

    sen = load_sensor(rig_file)
    sc = resolve_scene(sen, {"noise_c": None, "delta_t_c": 5.0, "sensor_temp_spread_c": None, "contact_s": 1.0})
    assert sc.values == {"noise_c": 0.02, "delta_t_c": 5.0, "sensor_temp_spread_c": 0.0, "contact_s": 1.3}
    assert sc.sources == {"noise_c": "sensor file", "delta_t_c": "user", "sensor_temp_spread_c": "default",
                          "contact_s": "user"}
    assert sc.start_s == pytest.approx(-0.3) and any("detected onset (force above 2 N)" in n for n in sc.notes)
    assert any("--sensor-temp-spread 0.52 plays it" in n for n in sc.notes)
    paper = resolve_scene(SENSORS["paper"], {"noise_c": None, "delta_t_c": None, "contact_s": 1.0})
    assert paper.values == {"noise_c": 0.05, "delta_t_c": 10.0, "contact_s": 1.0} and paper.start_s is None
    with pytest.raises(InputError, match="before the model's first heat flow"):
        resolve_scene(load_sensor(rig_file).replace(model={"name": "semi-infinite", "time_offset_s": 0.5}),
                      {"contact_s": 0.4})


def test_min_contact_counts_from_the_rigs_detected_onset():
    """The model's contact counts from the first heat flow, 0.3 s before the onset here: the rig needs 0.3 s less."""
    from designkit import query
    from designkit.rig import RigScene, for_rig

    ans = query.ask("min-contact", route="table", e1=35000.0, e2=20000.0, noise_c=0.05, delta_t_c=10.0)
    rig = RigScene({"noise_c": 0.05, "delta_t_c": 10.0}, {"noise_c": "sensor file", "delta_t_c": "default"}, -0.3,
                   ("contact time counts from the rig's detected onset",))
    got = for_rig(ans, rig)
    assert got.value == pytest.approx(ans.value - 0.3)
    assert got.interval[0] == pytest.approx(ans.interval[0] - 0.3)
    assert got.ideal_bound.value == pytest.approx(ans.ideal_bound.value - 0.3)
    d = got.to_dict()
    assert d["scene"]["conditions"]["noise_c"] == {"value": 0.05, "source": "sensor file"}
    assert d["scene"]["conditions"]["onset_offset_s"] == {"value": -0.3, "source": "sensor file"}
    assert "contact time counts from the rig's detected onset" in d["notes"]


def test_the_cli_answers_for_the_rig_as_calibrated(cli, rig_file):
    r = cli("distinguishable", "--e1", "400", "--e2", "1500", "--contact", "1", "--sensor", rig_file,
            "--trials", "30", "--repeats", "1", "--json")
    assert r.exit_code in (0, 3), r.output
    d = json.loads(r.stdout)
    c = d["scene"]["conditions"]
    assert c["noise_c"] == {"value": 0.02, "source": "sensor file"}
    assert c["delta_t_c"] == {"value": 7.0, "source": "sensor file"}
    assert c["contact_s"]["value"] == 1.0 and c["contact_s"]["model_contact_s"] == pytest.approx(1.3)
    assert c["contact_s"]["counted_from"] == "detected onset" and d["scene"]["contact_s"] == 1.0
    # the library, asked the same question, answers the same: the scene is resolved there, once
    from designkit.query import distinguishable

    lib = json.loads(json.dumps(distinguishable(e1=400.0, e2=1500.0, contact_s=1.0, sensor=str(rig_file), trials=30,
                                                repeats=1).to_dict()))
    assert lib["scene"] == d["scene"] and lib["value"] == d["value"] and lib["details"] == d["details"]


@pytest.mark.slow
def test_the_monte_carlo_ideal_bound_plays_the_rigs_scene(rig_file):
    """The bound is the ideal observer of the touches the SVM sees: a rig's correlated noise averages away
    less than white noise over a touch, so its bound comes later (before, the bound was always taken under
    white noise from the first heat flow, 0.22 s where the rig's SVM needed 1.09 s)."""
    from designkit.objects import ObjectClass
    from designkit.query.ideal_mc_bound import mc_ideal_min_contact

    rig = load_sensor(rig_file)
    correlated = rig.replace(conditions={**rig.conditions, "noise_correlation_s": 0.68})
    white = rig.replace(conditions=None)
    a, b = ObjectClass("a", (400.0, 480.0)), ObjectClass("b", (1500.0, 1580.0))
    kw = dict(noise_c=0.2, delta_t_c=7.0, max_contact_s=4.0, n_mc=300, seed=2)
    got_white = mc_ideal_min_contact(a, b, white, **kw)
    got_rig = mc_ideal_min_contact(a, b, correlated, **kw)
    assert got_white.value is not None and got_rig.value is not None
    assert got_rig.low > got_white.high
