"""Rough edges a new user hit with the calibration commands (issue 14's walkthrough): each through the CLI."""

from __future__ import annotations

import contextlib
import json
import shlex
from pathlib import Path

import pytest
from test_calibration_cli import METER_RANGES, _synthetic_index

from designkit.sensor import load_sensor

RANGES = sum((["--range", x] for x in METER_RANGES), [])


def _png_size(path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


# ------------------------------------------------ calibrate fit --model --plot
@pytest.mark.parametrize("model", ["semi-infinite", "contact"])
def test_fit_with_a_model_writes_the_plot(cli, tmp_path, model):
    index = _synthetic_index(tmp_path / "trials", n=3)
    plot = tmp_path / "fig" / "fit.png"
    r = cli("calibrate", "fit", index, *RANGES, "--model", model, "--plot", plot)
    assert r.exit_code == 0, r.output
    assert f"wrote {plot}" in r.stdout
    w, h = _png_size(plot)
    assert w > 1000 and h > 300
    r = cli("calibrate", "fit", index, *RANGES, "--model", model, "--plot", tmp_path / "j.png", "--json")
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["plot"] == str(tmp_path / "j.png") and (tmp_path / "j.png").exists()


def test_a_refused_model_fit_still_writes_its_plot(cli, tmp_path):
    """As without --model: the figure shows why the sensor file was refused."""
    index = _synthetic_index(tmp_path / "trials", n=3)
    plot, out = tmp_path / "refused.png", tmp_path / "s.yaml"
    r = cli("calibrate", "fit", index, "--range", "metal=100:200", "--range", "wood=331:506",
            "--model", "semi-infinite", "--out", out, "--plot", plot)
    assert r.exit_code == 2 and "not written" in r.stderr
    assert not out.exists()
    _png_size(plot)


# ------------------------------------ emulate and the guided run agree on the protocol
def _two_materials(per_material: int, seed: int = 0, speed: float = 100.0):
    from designkit import SENSORS
    from designkit_lab.emulator import EmulatedMaterial, Emulator, TouchPlan
    from designkit.calibration.profiles import load_profile

    return Emulator(load_profile("designkit"), SENSORS["paper"],
                    [EmulatedMaterial("metal", 17530.0), EmulatedMaterial("wood", 400.0)], noise_c=0.05,
                    plan=TouchPlan(touch_every_s=13.0, touches_per_material=per_material), speed=speed, seed=seed)


def test_guided_run_refuses_an_emulator_that_alternates(cli, tmp_path):
    """The old default: the emulator alternated while the guided run recorded all of metal first."""
    out = tmp_path / "run"
    with _two_materials(1) as emu:
        r = cli("calibrate", "--port", emu.port, "--material", "metal", "--material", "wood", "--trials", "2",
                *RANGES, "--out", out, "--model", "semi-infinite", "--yes")
    assert r.exit_code == 2
    errors = [ln for ln in r.stderr.strip().splitlines() if ln.startswith("Error:")]
    assert len(errors) == 1 and errors[0].startswith("Error: the emulator touches metal, wood, metal, wood in turn")
    assert "--touches-per-material 2" in errors[0] and r.stderr.strip().endswith(errors[0])
    assert not (out / "index.csv").exists()


def test_emulate_and_guided_defaults_agree(cli):
    from designkit.cli import calibrate as cal
    from designkit_lab.cli import emulate as emu

    r = cli("emulate", "--help")
    assert r.exit_code == 0
    import inspect

    emulate_default = inspect.signature(emu.emulate).parameters["touches_per_material"].default
    guided_default = inspect.signature(cal.guided).parameters["trials"].default
    assert emulate_default == guided_default == cal.DEFAULT_TRIALS


@contextlib.contextmanager
def _emulator_process(ctrl_c_able, *args):
    """``designkit emulate ARGS --json`` in its own process: yields what it announces, stopped with Ctrl-C after."""
    import signal
    import subprocess

    from test_calibration_cli import _exe, _read_json_object

    proc = subprocess.Popen(_exe() + ["emulate", *args, "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            **ctrl_c_able)
    try:
        yield _read_json_object(proc.stdout)
    finally:
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=20)


@pytest.mark.slow
def test_the_emulators_hint_pastes_into_a_shell_and_labels_right(cli, tmp_path, ctrl_c_able):
    """A material name with a space: the printed command is quoted, and running it records right."""
    with _emulator_process(ctrl_c_able, "--material", "Aluminium alloys", "--material", "wood",
                           "--touches-per-material", "2", "--touch-every", "13", "--speed", "50",
                           "--duration", "60") as info:
        args = shlex.split(info["try"])
        assert args[:2] == ["designkit", "calibrate"]
        assert args[args.index("--material") + 1] == "Aluminium alloys"
        assert args[args.index("--trials") + 1] == "2" and "--yes" in args
        args[args.index("--out") + 1] = str(tmp_path / "trials")
        r = cli(*args[1:], "--model", "semi-infinite", "--json", "--force")
        assert r.exit_code == 0, r.output
        labels = [json.loads((tmp_path / "trials" / p).with_suffix(".json").read_text())["material"]
                  for p in json.loads(r.stdout)["record"]["trials"]]
    played = [m["label"] for m in info["materials"]]    # database names as the database spells them
    assert played[0] == "Aluminium alloys" and played[1].lower() == "wood"
    assert labels == [played[0]] * 2 + [played[1]] * 2


def test_a_run_out_of_step_with_the_emulator_stops_before_a_wrong_label(cli, tmp_path):
    """Another program read the emulator's first line and touch 1 (as a run waiting for Enter loses
    touches): the run sees no plan, but each touch is announced as it starts, and touch 3 (wood)
    stops a run that records metal before it is written."""
    import serial

    out = tmp_path / "run"
    with _two_materials(2, speed=10.0) as emu:
        with serial.Serial(emu.port, timeout=0.05) as first:
            seen = b""
            while b'touch 1 of "metal" starts' not in seen:
                seen += first.read(4096)
        r = cli("calibrate", "record", "--port", emu.port, "--material", "metal", "--trials", "2", "--out", out)
    assert r.exit_code == 2
    errors = [ln for ln in r.stderr.strip().splitlines() if ln.startswith("Error:")]
    assert len(errors) == 1 and errors[0].startswith(
        f"Error: the emulator on {emu.port} starts touch 3 with wood while this run records metal ("), r.stderr
    # touch 2 recorded (metal); on a loaded machine it may have passed before the run opened the port
    assert ("(this run's touches of metal so far were metal)" in errors[0] and "1 trial(s) kept" in errors[0]) or \
        ("(metal is another of its materials)" in errors[0] and "0 trial(s) kept" in errors[0]), errors[0]
    from designkit.calibration.trials import recorded_trials

    kept = recorded_trials(out)
    assert len(kept) <= 1 and all(p.name.startswith("metal") for p in kept)


def test_an_announcement_names_the_emulators_materials(tmp_path):
    """A run that missed the first line still knows the emulator's labels from any touch's announcement."""
    from designkit._validation import InputError
    from designkit.calibration.touch_plan import parse_announcement
    from designkit.cli.calibrate import _EmulatorWatch

    emu = _two_materials(2)
    msg = emu.announcement(2)
    assert parse_announcement(msg)[:2] == (3, "wood")
    watch = _EmulatorWatch(["metal"], 2, "/dev/pts/9", tmp_path)
    with pytest.raises(InputError, match="metal is another of its materials"):
        watch(msg, "metal")
    _EmulatorWatch(["block"], 2, "/dev/pts/9", tmp_path)(msg, "block")   # a name of one's own is fine


@pytest.mark.parametrize("materials, trials, touches, expect", [
    (["metal", "wood"], 2, ["metal", "metal", "wood", "wood"], None),
    (["a", "b"], 2, ["metal", "metal", "wood", "wood"], None),            # any names, one per material
    (["metal", "wood"], 2, ["metal", "wood"], "while this run records metal (this run's touches of metal so far"),
    (["a", "b"], 1, ["metal", "metal"], "while this run records b (this run recorded metal as a)"),
])
def test_each_announced_touch_is_checked_against_the_label(tmp_path, materials, trials, touches, expect):
    from designkit._validation import InputError
    from designkit.cli.calibrate import _EmulatorWatch

    watch = _EmulatorWatch(materials, trials, "/dev/pts/9", tmp_path)   # its first line not seen: no plan
    recording = [m for m in materials for _ in range(trials)]
    try:
        for j, (label, ours) in enumerate(zip(touches, recording)):
            watch(f'# designkit emulator: touch {j + 1} of "{label}" starts', ours)
        got = None
    except InputError as exc:
        got = str(exc)
    if expect is None:
        assert got is None
    else:
        assert got is not None and expect in got and "--yes" in got


@pytest.mark.slow
def test_the_emulators_classify_hint_decides_its_touches_right(cli, ctrl_c_able):
    """classify's --time-offset defaults to 0 (a calibrated sensor file carries its own): against the emulator
    every touch was decided as the same material. The emulator now prints a classify line with its offset;
    run as printed, it decides the alternating touches right."""
    with _emulator_process(ctrl_c_able, "--material", "a=400", "--material", "b=600", "--touches-per-material",
                           "1", "--touch-every", "13", "--speed", "40", "--duration", "60") as info:
        args = shlex.split(info["try_classify"])
        assert args[:2] == ["designkit", "classify"] and args[args.index("--time-offset") + 1] == "-0.25"
        r = cli(*args[1:], "--touches", "4", "--json")
        assert r.exit_code == 0, r.output
        got = [d["material"] for d in json.loads(r.stdout)["decisions"]]
    assert got == ["a", "b", "a", "b"]


# ------------------------------------------------ the guided run over a rig replaying real touches
def _replay_rig(robot_data_dir, per_material: int, profile):
    """An emulator whose touches are the shared recordings' own (metal and wood of sets 1, 2, ...), in turn.

    Each recording (1 s before its onset to 7 s after, at 200 Hz) is played from its first sample on,
    its last sample held 0.8 s longer (the recorder's window of 7 s counts from its own, later onset),
    then released; between touches the sensor rests at the next touch's first reading.
    """
    import numpy as np

    from designkit import SENSORS
    from designkit_lab.emulator import EmulatedMaterial, Emulator, TouchPlan
    from designkit.calibration.trials import load_index

    trials = load_index(robot_data_dir / "index.csv", only=["metal", "wood"])
    recs = {m: [tr for tr in trials if tr.material == m][:per_material] for m in ("metal", "wood")}

    class Replay(Emulator):
        def values(self, k0, k1):
            p, fs = self.plan, self.profile.sample_rate_hz
            t = np.arange(k0, k1) / fs
            j = np.maximum(np.floor((t - p.first_touch_s + 1.0) / p.touch_every_s), 0).astype(int)
            rel = t - (p.first_touch_s + j * p.touch_every_s)
            out = {k: np.zeros(t.size) for k in ("sensor", "object", "force")}
            for jj in np.unique(j):
                rec = recs[self.material_of_touch(int(jj)).label][int(jj) % p.touches_per_material]
                sel = j == jj
                idx = np.clip(np.rint((rel[sel] - rec.time_s[0]) * fs).astype(int), 0, rec.time_s.size - 1)
                pressed = (rel[sel] >= rec.time_s[0]) & (rel[sel] < rec.time_s[-1] + 0.8)
                out["sensor"][sel] = rec.sensor_c[idx]
                out["object"][sel] = rec.object_c[idx]
                out["force"][sel] = np.where(pressed, np.maximum(rec.force_n[idx], 0.0), 0.0)
            return {**out, "timestamp": t}

    return Replay(profile, SENSORS["paper"], [EmulatedMaterial("metal", 17530.0), EmulatedMaterial("wood", 400.0)],
                  noise_c=0.0, plan=TouchPlan(touch_every_s=13.0, touches_per_material=per_material,
                                              press_force_n=4.0), speed=100.0)


@pytest.mark.slow
def test_guided_run_over_a_replayed_real_rig_writes_a_sensor_file_that_holds(cli, robot_data_dir, tmp_path):
    """Issue 34: the guided run recorded 60 real touches, then refused them (the paper's model conflicts).
    Now it chooses the model on held-out touches (no trial sets: each material's second half) and writes it."""
    import yaml

    from designkit.calibration.profiles import load_profile

    text = (Path(__file__).parents[1] / "calibration" / "profiles" / "designkit.yaml").read_text()
    prof_path = tmp_path / "rig.yaml"   # the rig presses at 4-5 N: contact from 2 N (its recorder's onset), release 1 N
    data = yaml.safe_load(text)
    data["name"] = "rig"
    data["contact"].update(force_threshold_n=2.0, release_n=1.0)
    prof_path.write_text(yaml.safe_dump(data))
    out = tmp_path / "run"
    with _replay_rig(robot_data_dir, 30, load_profile(str(prof_path))) as emu:
        r = cli("calibrate", "--port", emu.port, "--profile", prof_path, "--material", "metal", "--material", "wood",
                "--trials", "30", "--range", "metal=aluminium", "--out", out, "--yes", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["record"]["n_trials"] == 60
    fit = d["fit"]
    assert fit["split"]["by"] == "touch order" and fit["n_fit"] == 30 and fit["n_held_out"] == 30
    best = next(x for x in fit["results"] if x["candidate"] == fit["selected"])
    assert best["consistent"] and best["held_out_rms_c"]["metal"] <= 0.05 and best["held_out_rms_c"]["wood"] <= 0.05
    sen = load_sensor(Path(d["sensor"]))
    assert sen.model["candidate"] == fit["selected"] and not sen.problems
