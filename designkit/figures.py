"""Figures (matplotlib, from the ``figures`` extra). Imported only when a figure is asked for."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._validation import InputError

__all__ = ["plot_curves", "pyplot"]


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg backend, or a clear error."""
    try:
        import matplotlib
    except ImportError:
        raise InputError("figures need matplotlib: pip install 'designkit[figures]'") from None
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def plot_curves(path: Path, time_s, temperature_c, *, title: str = "") -> Path:
    """Sensor temperature against time, one line per trial, saved as PNG."""
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
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
