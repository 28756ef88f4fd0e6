"""A reopened port is a new device until its stream shows otherwise (issue 14, a new user's walkthrough).

Over real pseudo-terminals: the recorder is given a symlink as its port (as udev's
/dev/serial/by-id names are); when the emulated device vanishes, the link is pointed at another
emulator's pty, the way a freed /dev/pts/N is handed to the next program that opens a pty.
"""

from __future__ import annotations

import json
import os
import re
import time
from pathlib import Path

import pytest
import yaml

from designkit import SENSORS
from designkit_lab.emulator import EmulatedMaterial, Emulator, Faults, TouchPlan
from designkit.calibration.profiles import list_profiles, profile_from_dict
from designkit.calibration.recorder import DeviceChanged, SerialRecorder
from designkit.calibration.trials import load_index

PAPER = SENSORS["paper"]
PLAN = TouchPlan(touch_every_s=13.0)   # touches at 2, 15, 28, 41 ... s device time
VANISH_S = 31.0                        # 3 s into the third touch: two trials written before


def _profile():
    data = yaml.safe_load(list_profiles()["designkit"].read_text())
    data["serial"].update(reconnect_s=3.0)
    return profile_from_dict(data, source="profile designkit (test)")


def _emu(prof, *, sensor_c=35.0, ambient_c=25.0, faults=Faults(), seed=0):
    return Emulator(prof, PAPER, [EmulatedMaterial("wood", 400.0)], noise_c=0.05, sensor_temp_c=sensor_c,
                    ambient_c=ambient_c, plan=PLAN, speed=50.0, faults=faults, seed=seed)


def _link(path: Path, target: str) -> None:
    tmp = path.with_name(path.name + ".new")
    os.symlink(target, tmp)
    os.replace(tmp, path)


def _record_across_a_reconnect(tmp_path, second: Emulator, n: int, before_reopen=lambda: None):
    """Record ``n`` touches through a link that moves from a vanishing emulator to ``second``."""
    prof = second.profile
    port = tmp_path / "ttyRIG"
    out = tmp_path / "trials"
    with _emu(prof, faults=Faults(vanish_after_s=VANISH_S)) as first:
        _link(port, first.port)
        events = []

        def on_event(e):
            events.append(e)
            if e.kind == "gap" and "disconnected" in e.message:
                before_reopen()
                _link(port, second.port)     # the path now belongs to someone else's device

        rec = SerialRecorder(str(port), prof, out, on_event=on_event)
        try:
            with rec:
                rec.record("wood", n)
            error = None
        except DeviceChanged as exc:
            error = exc
    return rec, events, error, out


def test_a_port_taken_over_by_another_device_stops_the_recording_and_keeps_the_trials(tmp_path):
    # the user's case: the other program's emulator runs its heater at 29.7 degC in a 22.5 degC room
    prof = _profile()
    with _emu(prof, sensor_c=29.7, ambient_c=22.5, seed=5) as other:
        rec, events, error, out = _record_across_a_reconnect(tmp_path, other, 6)
    assert error is not None, "recorded from another device's stream"
    msg = str(error)
    assert "\n" not in msg and "streams another device than this session's" in msg
    got = re.search(r"sensor ([\d.]+) °C out of contact, the session's ([\d.]+) °C; "
                    r"object ([\d.]+) °C, the session's ([\d.]+) °C", msg)
    assert got, msg
    assert [float(x) for x in got.groups()] == pytest.approx([29.7, 35.0, 22.5, 25.0], abs=0.05)
    assert "2 trial(s) kept" in msg
    trials = load_index(out / "index.csv")
    assert len(trials) == 2 == len(rec.written)          # nothing lost, nothing of the other device
    for tr in trials:
        side = json.loads(Path(tr.source).with_suffix(".json").read_text())
        assert side["sensor_temp_before_c"] == pytest.approx(35.0, abs=0.05)
        assert side["object_temp_before_c"] == pytest.approx(25.0, abs=0.05)
    assert any(e.kind == "reconnect" and "checking" in e.message for e in events)


def test_a_clock_that_goes_back_to_mid_stream_is_another_device(tmp_path):
    # same temperatures, but its clock is mid-stream: another program has been reading it
    import serial

    prof = _profile()
    with _emu(prof, seed=7) as other:
        readers = []

        def another_program_reads_it_first():   # until its clock is past 12 s, short of the session's 31 s
            r = serial.Serial(other.port, timeout=0.01)
            readers.append(r)
            deadline = time.monotonic() + 10
            while other.samples_sent < 12.0 * prof.sample_rate_hz and time.monotonic() < deadline:
                r.read(65536)
        try:
            rec, events, error, out = _record_across_a_reconnect(tmp_path, other, 6, another_program_reads_it_first)
        finally:
            for r in readers:
                r.close()
    assert error is not None
    assert re.search(r"the device clock went back from [23]\d\.\d\d s to 1\d\.\d\d s, where a reset restarts it "
                     r"near 0", str(error)), error
    assert len(load_index(out / "index.csv")) == 2


def test_the_same_device_back_after_a_reset_is_recorded_from(tmp_path):
    # a device like the session's, its clock restarted at 0: the touches go on being recorded
    prof = _profile()
    with _emu(prof, seed=9) as same:
        rec, events, error, out = _record_across_a_reconnect(tmp_path, same, 4)
    assert error is None
    assert any(e.kind == "reconnect" and "streams this session's device again" in e.message
               and "clock restarted" in e.message for e in events)
    trials = load_index(out / "index.csv")
    assert len(trials) == 4
    onsets = [json.loads(Path(tr.source).with_suffix(".json").read_text())["onset_device_time_s"]
              for tr in trials]
    assert onsets[2] < onsets[1]       # the last two came from the restarted clock
    for tr in trials:
        side = json.loads(Path(tr.source).with_suffix(".json").read_text())
        assert side["sensor_temp_before_c"] == pytest.approx(35.0, abs=0.05)
