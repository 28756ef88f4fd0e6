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

A sweep reads many classes of one scene: ``SCENE`` renders every class of a 60-interval grid (0-24,000
J s^-1/2 K^-1 m^-2, the rig's materials' span) and 100 intervals of the paper's (width 80), 2 repeats
each (seeds as a sweep's), and prints each model's CPU per touch over the whole scene against the
semi-infinite touch's (issue 35's target: at most 2x), old code and new, with the largest difference of
the new readings from the old and from the model read directly at every touch's effusivity (the
independent reference: no interpolation), on every 10th touch of 6 classes, every sample.

``RIG`` renders the calibrated rig's table touches (``--rig``, default tests/data/rig_sensor.yaml): 40 classes at
three of its table's contacts, as the sweep's scorer renders them (each touch pressing as one of the calibration
touches, ``simulation.touch_picks``; the rig's correlated noise, from its onset), against the semi-infinite model in
the same scene, old code and new: their first repeat (the scene's panels read as the classes need them) and their
second (what a sweep's later repeats and blocks pay).

Run: ``PYTHONPATH=. python benchmarks/bench_sim_models.py [--repeats 5] [--baseline fe434f1] [--only-rig]``.
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

DIRECT = r'''
import json
import numpy as np
from designkit.sensor import Sensor
from designkit.models import get_model
from designkit.models.ramp import ForceRamp

rng = np.random.default_rng(2024)
out = []
for case in range(12):   # random layered models and ramps, read directly (no interpolation) at random objects
    sensor = Sensor(float(rng.uniform(500, 3000)), float(rng.uniform(5e-9, 5e-8)), depth_m=float(rng.uniform(2e-5, 2e-4)))
    lay = get_model("layered", film_thickness_m=float(rng.uniform(5e-5, 5e-4)),
                    backing_effusivity_ws05_m2k=float(rng.uniform(200, 5e5)),
                    conductance_w_m2k=float(rng.choice([np.inf, rng.uniform(500, 5e4)])),
                    lag_s=float(rng.choice([0.0, rng.uniform(0.05, 3.0)])),
                    smoothing_window=int(rng.choice([0, 99])), smoothing_order=3)
    tp = np.arange(0, 60) * 0.02
    model = lay if case % 2 == 0 else ForceRamp.from_force_profile(lay, tp, np.clip(tp / float(rng.uniform(0.3, 1.1)), 0, 1),
                                                                    float(rng.uniform(0.0, 0.4)))
    t = np.arange(int(rng.integers(201, 801))) / 200.0
    e = rng.uniform(20, 30000, 7)
    out.append(model.response(t, e, sensor).tolist())
print(json.dumps(out))
'''


SCENE = r'''
import json, sys, time
import numpy as np
import scipy.interpolate, scipy.signal, scipy.special  # imports outside the timings
from designkit import Scene
from designkit.sensor import Sensor
from designkit.models import get_model
from designkit.models.ramp import ForceRamp
from designkit.simulation import draw_trials, render_trials

sensor = Sensor(1980.74, 8.798e-09, depth_m=8e-5, name="rig")
layered = get_model("layered", film_thickness_m=0.000221, backing_effusivity_ws05_m2k=1980742.7,
                    conductance_w_m2k=18496.5, lag_s=2.618, smoothing_window=99, smoothing_order=3)
tp = np.arange(-50, 76) * 0.02
ramp = ForceRamp.from_force_profile(layered, tp, np.clip(0.05 + 0.95 * (tp + 0.5) / 2.5, 0, 1), 0.168)
models = {"semi-infinite": get_model(), "contact": get_model("contact", conductance_w_m2k=2500.0),
          "layered": layered, "force-ramp": ramp}
grids = {"rig-60": np.linspace(0.0, 24000.0, 61), "paper-100": 80.0 * np.arange(101)}
sample = (1, 7, 19, 33, 48, 59)
out = {}
for gname, edges in grids.items():
    for contact in (2.0, 10.0):
        scene = Scene(contact_s=contact, noise_c=0.05)
        m = sensor.times_s(contact).size
        render_trials(draw_trials(331.0, 506.0, 2, m, [0]), sensor, scene, get_model())   # imports
        for name, fm in models.items():
            us = {}
            t0 = time.process_time()
            for k in range(edges.size - 1):
                for rep in (0, 1):
                    d = draw_trials(edges[k], edges[k + 1], 100, m, [0, k, rep])
                    temps = render_trials(d, sensor, scene, fm).temperature_c
                    if rep == 0 and k in sample:
                        us[k] = ((temps - scene.sensor_temp_c - scene.noise_c * d.noise)
                                 / (scene.ambient_temp_c - scene.sensor_temp_c), d.effusivity)
            cpu = time.process_time() - t0
            direct = 0.0
            if name in ("layered", "force-ramp"):
                t = np.arange(m) / sensor.sample_rate_hz
                direct = max(float(np.max(np.abs(u - fm.response(t, e, sensor)))) for u, e in us.values())
            out[f"{name}@{contact:g}@{gname}"] = {"touch_s": cpu / (2 * 100 * (edges.size - 1)), "direct": direct,
                                                  "u": [u[::10].tolist() for u, _ in us.values()]}
print(json.dumps(out))
'''

RIG = r'''
import json, sys, time
import numpy as np
import scipy.interpolate, scipy.signal, scipy.special  # imports outside the timings
from designkit.models import get_model
from designkit.sweep.for_sensor import effusivity_span, sensor_sweep_config
from designkit.simulation import draw_trials, render_trials, touch_picks, window_times_s

cfg = sensor_sweep_config(sys.argv[2], span=effusivity_span(material_set="paper12"))
sensor = cfg.resolved_sensor()
out = {}
for ci in (0, 4, 7):
    scene = cfg.scene((0,), cfg.contact_s[ci])
    m = window_times_s(sensor, scene).size
    for name, fm in (("semi-infinite", get_model()), ("rig", cfg.model)):
        render_trials(draw_trials(331.0, 506.0, 2, m, [0]), sensor, scene, fm, None, touch_picks(fm, [0], 2))   # cold
        cpu = []
        for rep in (0, 1):   # the classes' first repeat (the scene's panels read as needed), then their second
            us, t0 = [], time.process_time()
            for k in range(200, 240):
                d = draw_trials(cfg.edges[k], cfg.edges[k + 1], cfg.trials, m, [cfg.seed, k, rep])
                us.append(render_trials(d, sensor, scene, fm, None,
                                        touch_picks(fm, [cfg.seed, k, rep], cfg.trials)).temperature_c)
            cpu.append((time.process_time() - t0) / (40 * cfg.trials))
            if rep == 0:
                u0 = [u[::9, ::5].tolist() for u in us[::4]]
        out[f"{name}@{cfg.contact_s[ci]:.3f}"] = {"touch_s": cpu[0], "warm_s": cpu[1], "u": u0}
print(json.dumps(out))
'''


def run(pythonpath: str, repeats: int, code: str = CASE, *extra: str) -> dict:
    env = dict(os.environ, PYTHONPATH=pythonpath, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1",
               MKL_NUM_THREADS="1")  # one core per process, as a sweep worker has
    with tempfile.TemporaryDirectory() as cwd:  # python -c puts its working directory first on sys.path
        res = subprocess.run([sys.executable, "-c", code, str(repeats), *extra], env=env, capture_output=True, text=True,
                             check=True, cwd=cwd)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5, help="warm renders per model and contact time")
    ap.add_argument("--baseline", default="fe434f1", help="the old code's commit")
    ap.add_argument("--rig", default=str(Path(__file__).resolve().parents[1] / "tests/data/rig_sensor.yaml"),
                    help="the calibrated rig's sensor file (its table's touches: 24 touch ramps, correlated noise)")
    ap.add_argument("--only-rig", action="store_true", help="only the rig's table touches")
    args = ap.parse_args()
    import numpy as np

    from designkit import Scene
    from designkit.simulation import response_tolerance

    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as tmp:
        tar = subprocess.run(["git", "-C", str(root), "archive", args.baseline, "designkit"], capture_output=True,
                             check=True).stdout
        subprocess.run(["tar", "-x", "-C", tmp], input=tar, check=True)
        old_rig = run(tmp, 0, RIG, args.rig)
        if not args.only_rig:
            old = run(tmp, args.repeats)
            old_direct = run(tmp, 0, DIRECT)
            old_scene = run(tmp, 0, SCENE)
    new_rig = run(str(root), 0, RIG, args.rig)
    print("the calibrated rig's table touches (sensor_sweep_config of --rig, paper12; 40 classes of 100 touches as the "
          "sweep renders them: each touch pressing as one of the 24 calibration touches, the rig's correlated noise, "
          "from its onset), CPU per touch and its ratio to the semi-infinite touch in the same scene; max|du|: new "
          "against old readings [degC at the sweep's dT = 1 degC]")
    print("(first: the classes' first repeat, the scene's panels read as they are needed; again: their second "
          "repeat, as a sweep renders every class twice and more)")
    print(f"{'contact':>9}{'':>6}{'old':>11}{'ratio':>7}{'new':>11}{'ratio':>7}{'new/old':>9}{'max|du|':>11}")
    for key in new_rig:
        name, contact = key.split("@")
        if name != "rig":
            continue
        o, n = old_rig[key], new_rig[key]
        so, sn = old_rig[f"semi-infinite@{contact}"], new_rig[f"semi-infinite@{contact}"]
        du = max(float(np.max(np.abs(np.array(a) - np.array(b)))) for a, b in zip(o["u"], n["u"]))
        for when, f in (("first", "touch_s"), ("again", "warm_s")):
            if f not in o:   # a baseline from before the second repeat was timed
                continue
            print(f"{contact + ' s' if when == 'first' else '':>9}{when:>6}{o[f] * 1e3:>9.4f}ms{o[f] / so[f]:>7.1f}"
                  f"{n[f] * 1e3:>9.4f}ms{n[f] / sn[f]:>7.1f}{n[f] / o[f]:>9.2f}"
                  + (f"{du:>11.2e}" if when == "first" else ""))
    if args.only_rig:
        return
    new = run(str(root), args.repeats)
    new_direct = run(str(root), 0, DIRECT)
    new_scene = run(str(root), 0, SCENE)
    print(f"per-touch simulation cost (draw + render, 100 touches of wood, 200 Hz), old = {args.baseline}, "
          "new = this tree; ratio to the semi-infinite touch of the same code")
    print(f"{'model':<14}{'contact':>8}{'old warm':>11}{'ratio':>7}{'new warm':>11}{'ratio':>7}"
          f"{'new cold':>11}{'ratio':>7}{'max|du|':>11}{'tol':>10}")
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
    print("a whole scene (every class of the grid, 2 repeats, 100 touches each), CPU per touch and its ratio to the "
          "semi-infinite touch of the same code; max|du|: new against old readings; direct: new against the model "
          "read at every touch's effusivity")
    print(f"{'model':<14}{'grid':>10}{'contact':>8}{'old':>11}{'ratio':>7}{'new':>11}{'ratio':>7}{'max|du|':>11}"
          f"{'direct':>10}{'tol':>10}")
    for key in new_scene:
        name, contact, grid = key.split("@")
        base_o, base_n = old_scene[f"semi-infinite@{contact}@{grid}"], new_scene[f"semi-infinite@{contact}@{grid}"]
        o, n = old_scene[key], new_scene[key]
        du = max(float(np.max(np.abs(np.array(a) - np.array(b)))) for a, b in zip(o["u"], n["u"]))
        m = int(float(contact) * 200) + 1
        tol = response_tolerance(Scene(contact_s=float(contact), noise_c=0.05).noise_ratio, m)
        print(f"{name:<14}{grid:>10}{contact + ' s':>8}{o['touch_s'] * 1e3:>9.4f}ms"
              f"{o['touch_s'] / base_o['touch_s']:>7.2f}{n['touch_s'] * 1e3:>9.4f}ms"
              f"{n['touch_s'] / base_n['touch_s']:>7.2f}{du:>11.2e}{n['direct']:>10.2e}{tol:>10.1e}")
    o = np.concatenate([np.ravel(a) for a in old_direct])
    n = np.concatenate([np.ravel(a) for a in new_direct])
    big = np.abs(o) > 1e-6
    print(f"direct evaluation (no interpolation), 12 random layered models and ramps, {o.size} readings: "
          f"max |new - old| = {np.max(np.abs(n - o)):.2e}, max relative difference where u > 1e-6: "
          f"{np.max(np.abs(n - o)[big] / np.abs(o[big])):.2e}")


if __name__ == "__main__":
    main()
