"""Calibration round trip over a pseudo-terminal, without hardware.

An emulated rig with a known sensor (the paper's: e_s = 892, alpha_s = 1.19e-9 m^2/s at
80 um) touches an aluminium-like object and wood, 10 times each, sigma 0.05 degC. Each
material is recorded over a real pty with pyserial exactly as from a USB rig, then the
engine identifies it again with the paper's semi-infinite model. The objects' effusivities are taken as known to about
5 % (an effusivity meter's accuracy): e_s is then identified to about that width.

Optionally also fits the shared robot recordings (metal and wood with the paper's
aluminium and wood ranges), choosing the model on held-out trial sets, when they are found (DESIGNKIT_ROBOT_DATA, or
../shared/data/robot-thermal-recordings next to the repository).

    python examples/calibration_roundtrip.py [--speed 100] [--out DIR]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from designkit import SENSORS
from designkit_lab.emulator import EmulatedMaterial, Emulator, TouchPlan
from designkit.calibration.fit import parse_ranges, resolve_ranges
from designkit.calibration.candidates import CANDIDATES
from designkit.calibration.compare import compare_models
from designkit.calibration.identify import identify
from designkit.calibration.split import choose_split
from designkit.calibration.profiles import load_profile
from designkit.calibration.recorder import SerialRecorder
from designkit.calibration.trials import load_index

OBJECTS = {"metal": 17530.0, "wood": 400.0}
RANGES = {"metal": (0.97, 1.08), "wood": (0.93, 1.02)}  # known to ~5 %, deliberately off-centre


def show(title, res, truth=None):
    print(f"\n{title}: {res.candidate.label}, {'consistent' if res.consistent else 'conflict'}")
    es = res.effusivity
    rows = [("e_s", es, truth and truth[0]), ("alpha_s", res.parameter("diffusivity_m2_s"), truth and truth[1]),
            ("time offset", res.parameter("time_offset_s"), truth and truth[2])]
    for name, p, t in rows:
        extra = f"   truth {t:.4g} ({100 * (p.value / t - 1):+.2f} %)" if t else ""
        print(f"  {name:12s} {p.value:.4g}  95 % [{p.ci95[0]:.4g}, {p.ci95[1]:.4g}]{extra}")
    for m, rms in res.rms_by_material_c.items():
        print(f"  {m:12s} residual RMS {rms:.4f} °C")
    for note in res.notes:
        print(f"  note: {note}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speed", type=float, default=100.0, help="device seconds per real second")
    ap.add_argument("--out", type=Path, default=None, help="folder for the trials (default: a temporary one)")
    args = ap.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="designkit-calibration-"))
    sensor = SENSORS["paper"]
    prof = load_profile("designkit")
    t0 = time.perf_counter()
    offset = None
    for seed, (label, e) in enumerate(OBJECTS.items()):
        emu = Emulator(prof, sensor, [EmulatedMaterial(label, e)], noise_c=0.05, speed=args.speed,
                       plan=TouchPlan(touch_every_s=13.0), seed=seed)
        with emu, SerialRecorder(emu.port, prof, out) as rec:
            print(f"recording {label} from {emu.port} ...")
            rec.record(label, 10)
            offset = emu.expected_time_offset_s
    print(f"recorded 20 trials in {time.perf_counter() - t0:.1f} s into {out}")
    specs = [f"{k}={OBJECTS[k] * lo}:{OBJECTS[k] * hi}" for k, (lo, hi) in RANGES.items()]
    res = identify(load_index(out / "index.csv"), "semi-infinite",
                   ranges=resolve_ranges(list(OBJECTS), parse_ranges(specs)))
    show("synthetic round trip", res, (sensor.effusivity, sensor.diffusivity_m2_s, offset))

    env = os.environ.get("DESIGNKIT_ROBOT_DATA")
    data = Path(env) if env else Path(__file__).resolve().parents[1].parent / "shared/data/robot-thermal-recordings"
    if (data / "index.csv").is_file():
        trials = load_index(data / "index.csv", only=["metal", "wood"])
        ranges = resolve_ranges(["metal", "wood"], parse_ranges(["metal=12767:25972", "wood=331:506"]))
        split = choose_split(trials, data / "index.csv")
        cmp = compare_models(split.fit, split.held_out, CANDIDATES, ranges=ranges)
        print(f"\nshared robot recordings: {split.describe()}; selected {cmp.reason}")
        show("shared robot recordings (paper: e_s = 892, alpha_s = 1.19e-9)",
             next(r for r in cmp.results if r.candidate.label == cmp.selected))
    else:
        print(f"\n(shared robot recordings not found at {data})")


if __name__ == "__main__":
    main()
