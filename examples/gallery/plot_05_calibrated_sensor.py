"""
A calibrated sensor answers a question
======================================

``designkit calibrate`` records touches of known materials and identifies the sensor; the sensor
file it writes is what ``--sensor`` and ``sensor=`` take. Here the touches come from a simulated
rig (a sensor of e_s = 1,200 J s^-1/2 K^-1 m^-2 and alpha_s = 1.0e-9 m^2/s, not the paper's),
eight touches of wood and of aluminium alloys, so the script runs without hardware; with a rig,
``designkit.calibration.trials.load_index`` reads the recorded ones instead.

The tables answer for the paper's sensor only. For another sensor the SVM's answer is computed
for the pair (``exact=True``: minutes); the ideal observer's bound is closed-form and answers in
milliseconds, which is what this example asks.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from designkit import SENSORS, Sensor, load_sensor
from designkit.figures import STYLE, log_ticks
from designkit.calibration.fit import resolve_ranges
from designkit.calibration.identify import identify
from designkit.calibration.trials import Trial
from designkit.materials import get_material
from designkit.objects import object_class
from designkit.query.ideal_bound import exact_ideal_min_contact
from designkit.simulation import noisy_readings

# %%
# Touches of a simulated rig: 1 s before contact, 3 s in contact, 200 Hz, 0.05 °C of noise.
rig = Sensor(1200.0, 1.0e-9, name="simulated rig")
rng = np.random.default_rng(0)
time_s = np.arange(-200, 600) / 200.0
touches = []
for name in ("wood", "aluminium alloys"):
    material = get_material(name)
    e_object = material.identified or 0.5 * (material.e_min + material.e_max)
    for k in range(8):
        sensor_c = np.where(time_s < 0, 35.0, 0.0)
        sensor_c[time_s >= 0] = noisy_readings(time_s[time_s >= 0], e_object, 35.0, 25.0, rig, 0.0, None)[0]
        touches.append(Trial(time_s, sensor_c + 0.05 * rng.standard_normal(time_s.size),
                             25.0 + 0.05 * rng.standard_normal(time_s.size), np.full(time_s.size, np.nan),
                             name, source=f"{name} {k + 1}"))

# %%
# Identify the sensor with the paper's model and write its sensor file.
fit = identify(touches, "semi-infinite", ranges=resolve_ranges(["wood", "aluminium alloys"], {}))
with tempfile.TemporaryDirectory() as folder:  # with a rig: --out my-sensor.yaml, kept
    mine = load_sensor(fit.sensor("my sensor").to_yaml(Path(folder) / "sensor.yaml"))
lo, hi = fit.effusivity.ci95
print(f"e_s = {mine.effusivity:.4g} [{lo:.4g}, {hi:.4g}] J s^-1/2 K^-1 m^-2 (true 1200), "
      f"alpha_s = {mine.diffusivity_m2_s:.3g} m^2/s (true 1e-09), noise {mine.noise_c:.3g} °C")

# %%
# The question: how long must the sensor touch to tell wood from glass? The ideal observer's
# shortest contact for the calibrated sensor and for the paper's, at 0.05 °C and against noise
# (one vectorized call per sensor).
wood, glass = object_class(material="wood"), object_class(material="glass")
edges = (wood.e_range[1] - 80.0, glass.e_range[0])  # the materials rule: the facing edges, 80 wide
noise_c = np.geomspace(0.005, 0.2, 40)
plt.rcParams.update(STYLE)
fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
for sensor, style in ((mine, "-"), (SENSORS["paper"], "--")):
    at_005 = float(exact_ideal_min_contact(sensor, *edges, 0.05 / 10))
    print(f"{sensor.name}: wood vs glass needs at least {at_005:.3g} s (ideal observer, 0.05 °C, dT 10 °C)")
    curve = exact_ideal_min_contact(sensor, edges[0], edges[1], noise_c / 10)
    ax.plot(noise_c, curve, style, label=f"{sensor.name} (e$_s$ {sensor.effusivity:.0f})")
ax.set_xscale("log")
log_ticks(ax.xaxis, [0.005, 0.01, 0.02, 0.05, 0.1, 0.2])
ax.set_xlabel("noise σ [°C]")
ax.set_ylabel("shortest contact, ideal observer [s]")
ax.set_title("Wood vs Glass (hardest pair), ΔT 10 °C, F1 ≥ 0.9")
ax.legend(loc="upper left")
plt.show()
