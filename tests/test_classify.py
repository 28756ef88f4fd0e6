"""``designkit classify`` over a real pseudo-terminal: the emulator streams touches of known
materials in the profile's wire format; every touch is decided live, correctly, before the
fixed contact the ideal observer needs. Bad input is one line and exit 2; a hopeless pair exits 3."""

from __future__ import annotations

import json

import pytest

from designkit import SENSORS
from designkit_lab.emulator import EmulatedMaterial, Emulator, TouchPlan
from designkit.calibration.profiles import load_profile

PAPER = SENSORS["paper"]


def _emulator(materials, *, speed=25.0, seed=0, noise=0.05):
    plan = TouchPlan(touch_every_s=10.0, contact_s=4.0, touches_per_material=1)
    return Emulator(load_profile("designkit"), PAPER, materials, noise_c=noise, sensor_temp_c=35.0, ambient_c=25.0,
                    plan=plan, speed=speed, seed=seed)


def test_classify_decides_each_touch_over_a_pty(cli):
    mats = [EmulatedMaterial("metal", 20000.0), EmulatedMaterial("wood", 420.0)]
    with _emulator(mats) as emu:
        r = cli("classify", "--port", emu.port, "--profile", "designkit", "--m", "metal=12767:25972",
                "--m", "wood=331:506.46", "--touches", "4", "--time-offset", str(emu.expected_time_offset_s),
                "--error-rate", "0.001", "--json")
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    got = [(d["state"], d["material"]) for d in out["decisions"]]
    assert got == [("decided", "metal"), ("decided", "wood")] * 2
    fixed = out["plan"]["fixed_contact_s"]
    assert all(d["time_to_decision_s"] <= fixed + 0.2 for d in out["decisions"])  # a touch each: not a mean
    assert all(abs(d["sensor_temp_c"] - 35.0) < 0.05 and abs(d["ambient_temp_c"] - 25.0) < 0.05
               for d in out["decisions"])


def test_classify_text_output_names_decision_and_time(cli):
    with _emulator([EmulatedMaterial("a", 35000.0)], seed=2) as emu:
        r = cli("classify", "--port", emu.port, "--m", "a=35000:35080", "--m", "b=20000:20080",
                "--time-offset", str(emu.expected_time_offset_s), "--error-rate", "0.05")
    assert r.exit_code == 0, r.output
    assert "touch 1: a after" in r.stdout and "s of contact" in r.stdout
    assert "touch 1:" not in r.stderr  # once, outside a terminal too (it was on stdout and stderr)
    # time and samples from the same origin, the detected onset: samples = time x 200 Hz
    import re

    t, n = re.search(r"after ([\d.]+) s of contact, (\d+) samples at 200 Hz \(both from the detected onset",
                     r.stdout).groups()
    assert int(n) == round(float(t) * 200)


def test_classify_uses_the_calibrated_sensors_time_offset(cli, tmp_path):
    """The emulator's onset detection lags the heat flow by 0.25 s (as a rig's force threshold does): with a
    sensor file that recorded that offset, no --time-offset is needed (decided at an offset of 0, wood reads as
    the faster-drawing aluminium)."""
    sensor = tmp_path / "cal.yaml"
    with _emulator([EmulatedMaterial("wood", 420.0)], seed=4) as emu:
        offset = emu.expected_time_offset_s
        PAPER.replace(name="calibrated", model={"name": "semi-infinite", "params": {}, "time_offset_s": offset}).to_yaml(sensor)
        r = cli("classify", "--port", emu.port, "--sensor", str(sensor), "--m", "wood", "--m", "aluminium alloys",
                "--touches", "2", "--json")
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    assert out["time_offset_s"] == pytest.approx(offset) and offset < -0.1
    assert [(d["state"], d["material"]) for d in out["decisions"]] == [("decided", "Wood")] * 2


def test_classify_decides_with_the_measured_noise_when_the_stream_is_noisier(cli):
    """A test told 0.01 °C on a 0.05 °C stream would decide after a few samples and often wrongly; the
    scatter before contact says so, and the touch is decided with it (said in one line per touch)."""
    mats = [EmulatedMaterial("metal", 20000.0), EmulatedMaterial("wood", 420.0)]
    with _emulator(mats, seed=5) as emu:
        r = cli("classify", "--port", emu.port, "--m", "metal=12767:25972", "--m", "wood=331:506.46",
                "--noise", "0.01", "--touches", "4", "--time-offset", str(emu.expected_time_offset_s),
                "--error-rate", "0.001", "--json")
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    assert [(d["state"], d["material"]) for d in out["decisions"]] == [("decided", "metal"), ("decided", "wood")] * 2
    for d in out["decisions"]:
        assert 0.04 < d["pre_contact_noise_c"] < 0.06 and d["noise_c"] == d["pre_contact_noise_c"]
    with _emulator(mats, seed=5, noise=0.01) as emu:  # matched: the test keeps its own noise
        r = cli("classify", "--port", emu.port, "--m", "metal=12767:25972", "--m", "wood=331:506.46",
                "--noise", "0.01", "--time-offset", str(emu.expected_time_offset_s), "--json")
    d = json.loads(r.stdout)["decisions"][0]
    assert d["noise_c"] == 0.01 and d["pre_contact_noise_c"] < 0.015


def test_classify_sample_rate_mismatch_is_one_line_exit_2(cli, tmp_path):
    sensor = tmp_path / "s.yaml"
    PAPER.replace(sample_rate_hz=100.0, name="slow").to_yaml(sensor)
    with _emulator([EmulatedMaterial("a", 35000.0)]) as emu:
        r = cli("classify", "--port", emu.port, "--sensor", str(sensor), "--m", "a=35000", "--m", "b=20000")
    assert r.exit_code == 2
    line = r.output.strip().splitlines()
    assert len(line) == 1 and "sample rate (200 Hz" in line[0] and "100 Hz" in line[0]


def test_classify_hopeless_exits_3_before_touching(cli):
    r = cli("classify", "--port", "/dev/null", "--m", "a=20000:20080", "--m", "b=20100:20180",
            "--max-contact", "2", "--json")
    assert r.exit_code == 3
    assert json.loads(r.stdout)["plan"]["separable"] is False


@pytest.mark.parametrize("args,msg", [
    (["--m", "a=1:2"], "two or more"),
    (["--m", "a=x", "--m", "b=3"], "NAME=MIN:MAX"),
    (["--m", "wood", "--m", "nosuchmaterial"], "nosuchmaterial"),
    (["--m", "a=1", "--m", "b=2", "--error-rate", "0.9"], "--error-rate must be in (0, 0.5), got 0.9"),
    # each was taken, or refused naming another option or a material
    (["--m", "a=1", "--m", "b=2", "--error-rate", "0"], "--error-rate must be in (0, 0.5), got 0"),
    (["--m", "a=1", "--m", "b=2", "--object-temp", "1e9"], "--object-temp must be at most 10000 degC"),
    (["--m", "a=1", "--m", "b=2", "--object-temp", "nan"], "--object-temp must be finite, got nan"),
    # a 411 MB header and 3 GB of memory with --export-c
    (["--m", "a=400", "--m", "b=20000", "--max-contact", "1e5"], "samples per touch; the limit is 1e+06"),
])
def test_classify_bad_input_is_one_line(cli, args, msg):
    r = cli("classify", "--port", "/dev/null", *args)
    assert r.exit_code == 2, r.output
    assert msg in r.output and len(r.output.strip().splitlines()) == 1


def test_classify_export_c_writes_a_header_that_compiles(cli, tmp_path):
    import shutil
    import subprocess

    out = tmp_path / "robot_seq.h"
    r = cli("classify", "--m", "wood", "--m", "metal=12767:25972", "--export-c", str(out), "--prefix", "robot",
            "--json")
    assert r.exit_code == 0, r.output
    text = out.read_text()
    assert json.loads(r.stdout)["bytes"] == len(text.encode()) and "robot_update" in text
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc:
        (tmp_path / "m.c").write_text('#include "robot_seq.h"\nint main(void) { robot_state s; '
                                      'robot_init(&s, 35.0, 25.0); return robot_update(&s, 0.0, 35.0) != -1; }\n')
        subprocess.run([cc, "-std=c99", "-Wall", "-Werror", "-o", str(tmp_path / "m"), str(tmp_path / "m.c"), "-lm"],
                       check=True)
        assert subprocess.run([str(tmp_path / "m")]).returncode == 0
    r = cli("classify", "--m", "a=1", "--m", "b=2", "--export-c", str(out), "--prefix", "9bad")
    assert r.exit_code == 2 and "prefix" in r.output


def test_a_device_that_vanishes_mid_session_keeps_the_decisions_made(cli, tmp_path):
    """The pty closes after two touches: the two decisions are in --json's document beside the error (only the
    error was there, saying "trial(s) kept in None"), exit 2, and the text route prints them before its one
    error line."""
    from designkit_lab.emulator import Faults

    mats = [EmulatedMaterial("metal", 20000.0), EmulatedMaterial("wood", 420.0)]
    for json_ in (True, False):
        plan = TouchPlan(touch_every_s=10.0, contact_s=4.0, touches_per_material=1)
        with Emulator(load_profile("designkit"), PAPER, mats, noise_c=0.05, sensor_temp_c=35.0, ambient_c=25.0,
                      plan=plan, speed=25.0, seed=3, faults=Faults(vanish_after_s=25.0),
                      port_link=tmp_path / f"ttyEMU{int(json_)}") as emu:  # the link vanishes with the device
            r = cli("classify", "--port", emu.port, "--profile", "designkit", "--m", "metal=12767:25972",
                    "--m", "wood=331:506.46", "--touches", "6", "--time-offset", str(emu.expected_time_offset_s),
                    "--error-rate", "0.001", "--timeout", "5", *(["--json"] if json_ else []))
        assert r.exit_code == 2, r.output
        last = r.stderr.splitlines()[-1]  # the text route streams its events on stderr before
        assert last.startswith("Error: the device on") and r.stderr.count("Error:") == 1, r.stderr
        assert not json_ or r.stderr.count("\n") == 1
        import re

        m = re.search(r"; (\d+) touch\(es\) decided$", last)
        assert m and int(m.group(1)) >= 2 and "None" not in r.stderr and "trial" not in r.stderr, r.stderr
        n = int(m.group(1))
        if json_:
            out = json.loads(r.stdout)
            assert [d["material"] for d in out["decisions"]] == ["metal", "wood"] * (n // 2) + ["metal"] * (n % 2)
            assert out["interrupted"] is True and out["error"]["exit_status"] == 2
        else:
            assert "touch 1: metal after" in r.stdout and "touch 2: wood after" in r.stdout
            assert r.stdout.count("\ntouch ") == n
