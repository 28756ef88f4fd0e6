"""
Materials by name, as arrays
============================

Which of the paper's materials can the sensor tell from glass, and after how long? A material is
an effusivity range; :func:`~designkit.query.pair_question` applies the materials rule (the
hardest pair: the classes at the facing edges of the two ranges) and gives the effusivities to
ask for. All pairs and two noise levels go into one array call.
"""

import matplotlib.pyplot as plt
import numpy as np

from designkit.figures import STYLE
from designkit.materials import list_materials
from designkit.query import min_contact, pair_question

reference = "paper12:glass"
others = [m.name for m in list_materials(set="paper12") if m.name != "Glass"]
pairs = {name: pair_question(m1=reference, m2=f"paper12:{name}") for name in others}
apart = [name for name, p in pairs.items() if p.classes is not None]  # overlapping ranges: no answer
e1 = np.array([pairs[n].points[0] for n in apart])
e2 = np.array([pairs[n].points[1] for n in apart])
noise_c = np.array([[0.02], [0.05]])  # two noise levels down, the pairs across
answer = min_contact(e1, e2, noise_c=noise_c, delta_t_c=10)
assert answer.shape == (2, len(apart))

for name, t, lo, hi in zip(apart, answer.value[1], answer.low[1], answer.high[1]):
    print(f"Glass vs {name}: {t:.3g} s ({lo:.3g} to {hi:.3g} s) at 0.05 °C")
print("no answer (overlapping ranges):", ", ".join(n for n in others if n not in apart) or "none")
assert answer.value[1, 0] == min_contact(m1=reference, m2=f"paper12:{apart[0]}").value

plt.rcParams.update(STYLE)
fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
y = np.arange(len(apart))
for k, (sigma, dy) in enumerate(zip(noise_c[:, 0], (-0.18, 0.18))):
    v = answer.value[k]
    ax.errorbar(v, y + dy, xerr=[v - answer.low[k], answer.high[k] - v], fmt="o", capsize=2,
                color=f"C{k}", label=f"SVM, noise {sigma:g} °C (90 % interval)")
    ax.plot(answer.ideal[k], y + dy, "|", color=f"C{k}", ms=9, mew=1.5)
ax.plot([], [], "|", color="0.3", ms=9, mew=1.5, label="ideal observer bound")
ax.set_yticks(y, [f"Glass vs {n}" for n in apart])
ax.invert_yaxis()
ax.set_xlabel("shortest contact [s]")
ax.set_title("The paper's sensor, ΔT 10 °C, F1 ≥ 0.9")
ax.legend(loc="lower right")
plt.show()
