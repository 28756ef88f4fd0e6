"""
The F1 matrix of the paper's materials
======================================

The paper's Fig. 3: the SVM's F1 for every pair of effusivity intervals, here after 2 s of
contact at noise over temperature difference 0.005 (0.05 °C at 10 °C), read from two shipped
tables: ``f1-matrix-fine-low`` (intervals of 80 J s^-1/2 K^-1 m^-2 up to 4,000, where nine of the
paper's twelve materials lie) and ``f1-matrix-2s`` (intervals of 400 up to 40,000). Each material
is drawn as its effusivity range on the diagonal: two materials are told apart (F1 ≥ 0.9) where
the off-diagonal square between their ranges is yellow.
"""

import matplotlib.pyplot as plt
import numpy as np

from designkit.figures import STYLE
from designkit.materials import list_materials
from designkit.tables.store import load_table

RATIO = 0.005  # noise sigma over temperature difference


def f1_matrix(name):
    """The table's F1 matrix at sigma/dT = RATIO and its interval edges [J s^-1/2 K^-1 m^-2]."""
    table = load_table(name)
    k = int(np.argmin(abs(table.axes["noise_ratio"] - RATIO)))
    centres = table.axes["e_ref"]
    half = 0.5 * (centres[1] - centres[0])
    edges = np.append(centres - half, centres[-1] + half)
    return table.arrays["f1_matrix"][k, 0], edges, table.threshold


materials = list_materials(set="paper12")
plt.rcParams.update(STYLE)
fig, axes = plt.subplots(1, 2, figsize=(9.0, 4.6), constrained_layout=True)
for ax, name, scale in zip(axes, ("f1-matrix-fine-low", "f1-matrix-2s"), (1, 1000)):
    f1, edges, threshold = f1_matrix(name)
    pairs = f1[np.triu_indices_from(f1, 1)]
    print(f"{name}: {np.mean(pairs >= threshold):.0%} of {pairs.size} interval pairs reach F1 {threshold:g}")
    im = ax.pcolormesh(edges / scale, edges / scale, f1, cmap="viridis", vmin=0.5, vmax=1.0)
    shown = [m for m in materials if m.e_max <= edges[-1]] if scale == 1 else materials[-3:]
    for k, mat in enumerate(shown):
        lo, hi = mat.e_min / scale, mat.e_max / scale
        ax.add_patch(plt.Rectangle((lo, lo), hi - lo, hi - lo, fill=False, ec="red", lw=1.0))
        if scale == 1 and mat.e_max < 1000:
            continue  # the six below 1000 overlap: named together below
        right = hi < 0.8 * edges[-1] / scale  # beside the box's lower right corner, or left of its top
        ax.annotate(mat.name, (hi, lo) if right else (lo, hi), xytext=(3, -2) if right else (-3, -2),
                    textcoords="offset points", fontsize=7, va="top", ha="left" if right else "right")
    if scale == 1:
        ax.annotate("cardboard, wood, rubber,\nacrylic, ABS, MDF", (900, 250), fontsize=7)
    unit = "" if scale == 1 else "10$^3$ "
    ax.set_xlabel(f"effusivity [{unit}J s$^{{-1/2}}$ K$^{{-1}}$ m$^{{-2}}$]")
    ax.set_ylabel(f"effusivity [{unit}J s$^{{-1/2}}$ K$^{{-1}}$ m$^{{-2}}$]")
    ax.set_aspect("equal")
    ax.grid(False)
    ax.set_title(f"{name}: 2 s of contact, σ/ΔT {RATIO:g}")
fig.colorbar(im, ax=axes, shrink=0.8, label="F1 of the SVM (3-fold; white: an interval against itself)")
plt.show()
