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
    rows = list(csv.reader(out.open()))
    assert rows[0] == ["time_s", "trial_1", "trial_2", "trial_3"]
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
