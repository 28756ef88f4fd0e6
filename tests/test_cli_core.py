"""`designkit simulate` and `designkit f1` through the CLI, as a user runs them."""

from __future__ import annotations

import csv
import json
import shutil
import subprocess
import sys

import numpy as np
import pytest


def test_simulate_csv_json_and_plot(cli, tmp_path):
    out, png = tmp_path / "curve.csv", tmp_path / "curve.png"
    r = cli("simulate", "--e", 20000, "--contact", 4, "--trials", 3, "--seed", 1, "--out", out, "--plot", png)
    assert r.exit_code == 0, r.output
    assert r.stdout == ""  # --out FILE holds the output (the curves' CSV without --format)
    rows = list(csv.reader(out.open()))
    assert rows[0] == ["time_s", "temperature_c_1", "temperature_c_2", "temperature_c_3"]
    assert len(rows) == 1 + 801
    data = np.array(rows[1:], dtype=float)
    assert data[0, 0] == 0.0 and data[-1, 0] == pytest.approx(4.0)
    assert png.stat().st_size > 5000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    j = cli("simulate", "--e", 20000, "--contact", 4, "--trials", 3, "--seed", 1, "--json")
    payload = json.loads(j.stdout)
    assert np.allclose(np.array(payload["temperature_c"]).T, data[:, 1:], rtol=1e-9)
    assert payload["time_s"][-1] == pytest.approx(4.0)
    assert payload["scene"]["noise_c"] == 0.05 and payload["sensor"]["name"] == "paper"


def test_simulate_noise_free_matches_physics(cli):
    from designkit.models.semi_infinite import sensor_temperature

    r = cli("simulate", "--e", 5000, "--contact", 2, "--noise", 0, "--sensor-temp", 30, "--ambient", 20, "--json")
    p = json.loads(r.stdout)
    ref = sensor_temperature(np.array(p["time_s"]), 5000, 30, 20, 892.0, (80e-6) ** 2 / (4 * 1.19e-9))
    np.testing.assert_allclose(p["temperature_c"][0], ref, rtol=1e-12)


def test_f1_json_keys_and_values(cli):
    r = cli("f1", "--e1", 35000, "--e2", 20000, "--contact", 2, "--trials", 40, "--json")
    assert r.exit_code == 0, r.output
    p = json.loads(r.stdout)
    for key in ("svm_f1", "ideal_f1", "fold_f1", "scene", "ideal_accuracy", "svm_standard_error"):
        assert key in p
    assert len(p["fold_f1"]) == 3 and p["svm_f1"] == pytest.approx(np.mean(p["fold_f1"]))
    assert p["ideal_f1"] == pytest.approx(1.0, abs=1e-6) and p["svm_f1"] >= 0.9
    assert p["scene"]["delta_t_c"] == 10 and p["scene"]["noise_c"] == 0.05 and p["scene"]["contact_s"] == 2


def test_f1_human_output(cli):
    r = cli("f1", "--e1", 35000, "--e2", 20000, "--contact", 1, "--trials", 30)
    assert r.exit_code == 0
    assert "SVM F1" in r.stdout and "ideal F1" in r.stdout


@pytest.mark.parametrize("args,needle", [
    (["f1", "--e1", "-5", "--e2", "20000"], "positive"),
    (["f1", "--e1", "nan", "--e2", "20000"], "number"),
    (["f1", "--e1", "inf", "--e2", "20000"], "finite"),
    (["f1", "--e1", "20000", "--e2", "20000"], "equal"),
    (["f1", "--e1", "2000", "--e2", "20000", "--width", "0"], "width"),
    (["f1", "--e1", "2000", "--e2", "20000", "--contact", "0"], "contact"),
    (["f1", "--e1", "2000", "--e2", "20000", "--contact", "-1"], "contact"),
    (["f1", "--e1", "2000", "--e2", "20000", "--noise", "-0.1"], "noise"),
    (["f1", "--e1", "2000", "--e2", "20000", "--folds", "1"], "folds"),
    (["f1", "--e1", "2000", "--e2", "20000", "--trials", "2"], "trials"),
    (["f1", "--e1", "abc", "--e2", "20000"], "--e1"),
    (["f1", "--e2", "20000"], "--e1"),
    (["simulate", "--e", "-1"], "positive"),
    (["simulate", "--e", "100", "--sensor", "missing.yaml"], "cannot read"),
    (["simulate", "--e", "100", "--trials", "0"], "trials"),
])
def test_bad_input_is_one_line_and_exit_2(cli, args, needle):
    r = cli(*args)
    assert r.exit_code == 2, r.output
    err = r.stderr.strip()
    assert len(err.splitlines()) == 1 and err.startswith("Error:") and needle in err
    assert "Traceback" not in r.output


def test_console_script_end_to_end(tmp_path):
    exe = shutil.which("designkit") or str(__import__("pathlib").Path(sys.executable).with_name("designkit"))
    ok = subprocess.run([exe, "f1", "--e1", "35000", "--e2", "20000", "--contact", "2", "--trials", "30", "--json"],
                        capture_output=True, text=True, timeout=120)
    assert ok.returncode == 0, ok.stderr
    assert json.loads(ok.stdout)["svm_f1"] >= 0.9
    bad = subprocess.run([exe, "f1", "--e1", "-1", "--e2", "3"], capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "Traceback" not in bad.stderr


# ------------------------------------------------------------------ forward models
def test_simulate_with_a_contact_model_lags_by_the_models_own_response(cli, paper_sensor):
    from designkit.models import Contact, SemiInfinite

    args = ("simulate", "--e", 20000, "--contact", 2, "--noise", 0, "--sensor-temp", 35, "--ambient", 25, "--json")
    semi = json.loads(cli(*args).stdout)
    r = cli(*args, "--model", "contact", "--conductance", 800)
    assert r.exit_code == 0, r.output
    lag = json.loads(r.stdout)
    assert lag["model"] == {"name": "contact", "conductance_w_m2k": 800.0} and semi["model"] == {"name": "semi-infinite"}
    t = np.array(lag["time_s"])
    u_contact = Contact(800.0).response(t, [20000.0], paper_sensor)[0]
    u_semi = SemiInfinite().response(t, [20000.0], paper_sensor)[0]
    got = np.array(lag["temperature_c"][0]) - np.array(semi["temperature_c"][0])
    np.testing.assert_allclose(got, (25 - 35) * (u_contact - u_semi), rtol=0, atol=1e-12)
    assert got[-1] > 0.01  # the sensor cools more slowly through the imperfect contact
    assert lag["contact_temperature_c"] is None and semi["contact_temperature_c"] is not None
    text = cli(*args[:-1], "--conductance", 800)
    assert text.exit_code == 0 and "model contact (conductance_w_m2k = 800 W m^-2 K^-1)" in text.stdout


def test_simulate_semi_infinite_readings_are_simulate_trials_readings(cli, paper_sensor):
    from designkit import Scene
    from designkit.simulation import simulate_trials

    p = json.loads(cli("simulate", "--e", 3000, "--contact", 1, "--trials", 2, "--seed", 4, "--json").stdout)
    ref = simulate_trials(3000, paper_sensor, Scene(contact_s=1, noise_c=0.05), n_trials=2, seed=4)
    np.testing.assert_array_equal(np.array(p["temperature_c"]), ref.temperature_c)


def test_f1_with_a_slab_model(cli):
    r = cli("f1", "--e1", 600, "--e2", 1400, "--contact", 2, "--trials", 30, "--model", "slab", "--thickness", 0.003,
            "--diffusivity", 1e-7, "--json")
    assert r.exit_code == 0, r.output
    p = json.loads(r.stdout)
    assert p["model"]["name"] == "slab" and p["model"]["thickness_m"] == 0.003 and p["diffusivity_m2_s"] == 1e-7
    assert 0 <= p["svm_f1"] <= 1 and p["ideal_f1"] >= 2 / 3
    text = cli("f1", "--e1", 600, "--e2", 1400, "--trials", 30, "--thickness", 0.003, "--diffusivity", 1e-7)
    assert text.exit_code == 0 and "model slab (3 mm on" in text.stdout


@pytest.mark.parametrize("args,needle", [
    (["f1", "--e1", "600", "--e2", "1400", "--thickness", "0.003"], "diffusivity"),
    (["f1", "--e1", "600", "--e2", "1400", "--diffusivity", "1e-7"], "not the semi-infinite model"),
    (["f1", "--e1", "600", "--e2", "1400", "--model", "contcat"], "unknown forward model"),
    (["f1", "--e1", "600", "--e2", "1400", "--conductance", "-3"], "conductance"),
    (["simulate", "--e", "600", "--model", "slab", "--thickness", "0.003"], "diffusivity"),
    (["simulate", "--e", "600", "--thickness", "0.003", "--conductance", "100"], "different models"),
    (["simulate", "--e", "600", "--diffusivity", "1e-7"], "not the semi-infinite model"),
])
def test_bad_model_options_are_one_line_and_exit_2(cli, args, needle):
    r = cli(*args)
    assert r.exit_code == 2, r.output
    err = r.stderr.strip()
    assert len(err.splitlines()) == 1 and err.startswith("Error:") and needle in err, err


def test_simulate_out_dash_prints_the_csv_and_writes_no_file(cli, tmp_path, monkeypatch):
    """'--out -' wrote a file named '-' and said "wrote -"; the README's vocabulary: '-' is standard output."""
    monkeypatch.chdir(tmp_path)
    r = cli("simulate", "--e", "20000", "--contact", "0.02", "--trials", "2", "--out", "-")
    assert r.exit_code == 0, r.output
    lines = r.stdout.splitlines()
    assert lines[0] == "time_s,temperature_c_1,temperature_c_2" and len(lines) == 1 + 5
    assert not (tmp_path / "-").exists()
    # '-' is standard output for every format: --json there is the JSON (it was refused as two outputs)
    r = cli("simulate", "--e", "20000", "--contact", "0.02", "--out", "-", "--json")
    assert r.exit_code == 0 and json.loads(r.stdout)["time_s"][-1] == 0.02 and not (tmp_path / "-").exists()


def test_calibrate_fit_refuses_out_dash_and_a_missing_folder_before_fitting(cli, tmp_path):
    """'--out -' wrote a file named '-' (and advised '--sensor -'); a missing folder was created from the root."""
    index = tmp_path / "index.csv"
    index.write_text("file,material\n")  # never read: the output is refused first
    r = cli("calibrate", "fit", index, "--out", "-")
    assert r.exit_code == 2 and "give the sensor file a name" in r.stderr and r.stderr.count("\n") == 1
    r = cli("calibrate", "fit", index, "--out", tmp_path / "no" / "such" / "s.yaml")
    assert r.exit_code == 2 and "does not exist (create it first)" in r.stderr
    assert not (tmp_path / "no").exists()
