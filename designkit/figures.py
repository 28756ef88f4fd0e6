"""Figures (matplotlib, from the ``figures`` extra): the one style of every designkit figure, and its saving.

Imported only when a figure is asked for. :func:`pyplot` applies :data:`STYLE`; :func:`save_figure`
writes PNG, SVG and PDF beside each other; :func:`log_ticks` labels a log axis at the values plotted;
numbers on a figure are rounded as everywhere else (:func:`designkit._numbers.sig`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._validation import InputError

__all__ = ["FIGURE_FORMATS", "STYLE", "log_ticks", "plot_curves", "plot_matrix", "pyplot", "save_figure"]

#: Formats a figure is saved in (every one, beside each other): vector (svg, pdf) and raster (png).
FIGURE_FORMATS = ("png", "svg", "pdf")

#: The style of every figure (matplotlib rcParams): readable labels, a light grid, lines that stay visible
#: where curves meet (dashed lines drawn over solid ones are not hidden).
STYLE = {
    "font.size": 9, "axes.titlesize": 9, "axes.labelsize": 9, "xtick.labelsize": 8, "ytick.labelsize": 8,
    "legend.fontsize": 8, "legend.framealpha": 0.85, "axes.grid": True, "grid.alpha": 0.3,
    "lines.linewidth": 1.6, "savefig.bbox": "tight", "svg.hashsalt": "designkit",
}


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg backend, or a clear error."""
    try:
        import matplotlib
    except ImportError:
        raise InputError("figures need matplotlib: pip install 'designkit[figures]'") from None
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    plt.rcParams.update(STYLE)
    return plt


def log_ticks(axis, values) -> None:
    """Label a log-scaled ``axis`` (``ax.xaxis``) at ``values`` (the points plotted), rounded by the one rule.

    Matplotlib labels only the decades of a log axis: a range inside one decade showed a single tick.
    """
    from matplotlib.ticker import FixedLocator, NullFormatter, NullLocator

    from ._numbers import sig

    ticks = sorted({float(v) for v in np.asarray(values, dtype=np.float64).ravel() if np.isfinite(v) and v > 0})
    if len(ticks) > 8:  # at most 8 labels: every k-th value, the ends kept
        k = int(np.ceil(len(ticks) / 8))
        ticks = sorted(set(ticks[::k]) | {ticks[-1]})
    axis.set_major_locator(FixedLocator(ticks))
    axis.set_major_formatter(lambda x, _pos: sig(x))
    axis.set_minor_locator(NullLocator())
    axis.set_minor_formatter(NullFormatter())


def plot_curves(path: Path, time_s, temperature_c, *, title: str = "") -> Path:
    """Sensor temperature against time, one line per trial, saved by the suffix of ``path`` (png, svg or pdf)."""
    plt = pyplot()
    temps = np.atleast_2d(temperature_c)
    fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
    alpha = 1.0 if temps.shape[0] == 1 else max(0.15, 1.0 / np.sqrt(temps.shape[0]))
    for row in temps:
        ax.plot(time_s, row, lw=1.0, alpha=alpha, color="C0")
    ax.set_xlabel("time after contact [s]")
    ax.set_ylabel("sensor temperature [°C]")
    if title:
        ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    return save_figure(fig, path, dpi=120)


def save_figure(fig, path, *, dpi: int = 200, formats=FIGURE_FORMATS) -> Path:
    """Save ``fig`` as ``path`` and in the other ``formats`` beside it (same name, their suffixes), then close it.

    ``path``'s suffix must be one of :data:`FIGURE_FORMATS`; svg and pdf are vector, png has ``dpi``.
    Returns ``path``.
    """
    path = Path(path)
    fmt = path.suffix.lower().lstrip(".")
    if fmt not in FIGURE_FORMATS:
        raise InputError(f"figure file {path.name!r}: give a .png, .svg or .pdf name")
    path.parent.mkdir(parents=True, exist_ok=True)
    for f in (fmt, *(x for x in formats if x != fmt)):
        fig.savefig(path.with_suffix(f".{f}"), dpi=dpi if f == "png" else None, format=f, bbox_inches="tight",
                    metadata=None if f == "png" else {"Date": None})  # no date: the same figure, the same file
    pyplot().close(fig)
    return path


def plot_matrix(result, path) -> Path:
    """Heatmap of a material matrix and the multi-class accuracy against contact time.

    ``result`` is a :class:`designkit.query.matrix.MaterialMatrix`; saved by
    the suffix of ``path`` (png, svg or pdf).
    """
    plt = pyplot()
    from matplotlib.colors import LogNorm

    from ._numbers import sig

    names = list(result.names)
    n = len(names)
    vals = np.asarray(result.values(), dtype=np.float64)
    status = result.status()
    bounds = {}
    for c in result.cells:
        bounds[c.i, c.j] = bounds[c.j, c.i] = {"at-most": "≤", "at-least": "≥"}.get(c.bound, "")
    curve = result.multiclass
    side = max(4.8, 0.42 * n + 2.2)
    width = side + (4.8 if curve is not None else 0.0)
    fig = plt.figure(figsize=(width, side), constrained_layout=True)
    grid = fig.add_gridspec(1, 2 if curve is not None else 1,
                            width_ratios=[side, 4.8] if curve is not None else [1])
    ax = fig.add_subplot(grid[0, 0])
    cmap = plt.get_cmap("viridis_r" if result.question in ("min-contact", "min-delta-t") else "viridis")
    cmap = cmap.with_extremes(bad="white")
    finite = vals[np.isfinite(vals)]
    norm = None
    if result.question != "distinguishable" and finite.size and finite.min() > 0 and finite.max() / finite.min() > 20:
        norm = LogNorm(vmin=finite.min(), vmax=finite.max())
    im = ax.imshow(np.ma.masked_invalid(vals), cmap=cmap, norm=norm,
                   vmin=None if norm else (0 if result.question == "distinguishable" else None),
                   vmax=None if norm else (1 if result.question == "distinguishable" else None))
    for i in range(n):
        for j in range(n):
            if i == j:
                continue
            st = status[i, j]
            if st == "overlap":
                ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, facecolor="0.85", edgecolor="white",
                                           hatch="///", lw=0.0))
                continue
            v = vals[i, j]
            txt = "n/a" if not np.isfinite(v) else (("yes" if v else "no") if result.question == "distinguishable"
                                                     else bounds.get((i, j), "") + sig(v))
            rgba = im.cmap(im.norm(v)) if np.isfinite(v) else (1, 1, 1, 1)
            dark = 0.299 * rgba[0] + 0.587 * rgba[1] + 0.114 * rgba[2] < 0.5
            ax.text(j, i, txt, ha="center", va="center", fontsize=7 if n > 8 else 9,
                    color="white" if dark else "black")
    lim = result.limiting
    if len(lim.names) == 2:
        i, j = names.index(lim.names[0]), names.index(lim.names[1])
        for a, b in ((i, j), (j, i)):
            ax.add_patch(plt.Rectangle((b - 0.5, a - 0.5), 1, 1, fill=False, edgecolor="red", lw=2.0))
    ax.grid(False)
    ax.set_xticks(range(n), names, rotation=45, ha="right", rotation_mode="anchor", fontsize=8)
    ax.set_yticks(range(n), names, fontsize=8)
    ax.set_xlim(-0.5, n - 0.5)
    ax.set_ylim(n - 0.5, -0.5)
    unit = f" [{'°C' if result.unit == 'degC' else result.unit}]" if result.unit else ""
    word = {"contact_s": "contact", "noise_c": "noise", "delta_t_c": "dT"}.get(result.quantity, result.quantity)
    cb = fig.colorbar(im, ax=ax, shrink=0.8)
    cb.set_label(f"{word}{unit}" if result.question != "distinguishable" else "distinguishable (1 = yes)")
    ax.set_title(f"{result.question}{unit}: hatched = overlapping ranges, red = limiting pair", fontsize=9)
    if curve is not None:
        ax2 = fig.add_subplot(grid[0, 1])
        if curve.ideal_accuracy is not None:
            ax2.plot(curve.contact_s, curve.ideal_accuracy, "o-", label="ideal observer (Bayes)")
        if curve.svm_accuracy is not None:
            ax2.plot(curve.contact_s, curve.svm_accuracy, "s--", label="SVM")
        ax2.axhline(curve.chance, ls=":", color="grey", label=f"chance (1/{n})")
        ax2.set_xlabel("contact time [s]")
        ax2.set_ylabel(f"accuracy, all {n} at once")
        ax2.set_ylim(0, 1.02)
        ax2.grid(alpha=0.3)
        ax2.legend(fontsize=8, loc="center right")
        sc = curve.scene
        ax2.set_title(f"σ {sc['noise_c']:g} °C, ΔT {sc['delta_t_c']:g} °C"
                      + ("" if curve.svm_accuracy is not None else " (SVM not computed)"), fontsize=9)
    return save_figure(fig, path)
