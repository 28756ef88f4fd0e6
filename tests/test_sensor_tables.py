"""Tables for your sensor (issue 34): `tables build --sensor FILE` builds and registers the table a calibrated
sensor's questions need; `--sensor FILE` questions answer from it; bad input is refused in one line.

The build here is tiny (2 materials, 3 contact times, 6 trials): seconds. The 10-minute build of the paper's 12
materials and the coverage of its intervals are measured in benchmarks/bench_sensor_table.py.
"""

from __future__ import annotations

import json

import pytest

from designkit import SENSORS
from designkit._validation import InputError
from designkit.sensor import load_sensor

#: The rig's conditions as calibration records them (sensor file version 2).
RIG = {"noise_c": 0.02, "noise_source": "test", "pre_contact_noise_c": 0.001, "residual_rms_c": 0.02,
       "sensor_temp_c": {"mean": 29.5, "sd": 0.1}, "object_temp_c": {"mean": 22.5, "sd": 0.3},
       "delta_t_c": {"mean": 7.0, "sd": 0.3}, "sensor_temp_spread_c": 0.52, "onset": "force above 2 N",
       "onset_offset_s": -0.3, "contact_ramp": {"rise_s": 0.75, "to_share": 0.9}, "n_touches": 24}


def _rig(name: str = "rig", **conditions):
    """A calibrated sensor whose model (contact conductance) has no closed-form ideal observer, as the real rig's."""
    return SENSORS["paper"].replace(name=name, model={"name": "contact", "params": {"conductance_w_m2k": 1800.0},
                                                      "time_offset_s": -0.3}, conditions={**RIG, **conditions})


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """One tiny table built with the command itself, registered in a data folder of its own."""
    import os

    from typer.testing import CliRunner

    from designkit.cli import app

    home = tmp_path_factory.mktemp("sensor-tables")
    sensor_file = home / "rig.yaml"
    _rig().to_yaml(sensor_file)
    old = os.environ.get("DESIGNKIT_DATA_DIR")
    os.environ["DESIGNKIT_DATA_DIR"] = str(home / "data")
    try:
        res = CliRunner().invoke(app, ["tables", "build", "--sensor", str(sensor_file), "--m", "wood", "--m", "glass",
                                       "--contact-points", "3", "--trials", "6", "--jobs", "1", "--json"])
    finally:
        if old is None:
            del os.environ["DESIGNKIT_DATA_DIR"]
        else:
            os.environ["DESIGNKIT_DATA_DIR"] = old
    assert res.exit_code == 0, res.output
    return {"home": home, "sensor_file": sensor_file, "data": home / "data", "summary": json.loads(res.stdout)}


@pytest.fixture
def data_dir(built, monkeypatch):
    monkeypatch.setenv("DESIGNKIT_DATA_DIR", str(built["data"]))
    return built["data"]


def test_the_build_sweeps_the_rigs_conditions_and_registers_the_table(built, data_dir):
    from designkit.rig import model_start_s
    from designkit.tables.registry import registry_dir, sensor_digest, table_for_sensor

    s = built["summary"]
    cfg = s["config"]
    sensor = load_sensor(built["sensor_file"])
    # sigma/dT: the rig's own (noise 0.02 over dT 7); the model: the file's; the touches: the rig's (as --exact's)
    assert cfg["noise_ratio"] == pytest.approx([0.02 / 7], rel=1e-12) and cfg["rig_scene"] is True
    assert cfg["model"] == {"name": "contact", "conductance_w_m2k": 1800.0}
    # contact counted from the detected onset, on the sensor's time scale (here the thermistor's tau, 1.345 s,
    # longer than the ramp's 0.75 s: one to eight of them, capped at the exact route's 10 s of model time),
    # stored as the model counts; the rig's repeats
    assert s["contacts_from_onset_s"] == pytest.approx([1.345, 3.611, 9.7], abs=1e-3)
    assert cfg["max_repeats"] == 2
    assert cfg["contact_s"] == pytest.approx([c - model_start_s(sensor) for c in s["contacts_from_onset_s"]])
    assert s["effusivity_span"] == {"min": 240.0, "max": 1680.0, "source": "materials Wood, Glass"}
    assert cfg["e_max"] - cfg["e_min"] == 80.0 * cfg["intervals"]  # the class width of --exact and svm-fine
    assert s["sensor"]["digest"] == sensor_digest(sensor)
    assert registry_dir() == data_dir / "sensor-tables" and s["registry_entry"].startswith(str(data_dir))
    table = table_for_sensor(sensor)
    assert table is not None and table.header["content_hash"] == s["content_hash"]
    assert not any((data_dir / "sensor-tables").glob("*/work-*"))  # the chunks go once the table is registered


def test_a_sensor_question_answers_from_its_table_counted_from_the_onset(built, data_dir, cli):
    from designkit.query.table import min_contact

    res = cli("min-contact", "--sensor", built["sensor_file"], "--m1", "wood", "--m2", "glass", "--json")
    assert res.exit_code == 0, res.output
    d = json.loads(res.stdout)
    assert d["route"] == "table" and d["table"]["name"] == "sensor-rig"
    assert d["scene"]["conditions"]["noise_c"] == {"value": 0.02, "source": "sensor file"}
    assert d["scene"]["conditions"]["delta_t_c"] == {"value": 7.0, "source": "sensor file"}
    # the table route's answer at the rig's conditions, moved from the model's first heat flow to the onset
    lib = min_contact(m1="wood", m2="glass", noise_c=0.02, delta_t_c=7.0, table=built["summary"]["table"],
                      ideal_table=None, ideal_bound=False)
    assert lib.value is not None and d["value"] == pytest.approx(lib.value - 0.3)
    assert any("table built for sensor rig" in n for n in d["notes"])


def test_an_edited_or_older_sensor_file_has_no_table(built, data_dir):
    from designkit.tables.registry import table_for_sensor

    sensor = load_sensor(built["sensor_file"])
    assert table_for_sensor(sensor) is not None
    assert table_for_sensor(sensor.replace(conditions={**RIG, "noise_c": 0.03})) is None  # recalibrated: other digest
    assert table_for_sensor(sensor.replace(provenance={"note": "changes no answer"})) is not None
    assert table_for_sensor(SENSORS["paper"]) is None and table_for_sensor(sensor.replace(conditions=None)) is None


def test_a_question_outside_the_tables_span_is_refused_in_one_line(built, data_dir, cli):
    res = cli("min-contact", "--sensor", built["sensor_file"], "--m1", "wood", "--m2", "stainless steel")
    assert res.exit_code == 2
    line = res.output.strip()
    assert "\n" not in line and "outside" in line and "--exact" in line and "tables build" in line
    noisy = cli("min-contact", "--sensor", built["sensor_file"], "--m1", "wood", "--m2", "glass", "--noise", "0.5")
    assert noisy.exit_code == 2 and "sigma/dT" in noisy.output and "--exact" in noisy.output
    assert "{" not in noisy.output and "--e-range" not in noisy.output  # a wider effusivity span would not help


def test_a_table_of_another_sensor_is_never_used(built, data_dir, cli, tmp_path):
    from designkit.tables.registry import entry_path, register_table, sensor_digest, table_for_sensor

    table = built["summary"]["table"]
    other = _rig(name="rig", noise_c=0.05)
    with pytest.raises(InputError, match="built for sensor 'rig' as it was then"):
        register_table(other, table)
    # an entry edited to name the other sensor's digest: refused when asked, in one line
    entry = json.loads(entry_path(load_sensor(built["sensor_file"])).read_text())
    entry["sensor_digest"] = sensor_digest(other)
    entry_path(other).write_text(json.dumps(entry))
    with pytest.raises(InputError, match="another content"):
        table_for_sensor(other)
    other_file = tmp_path / "other.yaml"
    other.to_yaml(other_file)
    res = cli("min-contact", "--sensor", other_file, "--m1", "wood", "--m2", "glass")
    assert res.exit_code == 2 and "another content" in res.output and len(res.output.strip().splitlines()) == 1
    entry_path(other).unlink()


def test_the_build_refuses_a_sensor_without_the_rigs_conditions(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("DESIGNKIT_DATA_DIR", str(tmp_path / "data"))
    old = tmp_path / "old.yaml"
    SENSORS["paper"].replace(name="old").to_yaml(old)
    res = cli("tables", "build", "--sensor", old, "--m", "wood", "--m", "glass")
    assert res.exit_code == 2 and "records no rig conditions" in res.output
    preset = cli("tables", "build", "--sensor", "paper")
    assert preset.exit_code == 2 and "is a preset" in preset.output
    both = cli("tables", "build", "--sensor", old, "--materials", "paper12", "--m", "wood")
    assert both.exit_code == 2 and "give one of" in both.output
    assert not (tmp_path / "data").exists()  # refused before any work


def test_one_question_has_one_answer_on_every_surface(built, data_dir, cli, tmp_path):
    """A rig sensor file's scene is resolved once, in the library: the library's scalar and array answers, the
    CLI's --json and its --batch give the same number, interval and conditions (each value with its source)."""
    from designkit.query import min_contact

    f = str(built["sensor_file"])
    batch = tmp_path / "pairs.csv"
    batch.write_text("m1,m2\nwood,glass\nwood,glass\n")
    for given, cli_given in (({}, ()), ({"noise_c": 0.04, "delta_t_c": 14.0}, ("--noise", "0.04", "--delta-t", "14"))):
        lib = min_contact(m1="wood", m2="glass", sensor=f, **given)
        arr = min_contact(m1=["wood", "glass"], m2=["glass", "wood"], sensor=f, **given)
        res = cli("min-contact", "--sensor", f, "--m1", "wood", "--m2", "glass", "--json", *cli_given)
        rows = cli("min-contact", "--sensor", f, "--batch", batch, "--json", *cli_given)
        assert res.exit_code == 0 and rows.exit_code == 0, res.output + rows.output
        d, rec = json.loads(res.stdout), json.loads(rows.stdout)[0]
        one = json.loads(json.dumps(lib.to_dict()))
        assert lib.route == d["route"] == rec["route"] == "table" and lib.value is not None
        assert d["value"] == one["value"] == float(arr.value[0]) == rec["value"]
        assert d["interval"] == one["interval"]
        assert (rec["interval_low"], rec["interval_high"]) == (d["interval"]["low"], d["interval"]["high"])
        conditions = one["scene"]["conditions"]
        assert d["scene"]["conditions"] == conditions == arr.to_dict()[0]["conditions"] == rec["conditions"]
        assert conditions["noise_c"] == ({"value": 0.02, "source": "sensor file"} if not given
                                         else {"value": 0.04, "source": "user"})
        assert conditions["delta_t_c"] == ({"value": 7.0, "source": "sensor file"} if not given
                                           else {"value": 14.0, "source": "user"})
        assert conditions["onset_offset_s"] == {"value": -0.3, "source": "sensor file"}
        assert d["route_reason"] == one["route_reason"] and "built for sensor rig" in d["route_reason"]
        if not given:  # the matrix reads the sensor's registered table too, and gives the same answer
            mat = cli("matrix", "--sensor", f, "--m", "wood", "--m", "glass", "--no-multiclass", "--json")
            assert mat.exit_code == 0, mat.output
            (cell,) = json.loads(mat.stdout)["cells"]
            assert cell["value"] == d["value"], cell
            assert (cell["interval"]["low"], cell["interval"]["high"]) == (d["interval"]["low"], d["interval"]["high"])


def test_a_registered_sensors_question_from_a_fresh_shell_reads_no_yaml_and_no_schema(built, data_dir):
    """What the build checked (the sensor file's bytes, the shipped materials, the table's content) a later
    process trusts by its hash: neither pydantic nor yaml is imported for the question (issue 34's start-up)."""
    import subprocess
    import sys

    code = ("import sys; from designkit.query import min_contact; "
            f"a = min_contact(m1='wood', m2='glass', sensor={str(built['sensor_file'])!r}); "
            "print(a.route, a.value is not None, sorted(m for m in ('pydantic', 'yaml') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["table", "True", "[]"]


def test_a_checked_record_answers_only_for_the_same_bytes(built, data_dir, tmp_path):
    """The record of a checked sensor file holds for exactly its bytes: the same sensor read either way; an edited
    file is read the long way, and its bad input refused in the same one line as without any record."""
    from designkit.sensor import Sensor
    from designkit.tables.registry import sensor_digest

    recorded = load_sensor(built["sensor_file"])
    long_way = Sensor.from_yaml(built["sensor_file"])
    assert recorded == long_way and sensor_digest(recorded) == sensor_digest(long_way)
    assert recorded.conditions == long_way.conditions and recorded.provenance == long_way.provenance
    bad = tmp_path / "rig.yaml"
    bad.write_text(built["sensor_file"].read_text().replace("effusivity: 892.0", "effusivity: [892.0]"))
    with pytest.raises(InputError) as exc:
        load_sensor(bad)
    with pytest.raises(InputError) as plain:
        Sensor.from_yaml(bad)
    assert str(exc.value) == str(plain.value) and "effusivity" in str(exc.value)


def test_a_registered_tables_content_other_than_checked_gets_the_schemas_verdict(built, data_dir):
    """``checked_hash`` skips the header's schema only for the content it names."""
    from designkit.tables.registry import entry_path
    from designkit.tables.store import load_table

    npz = built["summary"]["table"]
    entry = json.loads(entry_path(load_sensor(built["sensor_file"])).read_text())
    ok = load_table(npz, checked_hash=entry["content_hash"])
    assert ok.checked and not ok.shipped
    assert not load_table(npz).checked and not load_table(npz, checked_hash="sha256:other").checked


def test_a_damaged_record_is_passed_over_for_the_file_itself(built, tmp_path, monkeypatch):
    from designkit.sensor import Sensor, remember_checked_file

    monkeypatch.setenv("DESIGNKIT_DATA_DIR", str(tmp_path / "data"))
    f = tmp_path / "copy.yaml"
    f.write_bytes(built["sensor_file"].read_bytes())
    s = Sensor.from_yaml(f)
    remember_checked_file(f, s)
    [rec] = (tmp_path / "data" / "checked-files").glob("sensor-*.json")
    d = json.loads(rec.read_text())
    d["data"]["effusivity"] = "not a number"
    rec.write_text(json.dumps(d))
    assert load_sensor(f) == s and load_sensor(f).to_dict() == s.to_dict()
