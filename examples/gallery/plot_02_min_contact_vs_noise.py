"""
Shortest contact against noise, for one pair of materials
=========================================================

How much does a quieter sensor shorten the touch that tells stainless steel from aluminium? One array call
asks the question at 30 noise levels; materials given by name are answered for their hardest
pair (the facing edges of the two effusivity ranges).
"""

import matplotlib.pyplot as plt
import numpy as np

from designkit.figures import STYLE, log_ticks
from designkit.query import min_contact

noise_c = np.geomspace(0.01, 0.2, 30)  # noise sigma per sample [°C]
answer = min_contact(m1="stainless steel", m2="aluminium alloys", noise_c=noise_c, delta_t_c=10)

for sigma in (0.01, 0.05, 0.1):
    single = min_contact(m1="stainless steel", m2="aluminium alloys", noise_c=sigma, delta_t_c=10)
    print(f"noise {sigma:g} °C: {single.value:.3g} s "
          f"(interval {single.interval[0]:.3g} to {single.interval[1]:.3g} s), ideal {single.ideal:.3g} s")

# %%
# ``answer.in_grid`` says where the answer lies inside the table's grid (here everywhere: the
# table tabulates contact times of 0.5 to 10 s and sigma/dT of 0.0005 to 0.05).
assert answer.in_grid.all()
plt.rcParams.update(STYLE)
fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
ax.fill_between(noise_c, answer.low, answer.high, color="C0", alpha=0.25, lw=0,
                label="SVM, 90 % interval")
ax.plot(noise_c, answer.value, color="C0", label="SVM (the paper's classifier)")
ax.plot(noise_c, answer.ideal, "--", color="C1", label="ideal observer bound")
ax.set_xscale("log")
ax.set_yscale("log")
log_ticks(ax.xaxis, [0.01, 0.02, 0.05, 0.1, 0.2])
log_ticks(ax.yaxis, [0.6, 1, 2, 4])
ax.set_xlabel("noise σ [°C]")
ax.set_ylabel("shortest contact [s]")
ax.set_title("Stainless steel vs Aluminium alloys, ΔT 10 °C, F1 ≥ 0.9, the paper's sensor")
ax.legend(loc="upper left")
plt.show()
