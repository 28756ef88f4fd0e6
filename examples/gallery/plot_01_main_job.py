"""
The main job: the shortest contact, with its interval
=====================================================

Which contact time separates an object of effusivity 35,000 J s^-1/2 K^-1 m^-2 from one of
20,000, with the paper's sensor, 0.05 °C of noise and the sensor 10 °C warmer than the object?
This is ``designkit min-contact --e1 35000 --e2 20000`` as one library call.
"""

import matplotlib.pyplot as plt
import numpy as np

from designkit.figures import STYLE, log_ticks
from designkit.query import min_contact

answer = min_contact(35000, 20000, noise_c=0.05, delta_t_c=10)
low, high = answer.interval
print(f"shortest contact: {answer.value:.3g} s "
      f"({answer.interval_coverage:.0%} interval {low:.3g} to {high:.3g} s), SVM")
print(f"ideal observer bound: {answer.ideal:.3g} s (no classifier does better)")

# %%
# Every question takes numpy arrays and answers all elements in one call (an ``ArrayAnswer``
# with ``value``, ``low``, ``high`` and ``ideal`` arrays). Here the partner's effusivity runs
# from 2,000 to 32,000: the closer the two objects, the longer the touch.
partner = np.geomspace(2000, 32000, 40)
curve = min_contact(35000, partner, noise_c=0.05, delta_t_c=10)
assert np.isclose(min_contact(35000, [20000.0]).value[0], answer.value)  # one answer everywhere

plt.rcParams.update(STYLE)
fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
ax.fill_between(partner, curve.low, curve.high, color="C0", alpha=0.25, lw=0,
                label="SVM, 90 % interval")
ax.plot(partner, curve.value, color="C0", label="SVM (the paper's classifier)")
ax.plot(partner, curve.ideal, "--", color="C1", label="ideal observer bound")
ax.errorbar([20000], [answer.value], yerr=[[answer.value - low], [high - answer.value]], fmt="o",
            color="black", capsize=3, label=f"the main job: {answer.value:.3g} s")
ax.set_yscale("log")
log_ticks(ax.yaxis, [0.5, 1, 2, 4, 8])  # label the log axis at round values
ax.set_xlabel("the partner's effusivity [J s$^{-1/2}$ K$^{-1}$ m$^{-2}$]; the other object: 35,000")
ax.set_ylabel("shortest contact [s]")
ax.set_title("F1 ≥ 0.9, noise 0.05 °C, ΔT 10 °C, the paper's sensor")
ax.legend(loc="upper left")
plt.show()
