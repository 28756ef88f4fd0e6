"""Recording over a real pseudo-terminal: the emulator speaks a profile's wire format, the
recorder reads it with pyserial. No mocks of the serial layer. Recorded temperatures are
checked against the physics model evaluated directly (designkit.models.semi_infinite), not against the
emulator's own output."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from designkit import SENSORS
from designkit._validation import InputError
from designkit_lab.emulator import EmulatedMaterial, Emulator, Faults, TouchPlan
from designkit.calibration.profiles import list_profiles, load_profile, profile_from_dict
from designkit.calibration.cutter import TrialCutter
from designkit.calibration.recorder import DeviceGone, NoData, SerialRecorder, TooManyBadLines
from designkit.calibration.trials import load_index, read_trial_csv, recorded_trials, write_trial
from designkit.models.semi_infinite import sensor_temperature

PAPER = SENSORS["paper"]
SENSOR_T, AMBIENT = 35.0, 25.0
PLAN = TouchPlan(touch_every_s=13.0)


def _profile(name: str, **serial) -> "object":
    data = yaml.safe_load(list_profiles()[name].read_text())
    data["serial"].update(serial)
    return profile_from_dict(data, source=f"profile {name} (test)")


def _emulator(profile, e=400.0, *, speed=50.0, faults=Faults(), seed=0, noise=0.05, port_link=None):
    return Emulator(profile, PAPER, [EmulatedMaterial("wood", e)], noise_c=noise, sensor_temp_c=SENSOR_T,
                    ambient_c=AMBIENT, plan=PLAN, speed=speed, faults=faults, seed=seed, port_link=port_link)


def _expected_onsets(emu, n=40):
    return np.array([emu.touch(j).expected_onset_s for j in range(n)])


def _check_trial_against_physics(path: Path, emu, e: float, noise: float, tol_extra: float = 0.0):
    """The trial's samples are the model at their times plus noise: right times, no corrupted sample.

    Heat starts to flow ``-emu.expected_time_offset_s`` before the noise-free detected onset; force
    noise may move the detection by a sample, so the best of -1, 0, +1 samples is checked.
    """
    tr = read_trial_csv(path)
    meta = tr.meta
    dt = 1.0 / emu.profile.sample_rate_hz
    if emu.profile.has_timestamp:  # device time: the onset is one of the emulated touches'
        onsets = _expected_onsets(emu)
        assert np.min(np.abs(onsets - meta["onset_device_time_s"])) <= 1.01 * dt
    best = None
    for shift in (-dt, 0.0, dt):
        t_contact = tr.time_s - emu.expected_time_offset_s + shift
        model = sensor_temperature(np.clip(t_contact, 0, None), e, SENSOR_T, AMBIENT, PAPER.effusivity,
                                   PAPER.tau_s)
        resid = tr.sensor_c - model
        if best is None or np.sum(resid ** 2) < np.sum(best ** 2):
            best = resid
    assert abs(np.mean(best)) < 4 * noise / np.sqrt(best.size) + tol_extra
    assert np.max(np.abs(best)) < 6 * noise + tol_extra
    assert np.std(best) == pytest.approx(noise, rel=0.15, abs=tol_extra)
    return tr


# ------------------------------------------------------------------ happy path
def test_records_trials_with_sidecars_and_index(tmp_path):
    prof = load_profile("designkit")
    with _emulator(prof) as emu, SerialRecorder(emu.port, prof, tmp_path) as rec:
        paths = rec.record("wood", 3)
    assert len(paths) == 3
    idx = (tmp_path / "index.csv").read_text().splitlines()
    assert idx[0] == "file,material,trial_index" and len(idx) == 4
    for p in paths:
        header = p.read_text().splitlines()[0]
        assert header == "time_s,passive_temp_c,active_temp_c,unused_channel,force_n"
        tr = _check_trial_against_physics(p, emu, 400.0, 0.05)
        assert tr.time_s[0] == pytest.approx(-1.0) and tr.time_s[-1] == pytest.approx(7.0)
        assert np.allclose(np.diff(tr.time_s), 0.005, atol=2e-4)
        side = json.loads(p.with_suffix(".json").read_text())
        for key in ("profile", "material", "recorded_at", "sensor_temp_before_c", "object_temp_before_c",
                    "pre_s", "post_s", "sample_rate_hz"):
            assert key in side
        assert side["sensor_temp_before_c"] == pytest.approx(SENSOR_T, abs=0.02)
        assert side["object_temp_before_c"] == pytest.approx(AMBIENT, abs=0.02)
    assert len(load_index(tmp_path / "index.csv")) == 3


def test_line_faults_are_reported_skipped_and_do_not_shift_counted_time(tmp_path):
    # The ADC profile has no timestamp: time is the line count, so a skipped line must still count.
    prof = load_profile("adc12-thermistor")
    faults = Faults(garbled=0.01, partial=0.01, non_numeric=0.01, field_count=0.01, out_of_range=0.01)
    with _emulator(prof, faults=faults, seed=3) as emu, SerialRecorder(emu.port, prof, tmp_path) as rec:
        paths = rec.record("wood", 3)
    kinds = rec.status.bad_by_kind
    assert set(kinds) == {"garbled", "field_count", "non_numeric", "out_of_range"}  # partial -> field count
    messages = [e.message for e in rec.events if e.kind == "bad_line"]
    assert any("wrong number of fields" in m for m in messages)
    assert any("out of range" in m for m in messages)
    assert any("garbled" in m for m in messages)
    # a 12-bit count is ~0.015 degC here: allow for quantization on top of the noise
    for p in paths:
        _check_trial_against_physics(p, emu, 400.0, 0.05, tol_extra=0.01)
        assert json.loads(p.with_suffix(".json").read_text())["n_missing"] > 0


def test_bursts_lose_no_samples(tmp_path):
    prof = load_profile("designkit")
    with _emulator(prof, faults=Faults(burst_every_s=1.0, burst_hold_s=0.1)) as emu, \
            SerialRecorder(emu.port, prof, tmp_path) as rec:
        paths = rec.record("wood", 2)
    for p in paths:
        assert json.loads(p.with_suffix(".json").read_text())["n_missing"] == 0
        _check_trial_against_physics(p, emu, 400.0, 0.05)


def test_gap_in_a_stream_without_timestamps_discards_that_trial_only(tmp_path):
    prof = load_profile("adc12-thermistor")
    # silent 0.3 s (real; 6 s of device time at speed 20) from device time 32 s: inside the trial
    # of the touch at 28 s; touches at 2, 15 and 41 s are whole
    with _emulator(prof, speed=20.0, faults=Faults(gap_every_s=32.0, gap_s=0.3)) as emu, \
            SerialRecorder(emu.port, prof, tmp_path) as rec:
        paths = rec.record("wood", 3)
    gaps = [e.message for e in rec.events if e.kind == "gap"]
    assert any("stalled" in m for m in gaps)
    assert any("discarded" in e.message for e in rec.events if e.kind == "skipped")
    for p in paths:  # the trials kept have the right times: the clock restarted cleanly
        _check_trial_against_physics(p, emu, 400.0, 0.05, tol_extra=0.01)


def test_gap_in_device_time_is_found_from_timestamps(tmp_path):
    prof = load_profile("designkit")
    with _emulator(prof, speed=20.0, faults=Faults(gap_every_s=32.0, gap_s=0.3)) as emu, \
            SerialRecorder(emu.port, prof, tmp_path) as rec:
        paths = rec.record("wood", 3)
    assert any("missing at device time 32" in e.message for e in rec.events if e.kind == "gap")
    assert any("discarded" in e.message for e in rec.events if e.kind == "skipped")
    for p in paths:
        _check_trial_against_physics(p, emu, 400.0, 0.05)


# ------------------------------------------------------------------ failures
def test_device_vanishing_mid_trial_keeps_what_was_written(tmp_path):
    prof = _profile("designkit", reconnect_s=0.3)
    # touches start at 2, 15, 28 s: vanish 3 s into the third touch. The port is a link that vanishes with
    # the device: by the bare /dev/pts/N the reconnect could open the pty another test's emulator was given.
    with _emulator(prof, faults=Faults(vanish_after_s=31.0), port_link=tmp_path / "ttyEMU") as emu, \
            SerialRecorder(emu.port, prof, tmp_path) as rec:
        with pytest.raises(DeviceGone) as exc:
            rec.record("wood", 5)
    msg = str(exc.value)
    assert not (tmp_path / "ttyEMU").is_symlink()  # gone with the device, before its pty number was freed
    assert "disappeared" in msg and "trial in progress was discarded" in msg and "\n" not in msg
    written = rec.written
    assert 1 <= len(written) <= 2 and f"{len(written)} trial(s) kept" in msg
    kept = load_index(tmp_path / "index.csv")
    assert [Path(t.source).name for t in kept] == [p.name for p in written]
    for p in written:
        _check_trial_against_physics(p, emu, 400.0, 0.05)
    assert not list(tmp_path.glob(".*.tmp"))  # no half-written file left behind


def test_silent_device_times_out_with_a_clear_message(tmp_path):
    prof = load_profile("designkit")
    with _emulator(prof, faults=Faults(silent=True)) as emu:
        rec = SerialRecorder(emu.port, prof, tmp_path, no_data_timeout_s=0.4)
        t0 = time.monotonic()
        with pytest.raises(NoData, match="never sent anything for .* baud rate 115200"):
            with rec:
                rec.record("wood", 1)
        assert time.monotonic() - t0 < 5


def test_wrong_profile_is_named_as_the_likely_cause(tmp_path):
    with _emulator(load_profile("adc12-thermistor")) as emu:
        with pytest.raises(NoData, match="matches profile 'designkit'.*wrong profile or baud rate"):
            with SerialRecorder(emu.port, load_profile("designkit"), tmp_path) as rec:
                rec.record("wood", 1)


def test_missing_port_is_a_one_line_error(tmp_path):
    with pytest.raises(InputError, match="cannot open serial port /dev/nonexistent-designkit"):
        SerialRecorder("/dev/nonexistent-designkit", load_profile("designkit"), tmp_path).open()


# ------------------------------------------------------- cutter without serial
def _slope_profile():
    data = yaml.safe_load(list_profiles()["designkit"].read_text())
    data["contact"] = {"rule": "temperature_slope", "slope_c_per_s": 0.3, "slope_window_s": 0.5}
    data["channels"].pop("force")
    data["line"]["fields"] = ["time_s", "sensor_c", "object_c", "_"]
    return profile_from_dict(data, source="slope profile")


def test_temperature_slope_rule_finds_contact_after_it_starts(tmp_path):
    prof = _slope_profile()
    emu = _emulator(load_profile("designkit"), e=17000.0)  # values only, no pty
    v = emu.values(0, int(45 * 200))
    cutter = TrialCutter(prof, tmp_path, "metal")
    vals = np.column_stack([v["sensor"], v["object"], np.full(v["sensor"].size, np.nan)])
    for k in range(0, v["timestamp"].size, 500):  # fed in chunks, as from a port
        cutter.feed(v["timestamp"][k:k + 500], vals[k:k + 500])
    onsets = [json.loads(p.with_suffix(".json").read_text())["onset_device_time_s"] for p in cutter.written]
    starts = [emu.touch(j).start_s for j in range(3)]
    assert len(onsets) == 3
    for onset, start in zip(onsets, starts):
        assert 0.0 < onset - start < 1.0  # after heat starts to flow, within the slope window's reach


def test_discontinuity_discards_the_trial_in_progress(tmp_path):
    prof = load_profile("designkit")
    emu = _emulator(prof)
    v = emu.values(0, int(14 * 200))
    vals = np.column_stack([v["sensor"], v["object"], v["force"]])
    cutter = TrialCutter(prof, tmp_path, "wood")
    cutter.feed(v["timestamp"][:1000], vals[:1000])  # up to 5 s: in the first trial
    assert cutter.in_trial
    events = cutter.discontinuity("test")
    assert [e.kind for e in events] == ["skipped"]
    cutter.feed(v["timestamp"][1000:], vals[1000:])
    assert cutter.written == []


def test_touch_without_enough_quiet_data_before_it_is_skipped(tmp_path):
    prof = load_profile("designkit")
    emu = _emulator(prof)
    v = emu.values(int(1.8 * 200), int(12 * 200))  # starts 0.2 s before the first touch
    cutter = TrialCutter(prof, tmp_path, "wood")
    events = cutter.feed(v["timestamp"], np.column_stack([v["sensor"], v["object"], v["force"]]))
    assert any(e.kind == "skipped" and "clean data before contact" in e.message for e in events)
    assert cutter.written == []


# ------------------------------------------------------------ Ctrl-C (process)
def _designkit_exe() -> list[str]:
    exe = Path(sys.executable).with_name("designkit")
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "designkit"]


def _record_until_trials_then_ctrl_c(emu, out: Path, n_trials: int, ctrl_c_able, *extra: str):
    """Run 'designkit calibrate record' as a process; Ctrl-C once ``n_trials`` sidecars are on disk."""
    proc = subprocess.Popen(_designkit_exe() + ["calibrate", "record", "--port", emu.port, "--profile",
                                                "designkit", "--material", "wood", "--trials", "50",
                                                "--out", str(out), *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **ctrl_c_able)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and len(list(out.glob("wood_*.json"))) < n_trials:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=30)
    return proc.returncode, stdout, stderr


def _check_recorded_folder(out: Path, emu) -> list[str]:
    """Every trial on disk is intact and listed by the index, and nothing else is there."""
    kept = load_index(out / "index.csv")
    names = sorted(Path(tr.source).name for tr in kept)
    assert names == sorted(p.name for p in out.glob("*.csv") if p.name != "index.csv")
    assert names == sorted(p.with_suffix(".csv").name for p in out.glob("*.json"))
    for tr in kept:
        assert tr.n_samples == 1601
        _check_trial_against_physics(Path(tr.source), emu, 400.0, 0.05)
    assert not [p for p in out.iterdir() if p.name.startswith(".")]
    return names


@pytest.mark.slow
def test_ctrl_c_keeps_every_trial_recorded(tmp_path, ctrl_c_able):
    """Ctrl-C right after a trial's sidecar appears: that trial is in the index too (the race of issue 15)."""
    prof = load_profile("designkit")
    out = tmp_path / "trials"
    with _emulator(prof, speed=20.0) as emu:
        code, stdout, stderr = _record_until_trials_then_ctrl_c(emu, out, 1, ctrl_c_able)
    assert code == 130, stderr
    names = _check_recorded_folder(out, emu)
    assert len(names) >= 1
    said = f"Interrupted: {len(names)} trial(s) of wood written to {out}"
    assert "".join(said.split()) in "".join(stderr.split())  # rich may wrap the line anywhere


@pytest.mark.slow
def test_ctrl_c_reports_the_trials_on_disk(tmp_path, ctrl_c_able):
    """After Ctrl-C, --json said n_trials 0 (and the text '0 trial(s) written') with three trials on disk."""
    prof = load_profile("designkit")
    out = tmp_path / "trials"
    with _emulator(prof, speed=20.0) as emu:
        code, stdout, stderr = _record_until_trials_then_ctrl_c(emu, out, 3, ctrl_c_able, "--json")
    assert code == 130, stderr
    names = _check_recorded_folder(out, emu)
    report = json.loads(stdout)
    assert len(names) >= 3 and report["interrupted"] is True
    assert report["n_trials"] == len(names) and sorted(Path(p).name for p in report["trials"]) == names
    assert report["index"] == str(out / "index.csv")


def test_index_and_trial_files_are_checked(tmp_path):
    (tmp_path / "index.csv").write_text("file,material\na.csv,wood\n,wood\n")
    (tmp_path / "a.csv").write_text("time_s,active_temp_c\n-1,35\n0,35\n1,34\n")
    with pytest.raises(InputError, match="line 3: empty file or material"):
        load_index(tmp_path / "index.csv")
    (tmp_path / "index.csv").write_text("file,material\na.csv,wood\nmissing.csv,wood\n")
    with pytest.raises(InputError, match="cannot read trial .*missing.csv"):
        load_index(tmp_path / "index.csv")
    (tmp_path / "b.csv").write_text("time_s,active_temp_c\n0,35\n-1,35\n1,34\n")
    with pytest.raises(InputError, match="time_s must increase"):
        read_trial_csv(tmp_path / "b.csv")
    (tmp_path / "c.csv").write_text("t,temp\n0,35\n")
    with pytest.raises(InputError, match="lacks column"):
        read_trial_csv(tmp_path / "c.csv")
    tr = read_trial_csv(tmp_path / "a.csv", "wood")  # passive and force channels are optional
    assert not tr.has_object and np.isnan(tr.force_n).all()


# ------------------------------------------------------ recorded <=> indexed
@pytest.fixture
def python_sigint():
    """SIGINT raises KeyboardInterrupt here, as in an interactive run (the suite may inherit it ignored)."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def _write_one(folder: Path, material: str = "wood") -> Path:
    t = np.arange(-200, 1401) / 200.0
    return write_trial(folder, material, t, np.full(t.size, 35.0), np.full(t.size, 25.0), np.full(t.size, 8.0),
                       {"profile": "test"})


def test_ctrl_c_between_sidecar_and_index_still_records_the_trial(tmp_path, monkeypatch, python_sigint):
    """The CI race, made certain: a real SIGINT arrives right after the sidecar is written, before
    the index. Ctrl-C is held until the index lists the trial, then raised."""
    from designkit.calibration import trials as trials_module

    real_write = trials_module.atomic_write_text

    def write_then_ctrl_c(path, text):
        done = real_write(path, text)
        if Path(path).suffix == ".json":
            os.kill(os.getpid(), signal.SIGINT)
        return done

    _write_one(tmp_path)
    monkeypatch.setattr(trials_module, "atomic_write_text", write_then_ctrl_c)
    with pytest.raises(KeyboardInterrupt):
        _write_one(tmp_path)
    monkeypatch.undo()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # handler given back
    on_disk = sorted(p.name for p in tmp_path.glob("wood_*.csv"))
    assert on_disk == ["wood_001.csv", "wood_002.csv"]
    assert sorted(Path(t.source).name for t in load_index(tmp_path / "index.csv")) == on_disk


def test_a_failed_trial_write_leaves_nothing_behind(tmp_path, monkeypatch):
    """The disk fills up at the commit (injected: a full disk cannot be had portably in a test)."""
    import errno

    from designkit.calibration import trials as trials_module

    real_write = trials_module.atomic_write_text

    def full_at_index(path, text):
        if Path(path).name == "index.csv":
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return real_write(path, text)

    _write_one(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    monkeypatch.setattr(trials_module, "atomic_write_text", full_at_index)
    with pytest.raises(OSError, match="No space left"):
        _write_one(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == before


@pytest.mark.parametrize("which", ["index", "trial", "sidecar"])
def test_a_file_that_is_not_utf8_is_named(tmp_path, which):
    path = _write_one(tmp_path)
    target = {"index": tmp_path / "index.csv", "trial": path, "sidecar": path.with_suffix(".json")}[which]
    data = target.read_bytes()
    target.write_bytes(data.replace(b"\n", b"\n\xff\xfe", 1))  # Latin-1/UTF-16 bytes on line 2
    with pytest.raises(InputError) as exc:
        load_index(tmp_path / "index.csv")
    message = str(exc.value)
    assert str(target) in message and "not UTF-8" in message and "line 2" in message and "\n" not in message


def test_a_byte_order_mark_is_read(tmp_path):
    """Spreadsheets save UTF-8 with a byte-order mark: the header is still found."""
    path = _write_one(tmp_path)
    for target in (tmp_path / "index.csv", path):
        target.write_bytes(b"\xef\xbb\xbf" + target.read_bytes())
    assert load_index(tmp_path / "index.csv")[0].n_samples == 1601


# ------------------------------------------------------------- bad input
@pytest.mark.parametrize("profile_name", ["designkit", "adc12-thermistor"])
def test_forty_percent_unreadable_lines_give_up_with_the_fraction_and_an_example(tmp_path, profile_name):
    """The reported case: 40 % bad lines skipped every touch (a trial needs 80 % of its samples) forever."""
    prof = load_profile(profile_name)
    with _emulator(prof, faults=Faults(garbled=0.4), seed=1) as emu, SerialRecorder(emu.port, prof, tmp_path) as rec:
        t0 = time.monotonic()
        with pytest.raises(TooManyBadLines) as exc:
            rec.record("wood", 3)
        assert time.monotonic() - t0 < 10
    msg = str(exc.value)
    m = re.fullmatch(r"(\d+\.\d) % of the last 1601 lines from (\S+) were unreadable \(e\.g\. '(.+)'\): a trial "
                     r"needs 80 % of its samples readable, so none can be kept; check the cable, the baud rate "
                     r"\d+ and the profile '[\w-]+'; 0 trial\(s\) kept.*", msg)
    assert m, msg
    assert 30.0 < float(m.group(1)) < 50.0 and m.group(2) == emu.port  # 40 % drawn, over one 1,601-line window
    assert rec.written == [] and not list(tmp_path.glob("wood_*"))


def test_a_stream_going_bad_gives_up_and_keeps_the_trials_recorded(tmp_path):
    prof = load_profile("designkit")
    # touches at 2 and 15 s are cut by 23 s; from 25 s on about 36 % of the lines are unreadable
    faults = Faults(garbled=0.2, non_numeric=0.2, line_faults_after_s=25.0)
    with _emulator(prof, faults=faults) as emu, SerialRecorder(emu.port, prof, tmp_path) as rec:
        with pytest.raises(TooManyBadLines) as exc:
            rec.record("wood", 10)
    msg = str(exc.value)
    assert "\n" not in msg and f"2 trial(s) kept in {tmp_path}" in msg
    assert [Path(t.source).name for t in load_index(tmp_path / "index.csv")] == ["wood_001.csv", "wood_002.csv"]
    for p in rec.written:
        _check_trial_against_physics(p, emu, 400.0, 0.05)


def test_line_faults_can_start_later():
    assert Faults.parse(["garbled=0.2", "line-faults-after=25"]) == Faults(garbled=0.2, line_faults_after_s=25.0)
    prof = load_profile("designkit")
    emu = _emulator(prof, faults=Faults(garbled=1.0, line_faults_after_s=1.0))
    lines = emu.lines(150, 250).split(b"\n")[:-1]  # device time 0.75 to 1.245 s
    clean = [b"".join(line.split()).isascii() for line in lines]
    assert clean == [True] * 50 + [False] * 50


def test_a_few_unreadable_lines_do_not_stop_the_recorder(tmp_path):
    prof = load_profile("designkit")
    with _emulator(prof, faults=Faults(garbled=0.1), seed=2) as emu, SerialRecorder(emu.port, prof, tmp_path) as rec:
        assert len(rec.record("wood", 2)) == 2


@pytest.mark.parametrize("timeout_s", [float("nan"), float("inf"), -1.0, 0.0])
def test_timeout_must_be_positive_and_finite(tmp_path, timeout_s):
    with pytest.raises(InputError, match=r"no_data_timeout_s \[s\] must be positive and finite"):
        SerialRecorder("/dev/whatever", load_profile("designkit"), tmp_path, no_data_timeout_s=timeout_s)


@pytest.mark.parametrize("kind", ["regular file", "folder", "/dev/null"])
def test_a_path_that_is_not_a_serial_device_is_named(tmp_path, kind):
    if kind == "regular file":
        port, what = tmp_path / "notes.txt", "a regular file"
        port.write_text("hello\n")
    elif kind == "folder":
        port, what = tmp_path, "a folder"
    else:
        port, what = Path("/dev/null"), "not a terminal"
    rec = SerialRecorder(str(port), load_profile("designkit"), tmp_path / "out")
    with pytest.raises(InputError) as exc:
        rec.open()
    assert str(exc.value) == f"{port} is not a serial device ({what})"


def test_recorded_trials_are_what_the_index_lists(tmp_path):
    assert recorded_trials(tmp_path) == []
    (tmp_path / "index.csv").write_text("file,material,trial_index\n")  # an index with no trials yet
    assert recorded_trials(tmp_path) == [] and load_index(tmp_path / "index.csv") == []
    first, second = _write_one(tmp_path), _write_one(tmp_path)
    assert recorded_trials(tmp_path) == [first, second]


def test_recording_into_a_folder_with_someone_elses_index_is_refused(tmp_path):
    """The index is rebuilt from the sidecars: it would have dropped every row of the shared recordings'."""
    index = tmp_path / "index.csv"
    index.write_text("file,material,trial_set,trial_index\nset01_wood_1.csv,wood,1,1\n")
    (tmp_path / "set01_wood_1.csv").write_text("time_s,active_temp_c\n-1,35\n0,35\n1,34\n")
    before = index.read_bytes()
    with pytest.raises(InputError) as exc:
        SerialRecorder("/dev/whatever", load_profile("designkit"), tmp_path)
    assert str(exc.value) == (f"index {index} lists 1 file(s) that are not designkit recordings (e.g. "
                              f"set01_wood_1.csv); recording into {tmp_path} would drop them from it: use "
                              "another folder")
    with pytest.raises(InputError, match="not designkit recordings"):
        _write_one(tmp_path)
    assert index.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == [
        "index.csv", "set01_wood_1.csv"]
    index.write_text("no,index,here\n")
    with pytest.raises(InputError, match=f"needs columns file and material; recording into {tmp_path} would "
                                         "replace it"):
        _write_one(tmp_path)


def test_an_index_of_designkit_trials_is_added_to(tmp_path):
    first = _write_one(tmp_path)
    (tmp_path / "notes.txt").write_text("not listed, not touched\n")
    second = _write_one(tmp_path, "metal")
    assert recorded_trials(tmp_path) == [second, first]  # index order: by material
    assert (tmp_path / "notes.txt").exists()


def test_record_refuses_an_empty_material_label(tmp_path):
    prof = load_profile("designkit")
    with _emulator(prof) as emu, SerialRecorder(emu.port, prof, tmp_path) as rec:
        with pytest.raises(InputError, match="material label must not be empty"):
            rec.record("  ", 1)
