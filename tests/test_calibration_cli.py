"""The calibrate and emulate commands, through the CLI: in-process (typer's CliRunner) and as
real processes of the designkit console script, over real pseudo-terminals."""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from designkit import SENSORS
from designkit_lab.emulator import EmulatedMaterial, Emulator, Faults, TouchPlan
from designkit.calibration.profiles import load_profile
from designkit.calibration.trials import write_trial
from designkit.sensor import load_sensor

PAPER = SENSORS["paper"]
METAL, WOOD = 17530.0, 400.0
# objects whose effusivity is known to about 5 %, as from an effusivity meter (asymmetric on purpose)
METER_RANGES = [f"metal={METAL * 0.97:.1f}:{METAL * 1.08:.1f}", f"wood={WOOD * 0.93:.1f}:{WOOD * 1.02:.1f}"]


def _exe() -> list[str]:
    exe = Path(sys.executable).with_name("designkit")
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "designkit"]


def _emulator(e: float, label: str, seed: int = 0, speed: float = 100.0) -> Emulator:
    return Emulator(load_profile("designkit"), PAPER, [EmulatedMaterial(label, e)], noise_c=0.05,
                    plan=TouchPlan(touch_every_s=13.0), speed=speed, seed=seed)


def _synthetic_index(folder: Path, n: int = 4, seed: int = 0) -> Path:
    """Trials written as the recorder writes them, from the closed-form model."""
    from scipy.special import erfc

    rng = np.random.default_rng(seed)
    t = np.arange(-200, 1401) / 200.0
    for name, e in (("metal", METAL), ("wood", WOOD)):
        w = e / (PAPER.effusivity + e)
        tt = t + 0.25
        g = np.where(tt > 0, erfc(np.sqrt(PAPER.tau_s / np.where(tt > 0, tt, 1.0))), 0.0)
        for _ in range(n):
            sensor = 35.0 - 10.0 * w * g + 0.05 * rng.standard_normal(t.size)
            obj = 25.0 + 0.05 * rng.standard_normal(t.size)
            write_trial(folder, name, t, sensor, obj, np.full(t.size, 8.0), {"profile": "test"})
    return folder / "index.csv"


# -------------------------------------------------------------------- fit
def test_fit_writes_a_sensor_that_other_commands_accept(cli, tmp_path):
    index = _synthetic_index(tmp_path / "trials")
    out = tmp_path / "my-sensor.yaml"
    r = cli("calibrate", "fit", index, *sum((["--range", x] for x in METER_RANGES), []), "--out", out,
            "--model", "semi-infinite", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    res = d["results"][0]
    assert d["selected"] == "semi-infinite" and res["consistent"]
    assert res["effusivity"]["interval"]["low"] <= res["effusivity"]["value"] <= res["effusivity"]["interval"]["high"]
    assert set(res["ratios"]) == {"metal", "wood"}
    sen = load_sensor(out)
    assert sen.effusivity == pytest.approx(res["effusivity"]["value"])
    assert sen.provenance["selection"]["split"]["by"] == "touch order"
    sim = cli("simulate", "--e", "400", "--sensor", out, "--contact", "1", "--json")
    assert sim.exit_code == 0, sim.output
    assert json.loads(sim.stdout)["sensor"]["effusivity"] == pytest.approx(sen.effusivity)


def test_fit_human_output_and_plot(cli, tmp_path):
    index = _synthetic_index(tmp_path / "trials", n=3)
    plot = tmp_path / "fit.png"
    r = cli("calibrate", "fit", index, *sum((["--range", x] for x in METER_RANGES), []), "--model",
            "semi-infinite", "--plot", plot)
    assert r.exit_code == 0, r.output
    assert "Selected: semi-infinite" in r.stdout and "diffusivity_m2_s" in r.stdout and "alpha_s is identified" \
        in r.stdout
    assert plot.read_bytes()[:4] == b"\x89PNG"


def test_fit_parameters_as_csv_read_by_the_csv_module_and_equal_to_the_json(cli, tmp_path):
    import csv
    import io

    index = _synthetic_index(tmp_path / "trials", n=3)
    args = [index, *sum((["--range", x] for x in METER_RANGES), []), "--model", "semi-infinite"]
    r = cli("calibrate", "fit", *args, "--format", "csv")
    assert r.exit_code == 0, r.output
    rows = list(csv.DictReader(io.StringIO(r.stdout)))
    assert list(rows[0]) == ["parameter", "material", "value", "std_error", "low_95", "high_95", "unit"]
    d = json.loads(cli("calibrate", "fit", *args, "--format", "json").stdout)
    es = next(x for x in rows if x["parameter"] == "e_s")
    assert float(es["value"]) == pytest.approx(d["results"][0]["effusivity"]["value"], rel=1e-12)
    assert {x["parameter"] for x in rows} >= {"e_o[metal]", "e_o[wood]", "time_offset_s", "diffusivity_m2_s"}
    md = cli("calibrate", "fit", *args, "--format", "md")
    assert md.exit_code == 0 and md.stdout.startswith("| parameter | material |")
    bad = cli("calibrate", "fit", *args, "--format", "xml")
    assert bad.exit_code == 2 and "unknown format 'xml'" in bad.output
    assert rows[0]["parameter"] == "e_s" and float(rows[0]["low_95"]) <= float(rows[0]["value"])


@pytest.mark.parametrize("args, message", [
    ([], "no effusivity range for metal"),
    (["--range", "metal=1:2", "--range", "wood=3"], "wood=3"),
    (["--range", "metal"], "--range must look like NAME=MIN:MAX"),
    (["--only", "glass"], "--only names material(s) not in index.csv: glass"),
    (["--range", "metal=1:2", "--range", "wood=331:506", "--object-temp", "wood=tepid"], "--object-temp"),
    (["--range", "metal=1:2", "--range", "wood=331:506", "--offset-range", "x"], "--offset-range"),
    (["--range", "metal=1:2", "--range", "wood=331:506", "--fit-to", "nan"], "--fit-to must be a positive"),
    (["--range", "metal=1:2", "--range", "wood=331:506", "--fit-to", "-1"], "--fit-to must be a positive"),
    (["--range", "metal=1:2", "--range", "wood=331:506", "--fit-to", "0.2"],
     "2 touch(es) end before 0.5 s after the onset (e.g. metal_001.csv, 0.2 s)"),
    (["--range", "metal=1:2", "--range", "wood=331:506", "--fit-sets", "3"],
     "--fit-sets names touch numbers 3 that the recording does not have (it has 1) (no trial sets: touch k of "
     "each material counts as set k)"),
    (["--range", "metal=1:2", "--range", "wood=331:506", "--fit-sets", "1"],
     "fit sets 1 leave no touches to score"),
])
def test_fit_errors_are_one_line(cli, tmp_path, args, message):
    index = _synthetic_index(tmp_path / "trials", n=1)
    r = cli("calibrate", "fit", index, *args)
    assert r.exit_code == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error:") and message in lines[0], r.stderr


def test_record_and_guided_need_their_options(cli, tmp_path):
    r = cli("calibrate", "record", "--port", "/dev/null-x")
    assert r.exit_code == 2 and "give --port, --material and --out" in r.stderr
    r = cli("calibrate", "--port", "/dev/null-x", "--out", tmp_path)
    assert r.exit_code == 2 and "at least one --material" in r.stderr
    r = cli("calibrate", "--port", "x", "record", "--port", "y")
    assert r.exit_code == 2 and "go after 'record'" in r.stderr
    r = cli("calibrate", "record", "--port", "/dev/nonexistent-designkit", "--material", "wood", "--out", tmp_path)
    assert r.exit_code == 2 and "cannot open serial port" in r.stderr


def test_guided_run_records_then_fits(cli, tmp_path):
    out = tmp_path / "run"
    with _emulator(WOOD, "wood", seed=2) as emu:
        r = cli("calibrate", "--port", emu.port, "--profile", "designkit", "--material", "wood", "--trials", "3",
                "--range", f"wood={WOOD * 0.95}:{WOOD * 1.05}", "--out", out, "--model", "semi-infinite", "--yes",
                "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["record"]["n_trials"] == 3 and d["sensor"] == str(out / "sensor.yaml")
    sen = load_sensor(out / "sensor.yaml")
    # one material: e_s is known only to the width of wood's range (and its ratio's interval)
    iv = d["fit"]["results"][0]["effusivity"]["interval"]
    lo, hi = iv["low"], iv["high"]
    assert lo <= PAPER.effusivity <= hi and sen.tau_s == pytest.approx(PAPER.tau_s, rel=0.05)


def test_guided_run_with_a_model_records_it_in_the_sensor_file(cli, tmp_path):
    """calibrate --model NAME: the identified model goes into sensor.yaml, and --sensor answers with it."""
    out = tmp_path / "run"
    with _emulator(WOOD, "wood", seed=3) as emu:
        r = cli("calibrate", "--port", emu.port, "--profile", "designkit", "--material", "wood", "--trials", "3",
                "--range", f"wood={WOOD * 0.95}:{WOOD * 1.05}", "--out", out, "--model", "semi-infinite", "--yes",
                "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)["fit"]
    assert d["selected"] == "semi-infinite" and d["out"] == str(out / "sensor.yaml")
    from designkit.models import load_sensor_model

    sen, fm = load_sensor_model(out / "sensor.yaml")
    assert fm.name == "semi-infinite" and sen.model["candidate"] == "semi-infinite"
    assert sen.tau_s == pytest.approx(PAPER.tau_s, rel=0.05)


def test_guided_run_stops_before_recording_when_a_range_is_missing(cli, tmp_path):
    r = cli("calibrate", "--port", "/dev/whatever", "--material", "unobtainium", "--out", tmp_path, "--yes")
    assert r.exit_code == 2 and "no effusivity range for unobtainium" in r.stderr
    assert not list(tmp_path.iterdir())


# ---------------------------------------------------------------- emulate
def _read_json_object(stream, timeout: float = 30.0) -> dict:
    """Read one (pretty-printed) JSON object from a pipe without waiting for EOF."""
    text, depth, deadline = "", 0, time.monotonic() + timeout
    fd = stream.fileno()
    while time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 0.1)
        if not ready:
            continue
        chunk = os.read(fd, 4096).decode()
        if not chunk:
            break
        text += chunk
        depth = text.count("{") - text.count("}")
        if text.strip() and depth == 0:
            return json.loads(text)
    raise AssertionError(f"no JSON from the emulator: {text!r}")


@pytest.mark.slow
def test_emulate_process_feeds_calibrate_record(cli, tmp_path, ctrl_c_able):
    proc = subprocess.Popen(_exe() + ["emulate", "--profile", "adc12-thermistor", "--material", "wood=400",
                                      "--touch-every", "13", "--speed", "50", "--duration", "60", "--json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, **ctrl_c_able)
    try:
        info = _read_json_object(proc.stdout)
        assert info["profile"] == "adc12-thermistor" and info["port"].startswith("/dev/")
        r = cli("calibrate", "record", "--port", info["port"], "--profile", "adc12-thermistor", "--material",
                "wood", "--trials", "2", "--out", tmp_path, "--json")
        assert r.exit_code == 0, r.output
        assert json.loads(r.stdout)["n_trials"] == 2
    finally:
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=20)
    assert proc.returncode == 0


def test_emulate_rejects_bad_input(cli):
    r = cli("emulate", "--profile", "designkit")
    assert r.exit_code == 2 and "--material" in r.stderr
    r = cli("emulate", "--e", "400", "--touch-every", "3")
    assert r.exit_code == 2 and "too short" in r.stderr
    r = cli("emulate", "--e", "400", "--fault", "sparks=1")
    assert r.exit_code == 2 and "unknown fault 'sparks'" in r.stderr


# ------------------------------------------------ round trip (done-when)
@pytest.mark.slow
def test_round_trip_over_a_pty_recovers_the_sensor(cli, tmp_path):
    """Emulate e_s = 892, alpha_s = 1.19e-9 at sigma 0.05 degC, 10 trials per material, record
    each material over a real pty, fit: recovered within the reported uncertainty and within 5 %."""
    out = tmp_path / "trials"
    for seed, (label, e) in enumerate((("metal", METAL), ("wood", WOOD))):
        with _emulator(e, label, seed=10 + seed) as emu:
            r = cli("calibrate", "record", "--port", emu.port, "--profile", "designkit", "--material", label,
                    "--trials", "10", "--out", out, "--json")
            assert r.exit_code == 0, r.output
            offset = emu.expected_time_offset_s
    r = cli("calibrate", "fit", out / "index.csv", *sum((["--range", x] for x in METER_RANGES), []),
            "--out", tmp_path / "sensor.yaml", "--model", "semi-infinite", "--fit-sets", "all", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["n_fit"] == 20
    res = d["results"][0]
    params = {p["name"]: p for p in res["parameters"]}
    for got, truth in ((res["effusivity"], PAPER.effusivity), (params["diffusivity_m2_s"], PAPER.diffusivity_m2_s),
                       (params["time_offset_s"], offset)):
        lo, hi = got["interval"]["low"], got["interval"]["high"]
        assert lo <= truth <= hi, (got, truth)
    assert res["effusivity"]["value"] == pytest.approx(PAPER.effusivity, rel=0.05)
    assert params["diffusivity_m2_s"]["value"] == pytest.approx(PAPER.diffusivity_m2_s, rel=0.05)
    assert res["noise_c"] == pytest.approx(0.05, rel=0.1)


# --------------------------------------------------------- real recordings
@pytest.mark.slow
def test_default_fit_of_the_shared_robot_recordings_chooses_a_model_that_holds(cli, robot_data_dir, tmp_path):
    """Issue 34's target: default options on metal and wood of sets 1-20 (the paper's model conflicts there):
    exit 0, no conflict, a sensor file, held-out RMS at most 0.05 degC per material, the choice stated."""
    out = tmp_path / "robot.yaml"
    r = cli("calibrate", "fit", robot_data_dir / "index.csv", "--only", "metal", "--only", "wood",
            "--range", "metal=aluminium", "--out", out, "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["split"]["by"] == "trial set" and d["split"]["fit_sets"] == [1, 2, 3, 4]
    assert d["split"]["held_out_sets"] == list(range(5, 21)) and d["n_fit"] + d["n_held_out"] == 120
    best = next(x for x in d["results"] if x["candidate"] == d["selected"])
    assert best["consistent"] and d["selected"] != "semi-infinite"
    assert best["held_out_rms_c"]["metal"] <= 0.05 and best["held_out_rms_c"]["wood"] <= 0.05
    assert d["reason"].startswith(d["selected"]) and "held-out" in d["reason"]
    paper = next(x for x in d["results"] if x["candidate"] == "semi-infinite")
    assert paper["held_out_rms_c"]["metal"] > 2 * best["held_out_rms_c"]["metal"]
    sen = load_sensor(out)
    assert sen.model["candidate"] == d["selected"] and not sen.problems
    assert sen.provenance["selection"]["held_out_rms_c"]["wood"] == pytest.approx(best["held_out_rms_c"]["wood"])


def test_fit_chooses_sets_from_those_present(cli, tmp_path):
    """Recordings numbered otherwise: sets 7, 9, 12 (1-4 hard-coded left 0 touches to fit); the first fitted."""
    folder = tmp_path / "trials"
    index = _synthetic_index(folder, n=3)
    import csv

    rows = list(csv.DictReader(index.open()))
    with index.open("w", newline="") as f:
        w = csv.DictWriter(f, ["file", "material", "trial_index", "trial_set"])
        w.writeheader()
        for row in rows:
            w.writerow({**row, "trial_set": (7, 9, 12)[int(row["trial_index"]) - 1]})
    r = cli("calibrate", "fit", index, *sum((["--range", x] for x in METER_RANGES), []), "--model",
            "semi-infinite", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["split"]["fit_sets"] == [7] and d["split"]["held_out_sets"] == [9, 12] and d["n_held_out"] == 4
    r = cli("calibrate", "fit", index, *sum((["--range", x] for x in METER_RANGES), []), "--model",
            "semi-infinite", "--fit-sets", "1-4")
    assert r.exit_code == 2 and r.stderr.strip().splitlines() == [
        "Error: --fit-sets names trial sets 1-4 that the recording does not have (it has 7, 9, 12)"], r.stderr


def test_fit_names_a_file_that_is_not_utf8(cli, tmp_path):
    index = _synthetic_index(tmp_path / "trials", n=1)
    trial = tmp_path / "trials" / "wood_001.csv"
    trial.write_bytes(trial.read_bytes().replace(b"time_s", b"t\xefme_s"))
    r = cli("calibrate", "fit", index, "--range", "metal=1:2", "--range", "wood=331:506")
    assert r.exit_code == 2
    lines = r.stderr.strip().splitlines()
    assert lines == [f"Error: trial {trial} is not UTF-8 text (byte 0xef on line 1)"], r.stderr


@pytest.mark.parametrize("command, extra", [(["record"], []), ([], ["--range", "wood=331:506", "--yes"])],
                         ids=["record", "guided"])
@pytest.mark.parametrize("value", ["nan", "inf", "-1", "0"])
def test_a_timeout_that_can_never_fire_is_refused(cli, tmp_path, command, extra, value):
    """--timeout nan on a silent device waited forever (NaN compares false)."""
    with Emulator(load_profile("designkit"), PAPER, [EmulatedMaterial("wood", WOOD)],
                  faults=Faults(silent=True)) as emu:
        t0 = time.monotonic()
        r = cli("calibrate", *command, "--port", emu.port, "--material", "wood", "--out", tmp_path / "out",
                *extra, "--timeout", value)
        assert time.monotonic() - t0 < 5
    assert r.exit_code == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "--timeout must be a positive, finite number of seconds" in lines[0], r.stderr
    assert not (tmp_path / "out").exists()


def test_record_gives_up_on_a_mostly_unreadable_stream(cli, tmp_path):
    with Emulator(load_profile("designkit"), PAPER, [EmulatedMaterial("wood", WOOD)], speed=50.0,
                  plan=TouchPlan(touch_every_s=13.0), faults=Faults(garbled=0.4)) as emu:
        r = cli("calibrate", "record", "--port", emu.port, "--material", "wood", "--out", tmp_path, "--trials", "3")
    assert r.exit_code == 2
    errors = [line for line in r.stderr.splitlines() if line.startswith("Error:")]  # after the event lines
    assert len(errors) == 1 and r.stderr.strip().splitlines()[-1] == errors[0], r.stderr
    assert "% of the last 1601 lines" in errors[0] and "0 trial(s) kept" in errors[0]
    assert "Traceback" not in r.stderr


@pytest.mark.parametrize("args, message", [
    (["--trials", "1000000000"], "--trials must be 1 to 1000 touches per material, got 1000000000"),
    (["--trials", "0"], "--trials must be 1 to 1000 touches per material, got 0"),
    # each of these was found only after the whole session had been recorded
    (["--model", "nosuch"], "no sensor model 'nosuch' to identify: give one of semi-infinite, contact"),
    (["--object-temp", "zzz=20"], "--object-temp names 'zzz', not a material of this run (wood)"),
    (["--object-temp", "wood=nan"], "--object-temp wood must be finite, got nan"),
    (["--sensor-out", "/proc/nope.yaml"], "--sensor-out /proc/nope.yaml: cannot write in /proc"),
    (["--sensor-out", "/nonexistent-dk/s.yaml"], "--sensor-out /nonexistent-dk/s.yaml: folder /nonexistent-dk does not exist"),
])
def test_guided_run_bounds_its_counts_before_recording(cli, tmp_path, args, message):
    r = cli("calibrate", "--port", "/dev/whatever", "--material", "wood", "--range", "wood=331:506",
            "--out", tmp_path / "out", "--yes", *args)
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert r.stderr.startswith(f"Error: {message}"), r.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("value", ["1000000000", "1001", "0"])
def test_record_bounds_trials(cli, tmp_path, value):
    r = cli("calibrate", "record", "--port", "/dev/whatever", "--material", "wood", "--out", tmp_path / "out",
            "--trials", value)
    assert r.exit_code == 2
    assert r.stderr.strip().splitlines() == [f"Error: --trials must be 1 to 1000 touches per material, got {value}"]


def test_record_refuses_a_folder_whose_index_it_would_spoil(cli, tmp_path):
    index = tmp_path / "index.csv"
    index.write_text("file,material,trial_set,trial_index\nset01_wood_1.csv,wood,1,1\n")
    (tmp_path / "set01_wood_1.csv").write_text("time_s,active_temp_c\n-1,35\n0,35\n1,34\n")
    with _emulator(WOOD, "wood") as emu:
        r = cli("calibrate", "record", "--port", emu.port, "--material", "wood", "--out", tmp_path, "--trials", "1")
    assert r.exit_code == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "not designkit recordings (e.g. set01_wood_1.csv)" in lines[0], r.stderr
    assert index.read_text() == "file,material,trial_set,trial_index\nset01_wood_1.csv,wood,1,1\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["index.csv", "set01_wood_1.csv"]


@pytest.mark.parametrize("command, extra", [(["record"], []), ([], ["--material", "wood", "--yes"])],
                         ids=["record", "guided"])
def test_record_refuses_an_empty_material(cli, tmp_path, command, extra):
    """An empty label was recorded as 'material_001.csv' into an index that 'calibrate fit' then refused."""
    r = cli("calibrate", *command, "--port", "/dev/whatever", "--material", " ", "--out", tmp_path / "out", *extra)
    assert r.exit_code == 2
    (line,) = r.stderr.strip().splitlines()  # one line, naming the option and what is wrong with it
    assert line.startswith("Error:") and "--material" in line and "empty" in line, line


def test_record_checks_the_out_folder_before_waiting_for_touches(cli, tmp_path):
    not_a_folder = tmp_path / "notes.txt"
    not_a_folder.write_text("hello\n")
    blocked = not_a_folder / "trials"  # its parent is a file: the folder cannot be created
    with _emulator(WOOD, "wood", speed=1.0) as emu:  # real time: the first touch is 10 s away
        t0 = time.monotonic()
        r1 = cli("calibrate", "record", "--port", emu.port, "--material", "wood", "--out", not_a_folder)
        r2 = cli("calibrate", "record", "--port", emu.port, "--material", "wood", "--out", blocked)
        assert time.monotonic() - t0 < 5
    assert r1.exit_code == 2 and r1.stderr.strip().splitlines() == [
        f"Error: {not_a_folder} is not a folder (the trials and their index.csv go in one)"]
    assert r2.exit_code == 2 and r2.stderr.strip().splitlines() == [
        f"Error: cannot create the trial folder {blocked}: Not a directory"]
