"""Multi-class recognition, which the paper left open: k materials at once.

Each material is one class whose touches have effusivity uniform over the
material's whole range (the paper's binary analysis instead averages F1 over
pairs of 80-wide intervals). The classifier is the paper's pipeline with
scikit-learn's multi-class SVC (one-vs-one); accuracy and confusion come from
stratified 3-fold cross-validation.

The ideal observer's multi-class accuracy is exact here: with fixed initial
conditions every class's touches reduce to one number ``v ~ w(e) + N(0, s^2)``
(:mod:`designkit.recognition.ideal`), so the Bayes classifier picks the class of highest
density of ``v``. Its accuracy is computed from the classes' laws of ``v``
(:func:`designkit.recognition.ideal.class_density` and ``class_survival``, closed
form): each class's probability over the runs of ``v`` where its density is the
highest, between the crossings of the densities
(:func:`designkit.query.matrix.multiclass_ideal_accuracy`).
"""

from __future__ import annotations

import time

import numpy as np

from ._report import Context, SectionResult, fmt, md_table
from .matrices import AMBIENT_C

__all__ = ["bayes_accuracy", "section_multiclass", "svm_multiclass"]

NOISE_C = 0.05
DELTA_T_C = 10.0
SUBSET_SIZES = (2, 3, 5, 10, 20, 40)
_MAX_BINS = 100_000


def bayes_accuracy(ranges, sensor, scene) -> float:
    """Best multi-class accuracy of any classifier (equal priors), classes uniform over ``ranges``.

    :func:`designkit.query.matrix.multiclass_ideal_accuracy` (the one implementation,
    which ``designkit matrix`` uses too).

    Parameters
    ----------
    ranges : array_like, shape (K, 2)
        Effusivity range of each class [J s^-1/2 K^-1 m^-2].
    sensor : Sensor
    scene : Scene
        Fixed initial conditions.
    """
    from designkit.query.matrix import multiclass_ideal_accuracy

    return multiclass_ideal_accuracy(ranges, sensor, scene, max_bins=_MAX_BINS)


def svm_multiclass(ranges, trials: int, sensor, scene, seed) -> dict:
    """Cross-validated (3-fold) accuracy and confusion of the paper's SVM on K classes at once.

    :func:`designkit.query.matrix.multiclass_svm_accuracy` (the one implementation).
    """
    from designkit.query.matrix import multiclass_svm_accuracy

    return multiclass_svm_accuracy(ranges, trials, sensor, scene, seed)


def section_multiclass(ctx: Context) -> SectionResult:
    """k materials at once: accuracy against k (database), and the paper's 12 materials' confusion."""
    t0 = time.perf_counter()
    from designkit.materials import list_materials
    from designkit.scene import Scene
    from designkit.sensor import SENSORS
    from designkit._validation import as_generator

    title = "Multi-class recognition: k materials at once (left open by the paper)"
    quick = ctx.settings.quick
    seed = ctx.settings.seed
    sensor = SENSORS["paper"]
    trials = 15 if quick else 60
    subsets = 1 if quick else 5
    sizes = SUBSET_SIZES[:3] if quick else SUBSET_SIZES
    db = list_materials()
    rng = as_generator([seed, 307])
    curve = []
    steps = len(sizes) * subsets + (0 if quick else 1) + 2
    done = 0
    scene2 = Scene.from_delta_t(contact_s=2.0, noise_c=NOISE_C, delta_t_c=DELTA_T_C, ambient_temp_c=AMBIENT_C)
    for k in sizes:
        accs, bayes = [], []
        for r in range(subsets):
            pick = np.sort(rng.choice(len(db), size=k, replace=False))
            ranges = [db[i].effusivity_range for i in pick]
            accs.append(svm_multiclass(ranges, trials, sensor, scene2, [seed, 311, k, r])["accuracy"])
            bayes.append(bayes_accuracy(ranges, sensor, scene2))
            done += 1
            ctx.step(done, steps)
        curve.append({"k": k, "subsets": subsets, "svm_accuracy": float(np.mean(accs)),
                      "svm_accuracy_sd": float(np.std(accs, ddof=1)) if len(accs) > 1 else 0.0,
                      "bayes_accuracy": float(np.mean(bayes)), "chance": 1.0 / k})
    if not quick:
        ranges = [m.effusivity_range for m in db]
        res = svm_multiclass(ranges, trials, sensor, scene2, [seed, 311, len(db), 0])
        curve.append({"k": len(db), "subsets": 1, "svm_accuracy": res["accuracy"], "svm_accuracy_sd": 0.0,
                      "bayes_accuracy": bayes_accuracy(ranges, sensor, scene2), "chance": 1.0 / len(db)})
        done += 1
        ctx.step(done, steps)

    p12 = list_materials(set="paper12")
    names = [m.name for m in p12]
    p12_ranges = [m.effusivity_range for m in p12]
    p12_res = {}
    for c in (2.0, 4.0):
        sc = scene2.replace(contact_s=c)
        res = svm_multiclass(p12_ranges, 30 if quick else 100, sensor, sc, [seed, 313, int(c)])
        p12_res[c] = {"accuracy": res["accuracy"], "confusion": res["confusion"].tolist(),
                      "bayes_accuracy": bayes_accuracy(p12_ranges, sensor, sc)}
        done += 1
        ctx.step(done, steps)

    from designkit.figures import pyplot

    plt = pyplot()
    from matplotlib.ticker import NullLocator

    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8), constrained_layout=True,
                             gridspec_kw={"width_ratios": [1.0, 1.15, 1.15]})
    ks = [c["k"] for c in curve]
    axes[0].errorbar(ks, [c["svm_accuracy"] for c in curve], yerr=[c["svm_accuracy_sd"] for c in curve],
                     marker="o", label="SVM (paper's pipeline)")
    axes[0].plot(ks, [c["bayes_accuracy"] for c in curve], "s--", label="ideal observer (Bayes)")
    axes[0].plot(ks, [c["chance"] for c in curve], ":", color="grey", label="chance")
    axes[0].set_xscale("log")
    axes[0].set_xticks(ks, [str(k) for k in ks])  # the k computed, in plain numbers (no 2x10^0 minor labels)
    axes[0].xaxis.set_minor_locator(NullLocator())
    axes[0].set_xlabel("materials recognised at once, k (random database subsets)")
    axes[0].set_ylabel("accuracy")
    axes[0].set_ylim(0, 1.02)
    axes[0].grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[0].set_title("σ 0.05 °C, dT 10 °C, contact 2 s", fontsize=9)
    for ax, c in zip(axes[1:], (2.0, 4.0)):
        cm = np.asarray(p12_res[c]["confusion"], dtype=np.float64)
        frac = cm / np.maximum(cm.sum(axis=1, keepdims=True), 1)
        im = ax.imshow(frac, vmin=0, vmax=1, cmap="Blues")
        for i in range(frac.shape[0]):  # each cell's fraction, where it is not zero
            for j in range(frac.shape[1]):
                if frac[i, j] >= 0.005:
                    ax.text(j, i, f"{frac[i, j]:.2f}"[1:] if frac[i, j] < 1 else "1", ha="center", va="center",
                            fontsize=6, color="white" if frac[i, j] > 0.6 else "black")
        ax.grid(False)
        fig.colorbar(im, ax=ax, shrink=0.8, label="fraction of its touches")
        ax.set_xticks(range(len(names)), names, rotation=60, ha="right", fontsize=7)
        ax.set_yticks(range(len(names)), names, fontsize=7)
        ax.set_xlabel("predicted")
        ax.set_ylabel("true")
        ax.set_title(f"paper's 12 materials, contact {c:g} s: accuracy {p12_res[c]['accuracy']:.2f}", fontsize=9)
    fig_path = ctx.save_figure(fig, "multiclass")
    csvs = [ctx.save_csv(f"multiclass_confusion_paper12_{int(c)}s", ["true \\ predicted"] + names,
                         [[n] + list(row) for n, row in zip(names, p12_res[c]["confusion"])]) for c in (2.0, 4.0)]
    rows = [[c["k"], c["subsets"], f"{c['svm_accuracy']:.3f}" + (f" ± {c['svm_accuracy_sd']:.3f}" if c["subsets"] > 1 else ""),
             fmt(c["bayes_accuracy"], 3), fmt(c["chance"], 2)] for c in curve]
    worst = {}
    for c in (2.0, 4.0):
        cm = np.asarray(p12_res[c]["confusion"], dtype=np.float64)
        off = cm + cm.T
        np.fill_diagonal(off, 0)
        i, j = np.unravel_index(np.argmax(off), off.shape)
        worst[c] = (names[i], names[j], int(off[i, j]))
    lines = [
        f"Each material is one class, its touches with e uniform over the material's whole range; "
        f"{trials if not quick else trials} touches per class (100 for the 12 materials), σ {NOISE_C:g} °C, "
        f"sensor {DELTA_T_C:g} °C above the object, the paper's sensor; the paper's features and linear SVM, "
        f"multi-class one-vs-one, stratified 3-fold cross-validated accuracy. The ideal observer's accuracy is "
        f"exact (closed form on the one-number sufficient statistic).",
        "",
        f"![multi-class]({fig_path})",
        "",
        md_table(["k", "random subsets", "SVM accuracy", "ideal (Bayes) accuracy", "chance"], rows),
        "",
        md_table(["paper's 12 materials", "SVM accuracy", "ideal accuracy", "most confused pair (touches)"],
                 [[f"contact {c:g} s", fmt(p12_res[c]["accuracy"], 3), fmt(p12_res[c]["bayes_accuracy"], 3),
                   f"{worst[c][0]} / {worst[c][1]} ({worst[c][2]})"] for c in (2.0, 4.0)], align="lrrl"),
        "",
        "Confusion matrices: " + ", ".join(f"[{c}]({c})" for c in csvs) + ". Accuracy falls quickly with k: "
        "binary F1 >= 0.9 for most pairs does not make a k-way recogniser, because the many materials "
        "with overlapping or nearby effusivity ranges (polymers, woods, metals) are all present at once. The "
        "three real classes at once are in the real-robot and sim-to-real sections.",
    ]
    numbers = {"noise_c": NOISE_C, "delta_t_c": DELTA_T_C, "trials_per_class": trials, "curve": curve,
               "paper12": {"names": names, **{f"contact_{c:g}s": p12_res[c] for c in (2.0, 4.0)}}, "csv": csvs}
    return SectionResult("multiclass", title, "\n".join(lines), numbers, (fig_path,),
                         wall_s=time.perf_counter() - t0)
