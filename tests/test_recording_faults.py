"""Issue 36, recording and serial classes: nothing recorded is lost, nothing wrong is recorded.

Over real pseudo-terminals with the real emulator (and the CLI as a process where the audit ran it
so): two recorders on one folder, labels that cannot name a file, streams with lines sent twice,
out of order or with a digit changed on the wire, and streams so damaged that no touch can be kept.
Recorded samples are checked against the emulator's own clean values (its noise is seeded per
sample block, so ``Emulator.values`` replays exactly what a clean wire carried).
"""

from __future__ import annotations

import errno
import json
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from designkit import SENSORS
from designkit._validation import InputError
from designkit_lab.emulator import EmulatedMaterial, Emulator, Faults, TouchPlan
from designkit.calibration.profiles import list_profiles, load_profile, profile_from_dict
from designkit.calibration.cutter import TrialCutter, TrialNotWritten
from designkit.calibration.recorder import SPIKE_SIGMAS, NoProgress, SerialRecorder
from designkit.calibration.trials import (MAX_STEM_CHARS, FolderBusy, FolderLock, check_material_label,
                                          load_index, recorded_trials, trial_stem, write_trial)

PAPER = SENSORS["paper"]
PLAN = TouchPlan(touch_every_s=13.0)   # touches at 2, 15, 28 ... s of device time


def _exe() -> list[str]:
    exe = Path(sys.executable).with_name("designkit")
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "designkit"]


def _profile(checksum: str = "none", **serial):
    data = yaml.safe_load(list_profiles()["designkit"].read_text())
    data["line"]["checksum"] = checksum
    data["serial"].update(serial)
    return profile_from_dict(data, source=f"profile designkit+{checksum} (test)")


def _emulator(prof, *, faults=Faults(), seed=0, speed=50.0, plan=PLAN, materials=None):
    return Emulator(prof, PAPER, materials or [EmulatedMaterial("wood", 400.0)], noise_c=0.05, sensor_temp_c=35.0,
                    ambient_c=25.0, plan=plan, speed=speed, faults=faults, seed=seed)


def _wrong_samples(path: Path, emu) -> np.ndarray:
    """How far each recorded sample is from what a clean wire carried at its device time [degC]."""
    meta = json.loads(path.with_suffix(".json").read_text())
    d = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    fs = emu.profile.sample_rate_hz
    k = np.rint((d[:, 0] + meta["onset_device_time_s"]) * fs).astype(int)
    clean = emu.values(int(k.min()), int(k.max()) + 1)
    i = k - k.min()
    dec = emu.profile.channels["sensor"].conversion.decimals
    return np.maximum(np.abs(d[:, 2] - np.round(clean["sensor"][i], dec)),
                      np.abs(d[:, 1] - np.round(clean["object"][i], dec)))


# ------------------------------------------------------------- class 2: one recorder per folder
@pytest.mark.slow
def test_a_second_recorder_on_the_same_folder_is_refused_before_recording(tmp_path, ctrl_c_able):
    """The audit: two 'calibrate record --out SAME --trials 4' both said 4 written; the index listed 4."""
    prof = load_profile("designkit")
    out = tmp_path / "trials"
    with _emulator(prof, speed=20.0) as first, _emulator(prof, seed=1) as second:
        a = subprocess.Popen(_exe() + ["calibrate", "record", "--port", first.port, "--material", "wood",
                                       "--trials", "50", "--out", str(out), "--json"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **ctrl_c_able)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not list(out.glob("wood_*.json")):
            time.sleep(0.02)
        b = subprocess.run(_exe() + ["calibrate", "record", "--port", second.port, "--material", "wood",
                                     "--trials", "3", "--out", str(out)],
                           capture_output=True, text=True, timeout=60)
        assert second.samples_sent == 0   # refused before its port was opened
        a.send_signal(signal.SIGINT)
        a_out, a_err = a.communicate(timeout=60)
    assert b.returncode == 2
    assert b.stderr.strip().splitlines() == [
        f"Error: another recorder is writing trials into {out} (a second 'calibrate record' or 'calibrate' with "
        "the same --out?): two at once would number their trials alike and overwrite each other's; let it "
        "finish, or record into another folder"]
    assert a.returncode == 130, a_err
    report = json.loads(a_out)
    listed = sorted(Path(t.source).name for t in load_index(out / "index.csv"))
    n = report["n_trials"]
    assert n >= 1 and listed == [f"wood_{k:03d}.csv" for k in range(1, n + 1)]
    assert sorted(Path(p).name for p in report["trials"]) == listed
    assert sorted(p.name for p in out.glob("*.json")) == [f"wood_{k:03d}.json" for k in range(1, n + 1)]


def test_recorders_one_after_the_other_append_to_the_folder(tmp_path):
    prof = load_profile("designkit")
    with _emulator(prof) as emu, SerialRecorder(emu.port, prof, tmp_path) as rec:
        rec.record("wood", 1)
        with pytest.raises(FolderBusy):
            FolderLock(tmp_path).acquire()   # held for the whole session, not only while writing
        other = SerialRecorder("/dev/whatever", prof, tmp_path)
        with pytest.raises(FolderBusy, match="another recorder is writing trials into"):
            other.open()
    with _emulator(prof, seed=1) as emu, SerialRecorder(emu.port, prof, tmp_path) as rec2:
        rec2.record("wood", 1)
    assert [p.name for p in recorded_trials(tmp_path)] == ["wood_001.csv", "wood_002.csv"]
    assert rec.session != rec2.session
    sessions = [json.loads(p.with_suffix(".json").read_text())["session"] for p in recorded_trials(tmp_path)]
    assert sessions == [rec.session, rec2.session]


def test_a_run_reports_its_own_trials_not_others_the_rebuilt_index_lists(tmp_path):
    """A trial left unlisted by a killed run is listed again when the index is rebuilt: it is not this run's."""
    out = tmp_path / "trials"
    t = np.arange(-200, 1401) / 200.0
    orphan = write_trial(out, "wood", t, np.full(t.size, 35.0), np.full(t.size, 25.0), np.full(t.size, 8.0),
                         {"profile": "test"})
    (out / "index.csv").write_text("file,material,trial_index\n")   # killed between sidecar and index
    prof = load_profile("designkit")
    with _emulator(prof) as emu:
        r = subprocess.run(_exe() + ["calibrate", "record", "--port", emu.port, "--material", "wood", "--trials",
                                     "1", "--out", str(out), "--json"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert report["n_trials"] == 1 and [Path(p).name for p in report["trials"]] == ["wood_002.csv"]
    assert recorded_trials(out) == [orphan, out / "wood_002.csv"]   # the orphan is listed again, not lost


# ------------------------------------------------------------------- class 4: labels
@pytest.mark.parametrize("label, why", [
    ("w" * 300, "is 300 characters long; at most 100"),
    ("wood\nmetal", "contains '\\n'"),
    ("wood\tblock", "contains '\\t'"),
    ("=400", "starts with '='"),
    ("@SUM(A1)", "starts with '@'"),
    (" wood", "spaces at its start or end"),
])
def test_a_label_that_cannot_name_trials_is_refused_before_recording(cli, tmp_path, label, why):
    """The audit: a 300-character label recorded 8 s, then 'File name too long', exit 2, nothing kept."""
    prof = load_profile("designkit")
    out = tmp_path / "trials"
    with _emulator(prof) as emu:
        r = cli("calibrate", "record", "--port", emu.port, "--material", label, "--trials", "1", "--out", out)
        assert emu.samples_sent == 0   # the port was never opened: nothing recorded, nothing lost
        with pytest.raises(InputError, match="material label"):
            SerialRecorder(emu.port, prof, out).record(label, 1)
    assert r.exit_code == 2
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: --material") and why in lines[0], r.output
    assert not out.exists()


@pytest.mark.parametrize("spec", ["=400", "wood\n=400", "wo\nod=400", "=wood=400"])
def test_emulate_refuses_a_label_that_cannot_name_trials(cli, spec):
    r = cli("emulate", "--material", spec, "--duration", "0.1")
    assert r.exit_code == 2 and "label" in r.output and len(r.output.strip().splitlines()) == 1, r.output


def test_the_longest_label_records_under_a_bounded_file_name(tmp_path):
    t = np.arange(-200, 1401) / 200.0
    cols = (np.full(t.size, 35.0), np.full(t.size, 25.0), np.full(t.size, 8.0))
    a = write_trial(tmp_path, "a" * 100, t, *cols, {})
    b = write_trial(tmp_path, "a" * 99 + "b", t, *cols, {})
    assert a.stem != b.stem and all(len(p.stem) <= MAX_STEM_CHARS + 4 for p in (a, b))
    assert sorted(tr.material for tr in load_index(tmp_path / "index.csv")) == ["a" * 100, "a" * 99 + "b"]
    assert check_material_label("Aluminium alloys") == "Aluminium alloys"


def _cut_one_touch(folder: Path, material: str = "wood") -> TrialCutter:
    prof = load_profile("designkit")
    v = _emulator(prof).values(0, int(12 * 200))   # the first touch, values only
    cutter = TrialCutter(prof, folder, material)
    cutter.feed(v["timestamp"], np.column_stack([v["sensor"], v["object"], v["force"]]))
    return cutter


def test_a_name_the_file_system_refuses_is_replaced_by_a_plain_one(tmp_path, monkeypatch):
    """Whatever fails at write time must not lose the touch (the refusal is injected: file systems differ)."""
    from designkit.calibration import trials as trials_module

    real = trials_module.atomic_write_text

    def refuse_label_names(path, text):
        if Path(path).name.startswith("wood"):
            raise OSError(errno.ENAMETOOLONG, "File name too long", str(path))
        return real(path, text)

    monkeypatch.setattr(trials_module, "atomic_write_text", refuse_label_names)
    cutter = _cut_one_touch(tmp_path)
    assert [p.name for p in cutter.written] == ["trial_001.csv"]
    assert any("written as trial_001.csv instead" in e.message for e in cutter.events)
    assert [tr.material for tr in load_index(tmp_path / "index.csv")] == ["wood"]


def test_a_folder_that_cannot_be_written_keeps_the_touch_elsewhere(tmp_path, monkeypatch):
    """Disk full at the trial folder: the touch goes to a temporary folder, the message says where, exit 2."""
    from designkit.calibration import trials as trials_module

    real = trials_module.atomic_write_text
    full = tmp_path / "trials"

    def disk_full(path, text):
        if Path(path).parent == full:
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return real(path, text)

    monkeypatch.setattr(trials_module, "atomic_write_text", disk_full)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    with pytest.raises(TrialNotWritten) as exc:
        _cut_one_touch(full)
    msg = str(exc.value)
    assert "\n" not in msg and "No space left on device" in msg and "0 trial(s) kept" in msg
    rescued = Path(msg.split("was kept as ")[1].split(" (move it")[0])
    assert rescued.is_file() and rescued.with_suffix(".json").is_file()
    assert load_index(rescued.parent / "index.csv")[0].n_samples == 1601


# ------------------------------------------------- class 6: lines with wrong times
@pytest.mark.parametrize("fault, kind", [("duplicate", "duplicate"), ("out_of_order", "out_of_order")])
def test_one_percent_of_lines_with_wrong_times_lose_no_touch(tmp_path, fault, kind):
    """The audit: 1 % duplicated or out-of-order timestamps, and nothing was recorded for 20 device-minutes;
    each bad line discarded the touch in progress as 'the device clock went back by -0.000 s'."""
    prof = load_profile("designkit")
    with _emulator(prof, faults=Faults(**{fault: 0.01}), seed=4) as emu, \
            SerialRecorder(emu.port, prof, tmp_path) as rec:
        rec.record("wood", 3)
        sent = emu.samples_sent / 200.0
    assert len(rec.written) == 3 and sent < 3 * 13 + 12   # the first three touches, none skipped
    assert rec.status.gaps == 0 and rec.status.skipped == 0 and rec.status.bad_by_kind[kind] > 10
    messages = [e.message for e in rec.events]
    assert not any("went back" in m or "-0.000" in m for m in messages)
    assert any(m.startswith("skipped a line with a repeated timestamp" if kind == "duplicate" else
                            "skipped a line with a timestamp before") for m in messages)
    for p in rec.written:
        assert np.max(_wrong_samples(p, emu)) < 1e-3   # every sample where the clean wire put it


@pytest.mark.slow
def test_classify_decides_through_duplicated_timestamps():
    """classify decided nothing on such a stream and never gave up (run as a process: on the old code it hangs)."""
    mats = [EmulatedMaterial("metal", 20000.0), EmulatedMaterial("wood", 420.0)]
    plan = TouchPlan(touch_every_s=10.0, contact_s=4.0, touches_per_material=1)
    with _emulator(load_profile("designkit"), faults=Faults(duplicate=0.01), materials=mats, plan=plan,
                   speed=25.0) as emu:
        r = subprocess.run(_exe() + ["classify", "--port", emu.port, "--m", "metal=12767:25972", "--m",
                                     "wood=331:506.46", "--touches", "4", "--time-offset",
                                     str(emu.expected_time_offset_s), "--error-rate", "0.001", "--json"],
                           capture_output=True, text=True, timeout=90)
    assert r.returncode == 0, r.stderr
    got = [(d["state"], d["material"]) for d in json.loads(r.stdout)["decisions"]]
    assert got == [("decided", "metal"), ("decided", "wood")] * 2


def test_a_real_clock_reset_still_ends_the_trial_in_progress(tmp_path):
    prof = load_profile("designkit")
    emu = _emulator(prof)
    v = emu.values(0, 16 * 200)
    cols = np.column_stack([v["sensor"], v["object"], v["force"]])
    rec = SerialRecorder("/dev/whatever", prof, tmp_path)
    cutter = TrialCutter(prof, tmp_path, "wood")
    rec._feed_checked(v["timestamp"][:1000], cols[:1000], cutter)   # 5 s: in the first touch
    assert cutter.in_trial
    rec._feed_checked(v["timestamp"][:200], cols[1000:1200], cutter)  # the clock restarts at 0
    gaps = [e.message for e in rec.events if e.kind == "gap"]
    assert gaps == ["the device clock went back by 4.995 s, from 4.995 s to 0.000 s (device reset?)"]
    assert not cutter.in_trial and cutter.written == []


def test_a_stream_that_never_lets_a_touch_be_kept_gives_up_with_what_it_kept(tmp_path):
    """Samples lost every 5 s of device time: every 8 s trial is cut. The recorder stops after 3 touches and
    5 trial windows (40 s) of stream without a trial, instead of waiting for ever; exit 2 in the CLI."""
    prof = load_profile("designkit")
    with _emulator(prof, faults=Faults(gap_every_s=5.0, gap_s=0.02)) as emu:
        t0 = time.monotonic()
        r = subprocess.run(_exe() + ["calibrate", "record", "--port", emu.port, "--material", "wood", "--trials",
                                     "3", "--out", str(tmp_path / "t")], capture_output=True, text=True, timeout=60)
        took = time.monotonic() - t0
    assert r.returncode == 2 and took < 30
    last = r.stderr.strip().splitlines()[-1]   # after the events (gaps, touches skipped) as they came
    assert last.startswith("Error: ") and "touches in a row were skipped and none kept" in last and "0 trial(s) kept" in last
    with _emulator(prof, faults=Faults(gap_every_s=5.0, gap_s=0.02)) as emu, \
            SerialRecorder(emu.port, prof, tmp_path / "u") as rec:
        with pytest.raises(NoProgress) as exc:
            rec.record("wood", 3)
    assert rec.status.skipped >= 3 and "of stream" in str(exc.value)


# --------------------------------------------- class 7: lines that parse but lie
def test_corrupted_digits_beyond_the_noise_never_reach_a_trial(tmp_path):
    """The audit: 24.9884 read as 26.9884 ended inside trials. 2 % of lines get one digit changed; what is
    kept differs from the clean wire by less than the filter's margin, and each dropped sample is named in
    its trial's sidecar and on the event stream."""
    prof = load_profile("designkit")
    with _emulator(prof, faults=Faults(corrupt=0.02), seed=6) as emu, \
            SerialRecorder(emu.port, prof, tmp_path) as rec:
        rec.record("wood", 3)
    assert len(rec.written) == 3 and rec.status.bad_by_kind["implausible"] > 5
    dropped = []
    for p in rec.written:
        assert np.max(_wrong_samples(p, emu)) < SPIKE_SIGMAS * 0.05 * 1.5
        dropped += json.loads(p.with_suffix(".json").read_text()).get("dropped_samples", [])
    assert dropped and all(d["why"].startswith("implausible: ") for d in dropped)
    assert any(e.kind == "bad_line" and "physically impossible jump" in e.message for e in rec.events)
    assert any(e.kind == "trial" and "implausible sample(s) dropped" in e.message for e in rec.events)


@pytest.mark.parametrize("checksum", ["xor8", "crc16"])
def test_a_line_checksum_keeps_every_corrupted_line_out(tmp_path, checksum):
    prof = _profile(checksum)
    with _emulator(prof, faults=Faults(corrupt=0.02), seed=6) as emu, \
            SerialRecorder(emu.port, prof, tmp_path) as rec:
        rec.record("wood", 2)
    assert rec.status.bad_by_kind["checksum"] > 10 and "implausible" not in rec.status.bad_by_kind
    for p in rec.written:
        assert np.max(_wrong_samples(p, emu)) < 1e-3


def test_the_checksum_is_read_and_written_by_the_profile():
    prof = _profile("xor8")
    line = prof.format_lines({"timestamp": np.array([12.345]), "sensor": np.array([34.9987]),
                              "object": np.array([24.9975]), "force": np.array([0.012])})[0]
    assert line == "12.3450,34.9987,24.9975,0.012*22"
    parsed = prof.parse_lines([line.encode(), line.replace("24.99", "26.99").encode(), line[:-3].encode()])
    assert parsed.rows == [0] and [k for _, k, _ in parsed.errors] == ["checksum", "checksum"]
    assert prof.to_dict()["line"]["checksum"] == "xor8"
    assert profile_from_dict(prof.to_dict()).checksum == "xor8"
    data = prof.to_dict()
    data["line"]["checksum"] = "md5"
    with pytest.raises(InputError, match="line.checksum must be one of none, xor8, crc16; got 'md5'"):
        profile_from_dict(data)


def test_order_faults_keep_the_other_faults_draws():
    """New fault kinds draw from their own generator: streams seeded for the old ones are unchanged."""
    prof = load_profile("designkit")
    a = _emulator(prof, faults=Faults(garbled=0.05), seed=3).lines(0, 2000)
    b = _emulator(prof, faults=Faults(garbled=0.05, duplicate=0.01), seed=3).lines(0, 2000)
    assert b != a and set(b.split(b"\n")) == set(a.split(b"\n"))


def test_classify_gives_up_on_a_stream_that_never_lets_a_touch_be_decided(cli):
    """Samples lost every 1.5 s of device time: no touch has the second of quiet data it needs before contact."""
    mats = [EmulatedMaterial("metal", 20000.0), EmulatedMaterial("wood", 420.0)]
    plan = TouchPlan(touch_every_s=10.0, contact_s=4.0, touches_per_material=1)
    with _emulator(load_profile("designkit"), faults=Faults(gap_every_s=1.5, gap_s=0.02), materials=mats,
                   plan=plan, speed=25.0) as emu:
        r = cli("classify", "--port", emu.port, "--m", "metal=12767:25972", "--m", "wood=331:506.46", "--touches",
                "4", "--time-offset", str(emu.expected_time_offset_s), "--json")
    assert r.exit_code == 2, r.output
    out = json.loads(r.stdout)
    assert out["interrupted"] is True and out["decisions"] == []
    assert "touches in a row were skipped and none decided" in out["error"]["message"]


@settings(max_examples=40, deadline=None)
@given(label=st.text(min_size=0, max_size=140))
def test_any_label_is_refused_in_one_line_or_names_its_trials_safely(label):
    """Labels come from the command line: any text either is refused in one line, or makes a file name of
    letters, digits and '_' no longer than MAX_STEM_CHARS, while the label itself is kept whole."""
    try:
        check_material_label(label)
    except InputError as exc:
        assert "\n" not in str(exc) and str(exc).strip()
        return
    stem = trial_stem(label)
    assert re.fullmatch(r"[a-z0-9_]{1,%d}" % MAX_STEM_CHARS, stem)
    with tempfile.TemporaryDirectory() as tmp:
        t = np.arange(-200, 1401) / 200.0
        path = write_trial(Path(tmp), label, t, np.full(t.size, 35.0), np.full(t.size, 25.0),
                           np.full(t.size, 8.0), {})
        assert path.name == f"{stem}_001.csv"
        assert [tr.material for tr in load_index(Path(tmp) / "index.csv")] == [label]
