"""Serial fault scenarios (issue 36): touches sent by the rig against touches recorded, per scenario.

Run from the repository root::

    python benchmarks/bench_serial_faults.py                          # this tree
    python benchmarks/bench_serial_faults.py --baseline /path/to/old   # and an older tree, same scenarios

The rig is this tree's emulator (:class:`designkit_lab.emulator.Emulator`, in this
process, on a real pseudo-terminal); the recorder is ``designkit calibrate record`` (or
``designkit classify``) run as a process from the tree under test (``PYTHONPATH``), exactly
as a user runs it. An older tree records from the same emulator, so its figures are those of
its recorder on the same wire.

Per scenario:

- ``sent``: touches whose whole trial window (``pre_s`` before to ``post_s`` after the onset)
  the rig streamed to a recorder while it ran, not counting touches an injected fault destroyed
  on the wire (samples lost in a gap, a device that vanished mid-touch), at most the touches
  asked for (a recorder stops after them);
- ``kept``: trials on disk that an index lists (after the rebuild the next run does: a hard
  kill may leave a complete trial unlisted until then), plus a trial the recorder saved
  elsewhere when its folder could not take it (disk full);
- ``reported``: what the recorder said it wrote (``--json``); ``lost`` = ``sent - kept``
  (below zero: 0), and for two recorders ``reported - kept`` when larger (trials said
  written that another recorder overwrote);
- ``wrong``: samples in kept trials that differ from what a clean wire carried (the emulator's
  noise is seeded per sample, so the clean values are replayed exactly), ``gross`` those more
  than 0.4 degC off (8 times the emulated noise: no real sample is), and the largest difference
  [degC]. Without a timestamp a duplicated line shifts the counted clock of every later sample
  by one period: those samples differ by the signal's change over 5 ms, not by a corruption;
- ``exit`` and ``s``: the recorder's exit status and real seconds (``hang``: still running
  when the scenario's limit came, killed).

A disk-full scenario needs a small file system: it mounts a 200 kB tmpfs when run as root and
is skipped otherwise.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from designkit import SENSORS  # noqa: E402
from designkit_lab.emulator import EmulatedMaterial, Emulator, Faults, TouchPlan  # noqa: E402
from designkit.calibration.profiles import list_profiles, load_profile  # noqa: E402

PLAN = TouchPlan(touch_every_s=13.0)
TOUCHES = 3
LIMIT_S = 60.0


def _recorder(tree: Path, args: list[str]) -> list[str]:
    return [sys.executable, "-m", "designkit", *args]   # the tree comes first on PYTHONPATH (_env)


def _env(tree: Path) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree)
    return env


def _popen(cmd, tree: Path, **kw) -> subprocess.Popen:
    """Start a recorder from ``tree`` (run there: ``python -m`` puts the working folder first on sys.path)."""
    return subprocess.Popen(cmd, env=_env(tree), cwd=str(tree), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, **kw)


def _emu(prof, faults=Faults(), seed=0, speed=50.0, materials=None, plan=PLAN) -> Emulator:
    return Emulator(prof, SENSORS["paper"], materials or [EmulatedMaterial("wood", 400.0)], noise_c=0.05,
                    sensor_temp_c=35.0, ambient_c=25.0, plan=plan, speed=speed, faults=faults, seed=seed)


def _whole_touches(emu: Emulator, device_s: float, faults: Faults) -> int:
    """Touches whose trial window ended before ``device_s`` and that no injected gap or vanish cut."""
    p = emu.profile
    n = 0
    for j in range(1000):
        on = emu.touch(j).expected_onset_s
        lo, hi = on - p.trial.pre_s, on + p.trial.post_s
        if hi > device_s:
            break
        if faults.vanish_after_s and hi > faults.vanish_after_s:
            break
        if faults.gap_every_s:
            k = np.arange(1, 1000) * faults.gap_every_s
            if np.any((k < hi) & (k + faults.gap_s * emu.speed > lo)):
                continue
        n += 1
    return n


#: A difference from the clean wire no sample can have: 8 times the emulated noise (0.05 degC).
GROSS_C = 0.4


def _wrong(folder: Path, emu: Emulator) -> tuple[int, int, float]:
    n, gross, worst = 0, 0, 0.0
    fs = emu.profile.sample_rate_hz
    for side in folder.glob("*.json"):
        meta = json.loads(side.read_text())
        csv = side.with_suffix(".csv")
        if "onset_device_time_s" not in meta or not csv.exists():
            continue
        d = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
        k = np.rint((d[:, 0] + meta["onset_device_time_s"]) * fs).astype(int)
        clean = emu.values(int(k.min()), int(k.max()) + 1)
        i = k - k.min()
        err = np.zeros(k.size)
        for role, col in (("sensor", 2), ("object", 1)):   # what a clean wire carried, read back
            conv = emu.profile.channels[role].conversion
            want = conv.to_value(conv.encode(clean[role][i]))
            err = np.maximum(err, np.abs(d[:, col] - want))
        n += int(np.sum(err > 2e-4))
        gross += int(np.sum(err > GROSS_C))
        worst = max(worst, float(err.max()))
    return n, gross, worst


def _kept(folder: Path) -> int:
    from designkit.calibration.trials import rebuild_index, recorded_trials

    if not folder.is_dir() or not list(folder.glob("*.json")):
        return 0
    try:
        rebuild_index(folder)
    except Exception:  # noqa: BLE001 - an index we would not rewrite: count what it lists
        pass
    return len(recorded_trials(folder))


def _run(cmd, tree, limit=LIMIT_S, on_start=None):
    t0 = time.monotonic()
    proc = _popen(cmd, tree, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    if on_start is not None:
        on_start(proc)
    try:
        out, err = proc.communicate(timeout=limit)
        code = proc.returncode
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        code = "hang"
    return code, out, err, time.monotonic() - t0


def _reported(out: str) -> int | None:
    try:
        return int(json.loads(out)["n_trials"])
    except (ValueError, KeyError, TypeError):
        return None


def _checked_profile(tmp: Path, checksum: str) -> Path:
    data = yaml.safe_load(list_profiles()["designkit"].read_text())
    data["line"]["checksum"] = checksum
    data["name"] = f"designkit-{checksum}"
    path = tmp / f"designkit-{checksum}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


# --------------------------------------------------------------------- scenarios
def record_scenario(tree, tmp, name, *, profile="designkit", faults=Faults(), speed=50.0, label="wood",
                    signal_after=None, limit=LIMIT_S, touches=TOUCHES, folder=None):
    prof = load_profile(profile)
    out = folder or tmp / name
    emu = _emu(prof, faults, speed=speed)
    at_signal = {}

    def on_start(proc):
        if signal_after is None:
            return
        sig, n = signal_after
        deadline = time.monotonic() + limit
        while time.monotonic() < deadline and len(list(out.glob("*.json"))) < n and proc.poll() is None:
            time.sleep(0.005)
        at_signal["device_s"] = emu.samples_sent / prof.sample_rate_hz
        proc.send_signal(sig)

    with emu:
        code, so, se, secs = _run(_recorder(tree, ["calibrate", "record", "--port", emu.port, "--profile",
                                                   str(profile), "--material", label, "--trials", str(touches),
                                                   "--out", str(out), "--json"]), tree, limit, on_start)
        device_s = at_signal.get("device_s", emu.samples_sent / prof.sample_rate_hz)
        # at a signal, a touch that ended in the last 2 device-seconds may not be written yet by anyone
        sent = _whole_touches(emu, device_s - (2.0 if signal_after else 0.0), faults)
    if signal_after is None:
        sent = min(sent, touches)
    kept = _kept(out)
    rescued = 0
    for line in se.splitlines():
        if "was kept as " in line:
            path = Path(line.split("was kept as ")[1].split(" (move it")[0])
            rescued += int(path.is_file())
    wrong, gross, worst = _wrong(out, emu) if out.is_dir() else (0, 0, 0.0)
    return {"scenario": name, "sent": sent, "kept": kept + rescued, "reported": _reported(so),
            "lost": max(0, sent - kept - rescued), "wrong": wrong, "gross": gross, "worst_c": worst, "exit": code,
            "s": secs, "note": (se.strip().splitlines() or [""])[-1][:160]}


def two_recorders(tree, tmp):
    prof = load_profile("designkit")
    out = tmp / "two"
    with _emu(prof, speed=50.0) as a, _emu(prof, seed=1, speed=50.0) as b:
        cmds = [_recorder(tree, ["calibrate", "record", "--port", e.port, "--material", "wood", "--trials",
                                 str(TOUCHES), "--out", str(out), "--json"]) for e in (a, b)]
        t0 = time.monotonic()
        procs = [_popen(c, tree) for c in cmds]
        results = [p.communicate(timeout=LIMIT_S) for p in procs]
        secs = time.monotonic() - t0
        sent = sum(min(_whole_touches(e, e.samples_sent / 200.0, Faults()), TOUCHES) for e in (a, b))
    reported = sum(_reported(o) or 0 for o, _ in results)
    kept = _kept(out)
    return {"scenario": "two recorders, one folder", "sent": sent, "kept": kept, "reported": reported,
            "lost": max(sent - kept, reported - kept, 0), "wrong": 0, "gross": 0, "worst_c": 0.0,
            "exit": "/".join(str(p.returncode) for p in procs), "s": secs,
            "note": " | ".join((e.strip().splitlines() or [""])[-1][:100] for _, e in results)}


def classify_scenario(tree, name, faults, limit=LIMIT_S):
    mats = [EmulatedMaterial("metal", 20000.0), EmulatedMaterial("wood", 420.0)]
    plan = TouchPlan(touch_every_s=10.0, contact_s=4.0, touches_per_material=1)
    emu = _emu(load_profile("designkit"), faults, materials=mats, plan=plan, speed=25.0)
    with emu:
        code, so, se, secs = _run(_recorder(tree, [
            "classify", "--port", emu.port, "--m", "metal=12767:25972", "--m", "wood=331:506.46", "--touches", "4",
            "--time-offset", str(emu.expected_time_offset_s), "--error-rate", "0.001", "--json"]), tree, limit)
    try:
        got = [(d["state"], d["material"]) for d in json.loads(so)["decisions"]]
    except (ValueError, KeyError):
        got = []
    right = sum(g == ("decided", m) for g, m in zip(got, ["metal", "wood"] * 2))
    return {"scenario": name, "sent": 4, "kept": right, "reported": len(got), "lost": 4 - right, "wrong": 0,
            "gross": 0, "worst_c": 0.0, "exit": code, "s": secs, "note": (se.strip().splitlines() or [""])[-1][:160]}


def disk_full(tree, tmp):
    mnt = tmp / "full"
    mnt.mkdir()
    if os.geteuid() != 0 or subprocess.run(["mount", "-t", "tmpfs", "-o", "size=200k", "tmpfs", str(mnt)],
                                           capture_output=True).returncode != 0:
        return None
    try:
        env_tmp = tmp / "systmp"
        env_tmp.mkdir()
        os.environ["TMPDIR"] = str(env_tmp)   # where a recorder may save what its folder cannot take
        return record_scenario(tree, tmp, "disk full (200 kB)", folder=mnt / "trials")
    finally:
        os.environ.pop("TMPDIR", None)
        subprocess.run(["umount", str(mnt)], capture_output=True)


def scenarios(tree: Path, tmp: Path, only: set[str] | None):
    ck = _checked_profile(tmp, "xor8")
    runs = [
        ("clean", lambda: record_scenario(tree, tmp, "clean")),
        ("out-of-order", lambda: record_scenario(tree, tmp, "out-of-order 1 %", faults=Faults(out_of_order=0.01))),
        ("duplicate", lambda: record_scenario(tree, tmp, "duplicated 1 %", faults=Faults(duplicate=0.01))),
        ("corrupt", lambda: record_scenario(tree, tmp, "corrupted digit 1 %", faults=Faults(corrupt=0.01))),
        ("corrupt-xor8", lambda: record_scenario(tree, tmp, "corrupted digit 1 %, xor8 profile", profile=ck,
                                                 faults=Faults(corrupt=0.01))),
        ("order-5", lambda: record_scenario(tree, tmp, "out-of-order 5 %, duplicated 5 %",
                                            faults=Faults(out_of_order=0.05, duplicate=0.05))),
        ("adc-corrupt", lambda: record_scenario(tree, tmp, "corrupted digit 1 % (adc12, no timestamp)",
                                                profile="adc12-thermistor", faults=Faults(corrupt=0.01))),
        ("adc-dup", lambda: record_scenario(tree, tmp, "duplicated 1 % (adc12, no timestamp)",
                                            profile="adc12-thermistor", faults=Faults(duplicate=0.01))),
        ("garbled", lambda: record_scenario(tree, tmp, "garbled/dropped lines 5 % (adc12)",
                                            profile="adc12-thermistor", faults=Faults(garbled=0.03, partial=0.02))),
        ("gap", lambda: record_scenario(tree, tmp, "samples lost (gap every 20 s)",
                                        faults=Faults(gap_every_s=20.0, gap_s=0.01))),
        ("gap-storm", lambda: record_scenario(tree, tmp, "samples lost every 5 s (no touch can be kept)",
                                              faults=Faults(gap_every_s=5.0, gap_s=0.02), limit=45.0)),
        ("vanish", lambda: record_scenario(tree, tmp, "device vanishes at 31 s", faults=Faults(vanish_after_s=31.0),
                                           touches=5)),
        ("two", lambda: two_recorders(tree, tmp)),
        ("label", lambda: record_scenario(tree, tmp, "300-character label", label="w" * 300)),
        ("sigint", lambda: record_scenario(tree, tmp, "SIGINT after 1 trial", speed=20.0, touches=50,
                                           signal_after=(signal.SIGINT, 1))),
        ("sigterm", lambda: record_scenario(tree, tmp, "SIGTERM after 1 trial", speed=20.0, touches=50,
                                            signal_after=(signal.SIGTERM, 1))),
        ("sigkill", lambda: record_scenario(tree, tmp, "SIGKILL after 2 trials", speed=20.0, touches=50,
                                            signal_after=(signal.SIGKILL, 2))),
        ("disk-full", lambda: disk_full(tree, tmp)),
        ("classify-dup", lambda: classify_scenario(tree, "classify, duplicated 1 %", Faults(duplicate=0.01),
                                                   limit=45.0)),
        ("classify-order", lambda: classify_scenario(tree, "classify, out-of-order 1 %", Faults(out_of_order=0.01),
                                                     limit=45.0)),
    ]
    for key, fn in runs:
        if only and key not in only:
            continue
        row = fn()
        if row is not None:
            row["key"] = key
            yield row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", type=Path, help="an older designkit tree to run the same scenarios with")
    ap.add_argument("--only", nargs="*", help="scenario keys to run (default: all)")
    ap.add_argument("--json", type=Path, help="also write the rows here")
    args = ap.parse_args()
    trees = ([("baseline", args.baseline.resolve())] if args.baseline else []) + [("this tree", ROOT)]
    rows = []
    head = f"{'scenario':46s} {'tree':9s} {'sent':>4s} {'kept':>4s} {'said':>4s} {'lost':>4s} {'wrong':>5s} " \
           f"{'gross':>5s} {'worst':>6s} {'exit':>5s} {'s':>5s}  last line"
    print(head)
    for label, tree in trees:
        where = subprocess.run([sys.executable, "-c", "import designkit; print(designkit.__file__)"], env=_env(tree),
                               cwd=str(tree), capture_output=True, text=True).stdout.strip()
        print(f"# {label}: recorder from {where}", flush=True)
        with tempfile.TemporaryDirectory(prefix="designkit-faults-") as tmp:
            for r in scenarios(tree, Path(tmp), set(args.only) if args.only else None):
                r["tree"] = label
                rows.append(r)
                said = "-" if r["reported"] is None else str(r["reported"])
                print(f"{r['scenario'][:46]:46s} {label:9s} {r['sent']:4d} {r['kept']:4d} {said:>4s} {r['lost']:4d} "
                      f"{r['wrong']:5d} {r['gross']:5d} {r['worst_c']:6.3f} {str(r['exit']):>5s} {r['s']:5.1f}  {r['note']}",
                      flush=True)
    for label, _ in trees:
        mine = [r for r in rows if r["tree"] == label]
        print(f"{label}: {sum(r['lost'] for r in mine)} touches lost of {sum(r['sent'] for r in mine)} sent in "
              f"{len(mine)} scenarios; {sum(r['gross'] for r in mine)} samples kept more than {GROSS_C} degC from the "
              f"clean wire ({sum(r['wrong'] for r in mine)} differing at all); "
              f"{sum(r['exit'] == 'hang' for r in mine)} hangs")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1, default=str))


if __name__ == "__main__":
    main()
