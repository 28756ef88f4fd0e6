"""Per-touch simulation cost of each forward model, against the semi-infinite model's, old code and new.

A realistic case: 100 touches of one effusivity class (wood, 331-506 J s^-1/2 K^-1 m^-2), 2 s and 10 s
of contact at 200 Hz, a calibrated real-rig sensor (layered film on the finger, contact conductance,
thermistor lag, the host's Savitzky-Golay smoothing, and the force-driven contact area along a
nominal 1.7 s ramp sampled every 20 ms). Each model's cost is ``draw_trials`` + ``render_trials`` per
touch in CPU seconds (``time.process_time``: the shared machine's load does not enter; BLAS on one
thread, as a sweep worker runs), the median of ``--repeats`` renders of fresh classes of the same scene (a sweep renders class
after class of one scene: "warm"), and the first render of a scene ("cold": what a one-off
simulation pays). The old code (commit ``--baseline``, extracted with ``git archive``) runs in a
subprocess in the same run; the new code is this tree's. Also printed: the largest difference of
the new readings from the old on the same draws (normalized, i.e. in units of ``|Ts0 - Ta|``) and
the tolerance the simulation asks (1 % of the noise over the curve).

Run: ``PYTHONPATH=. python benchmarks/bench_sim_models.py [--repeats 5] [--baseline c8fe4cc]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

CASE = r'''
import json, sys, time
import numpy as np
import scipy.interpolate, scipy.signal, scipy.special  # imports outside the timings
from designkit import Scene
from designkit.sensor import Sensor
from designkit.models import get_model
from designkit.models.ramp import ForceRamp
from designkit.simulation import draw_trials, render_trials

repeats = int(sys.argv[1])
sensor = Sensor(1980.74, 8.798e-09, depth_m=8e-5, name="rig")
layered = get_model("layered", film_thickness_m=0.000221, backing_effusivity_ws05_m2k=1980742.7,
                    conductance_w_m2k=18496.5, lag_s=2.618, smoothing_window=99, smoothing_order=3)
tp = np.arange(-50, 76) * 0.02
ramp = ForceRamp.from_force_profile(layered, tp, np.clip(0.05 + 0.95 * (tp + 0.5) / 2.5, 0, 1), 0.168)
models = {"semi-infinite": get_model(), "contact": get_model("contact", conductance_w_m2k=2500.0),
          "layered": layered, "force-ramp": ramp}
out = {}
for contact in (2.0, 10.0):
    scene = Scene(contact_s=contact, noise_c=0.05)
    m = sensor.times_s(contact).size
    render_trials(draw_trials(331.0, 506.0, 2, m, [0]), sensor, scene, get_model())   # imports
    for name, fm in models.items():
        times = []
        for r in range(repeats + 1):
            lo = 331.0 + 20.0 * r
            t0 = time.process_time()
            d = draw_trials(lo, lo + 175.0, 100, m, [1, r])
            temps = render_trials(d, sensor, scene, fm).temperature_c
            times.append((time.process_time() - t0) / 100)
            if r == 0:
                u = (temps - scene.sensor_temp_c - scene.noise_c * d.noise) / (scene.ambient_temp_c - scene.sensor_temp_c)
        out[f"{name}@{contact:g}"] = {"cold_s": times[0], "warm_s": float(np.median(times[1:])),
                                      "u": u[:, ::7].tolist()}
print(json.dumps(out))
'''


def run(pythonpath: str, repeats: int) -> dict:
    env = dict(os.environ, PYTHONPATH=pythonpath, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1",
               MKL_NUM_THREADS="1")  # one core per process, as a sweep worker has
    with tempfile.TemporaryDirectory() as cwd:  # python -c puts its working directory first on sys.path
        res = subprocess.run([sys.executable, "-c", CASE, str(repeats)], env=env, capture_output=True, text=True,
                             check=True, cwd=cwd)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5, help="warm renders per model and contact time")
    ap.add_argument("--baseline", default="c8fe4cc", help="the old code's commit")
    args = ap.parse_args()
    import numpy as np

    from designkit import Scene
    from designkit.simulation import response_tolerance

    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as tmp:
        tar = subprocess.run(["git", "-C", str(root), "archive", args.baseline, "designkit"], capture_output=True,
                             check=True).stdout
        subprocess.run(["tar", "-x", "-C", tmp], input=tar, check=True)
        old = run(tmp, args.repeats)
    new = run(str(root), args.repeats)
    print(f"per-touch simulation cost (draw + render, 100 touches of wood, 200 Hz), old = {args.baseline}, "
          "new = this tree; ratio to the semi-infinite touch of the same code")
    print(f"{'model':<14}{'contact':>8}{'old warm':>11}{'ratio':>7}{'new warm':>11}{'ratio':>7}"
          f"{'new cold':>11}{'ratio':>7}{'max |du|':>11}{'tol':>10}")
    for key in new:
        name, contact = key.split("@")
        base_o, base_n = old[f"semi-infinite@{contact}"], new[f"semi-infinite@{contact}"]
        o, n = old[key], new[key]
        du = float(np.max(np.abs(np.array(o["u"]) - np.array(n["u"]))))
        m = int(float(contact) * 200) + 1
        tol = response_tolerance(Scene(contact_s=float(contact), noise_c=0.05).noise_ratio, m)
        print(f"{name:<14}{contact + ' s':>8}{o['warm_s'] * 1e3:>9.3f}ms{o['warm_s'] / base_o['warm_s']:>7.1f}"
              f"{n['warm_s'] * 1e3:>9.3f}ms{n['warm_s'] / base_n['warm_s']:>7.1f}"
              f"{n['cold_s'] * 1e3:>9.3f}ms{n['cold_s'] / base_n['warm_s']:>7.1f}{du:>11.2e}{tol:>10.1e}")


if __name__ == "__main__":
    main()
