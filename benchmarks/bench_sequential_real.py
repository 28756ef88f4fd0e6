"""Live decisions on the real robot recordings, replayed sample by sample (issue 17).

Run from the repository root (needs ../shared/data/robot-thermal-recordings or
``DESIGNKIT_ROBOT_DATA``)::

    python benchmarks/bench_sequential_real.py

Protocol, fixed before looking at test touches:

- the sensor (e_s, tau) and the contact time offset are identified by designkit's
  calibration on trial sets 1-4 (metal and wood; :func:`designkit_lab.reproduce.robot.calibrate`);
  the white-noise sigma the test assumes is that fit's residual RMS (the model's
  misfit, 40x the thermistor noise: the honest noise of this model on these data);
- candidates: metal [12767, 25972] and wood [331, 506] J s^-1/2 K^-1 m^-2 (the
  calibration ranges); each touch's Ts0 is the heated sensor's mean before
  contact and Ta the passive thermistor's (what a robot measures);
- a second run assumes sigma = RMS x sqrt(99): the recordings were smoothed by the host
  with a Savitzky-Golay window of 99 samples (the recordings' README), so the misfit is
  correlated over about 99 samples and a white-noise likelihood counts each piece of
  evidence about 99 times; sqrt(99) is the matching inflation (chosen from the README,
  not tuned on the test touches);
- the test touches (sets 5-20) are replayed sample by sample through
  :meth:`SequentialTest.update` from the calibrated onset, up to 4 s;
- baseline: the paper's SVM trained and tested on real touches (3-fold x 10
  shuffles, first 4 s; :func:`designkit_lab.reproduce.robot.real_pair_f1`).

Cold wood is the same material as wood, cooled below the room: its touches are
replayed too, and the test's answers for them are printed (metal / wood /
undecided) beside the SVM that was trained on real cold wood as a class of its own.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

from designkit.recognition.sequential import SequentialTest
from designkit_lab.reproduce.robot import calibrate, load_real, real_pair_f1


def data_dir() -> Path | None:
    env = os.environ.get("DESIGNKIT_ROBOT_DATA")
    for p in ([Path(env)] if env else []) + [Path(__file__).resolve().parents[1] / ".." / "shared" / "data" /
                                             "robot-thermal-recordings", Path("/work/shared/data/robot-thermal-recordings")]:
        if (p / "index.csv").exists():
            return p
    return None


def main(eps_list=(0.01, 0.001)) -> int:
    d = data_dir()
    if d is None:
        print("robot recordings not found (set DESIGNKIT_ROBOT_DATA): nothing to measure")
        return 0
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    t0 = time.perf_counter()
    touches = load_real(d, contact_s=6.0)
    setup = calibrate(touches, seed=0)
    print(f"calibration ({time.perf_counter() - t0:.1f} s): {setup.source}")
    sensor, offset, rms = setup.sensor, setup.time_offset_s, setup.rms_c
    print(f"  e_s {sensor.effusivity:.0f}, tau {sensor.tau_s:.3f} s, time offset {offset:+.3f} s, "
          f"residual RMS {rms:.3f} degC")
    test_sets = touches.trial_set >= 5
    fs = sensor.sample_rate_hz
    k0 = int(round(max(offset, 0.0) * fs))  # first sample after the heat starts to flow
    cands = [("metal", (12767.0, 25972.0)), ("wood", (331.0, 506.0))]
    print(f"test touches: trial sets 5-20, {int(test_sets.sum())} touches; replay from {k0 / fs:.3f} s after the "
          f"detected onset, at most 4 s of contact")
    for sigma, why in ((rms, "residual RMS"), (rms * np.sqrt(99.0), "residual RMS x sqrt(99), the smoothing window")):
        print(f" sigma {sigma:.3f} degC ({why}):")
        for eps in eps_list:
            rows = {}
            for mat in ("metal", "wood", "cold_wood"):
                idx = np.flatnonzero(test_sets & (touches.material == mat))
                out = []
                for i in idx:
                    test = SequentialTest(cands, sensor, noise_c=sigma, sensor_temp_c=touches.sensor_temp_c[i],
                                          ambient_temp_c=touches.object_temp_c[i], error_rate=eps, max_contact_s=4.0)
                    dec = None
                    for k in range(k0, touches.time_s.size):
                        t_rel = (k - k0) / fs
                        if t_rel > 4.0 + 1e-9:
                            break
                        dec = test.update(t_rel, touches.sensor_c[i, k])
                        if dec.final:
                            break
                    out.append((dec.state, dec.material, dec.time_s))
                rows[mat] = out
            mw = rows["metal"] + rows["wood"]
            truth = ["metal"] * len(rows["metal"]) + ["wood"] * len(rows["wood"])
            decided = [o for o in mw if o[0] == "decided"]
            correct = sum(o[0] == "decided" and o[1] == t for o, t in zip(mw, truth))
            times = np.array([o[2] for o in mw])
            print(f"  eps {eps:g}: metal vs wood: {correct}/{len(mw)} correct ({correct / len(mw):.3f}), "
                  f"{len(mw) - len(decided)} undecided by 4 s; time to decision mean {times.mean():.3f} s, "
                  f"median {np.median(times):.3f}, max {times.max():.3f} "
                  f"(metal {np.mean([o[2] for o in rows['metal']]):.3f}, wood {np.mean([o[2] for o in rows['wood']]):.3f})")
            cw = rows["cold_wood"]
            says = {m: sum(o[0] == "decided" and o[1] == m for o in cw) for m in ("metal", "wood")}
            print(f"          cold wood ({len(cw)} touches): said metal {says['metal']}, wood {says['wood']}, "
                  f"undecided {len(cw) - sum(says.values())}; mean time {np.mean([o[2] for o in cw]):.3f} s")
    real4 = load_real(d, contact_s=4.0)
    for pair in (("wood", "metal"), ("cold_wood", "metal")):
        r = real_pair_f1(real4, pair, repeats=10, seed=0)
        print(f"baseline, fixed 4 s, the paper's SVM trained on real touches: {pair[0]} vs {pair[1]}: accuracy "
              f"{r['accuracy']:.3f}, F1 {r['f1']:.3f} +- {r['f1_sd']:.3f} (all 20 sets, 3-fold x 10)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
