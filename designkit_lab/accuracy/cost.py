"""Section ``cost``: what the sweep engine costs as the work grows.

Wall time, SVM fits and peak resident memory of the engine as the number of
intervals, trials and the contact time grow, with exponents fitted by log-log
least squares. Peak memory is each point's own (Linux's resettable
high-water mark), above the resident set at its start.

The exponents are measured and reported, never asserted: timings depend on
the machine and its load (``benchmarks/bench_cost.py`` prints them).
"""

from __future__ import annotations

import math
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from .instruments import fit_exponent, measure, resident_mb
from .results import PAPER_RATIO, CostCurve

__all__ = ["cost_curve", "cost_curve_specs", "cost_curves"]


def _config(variable: str, v: float, base: Mapping[str, Any]):
    """The sweep configuration of one point of a cost curve."""
    from designkit.sweep import SweepConfig

    kw = dict(base)
    if variable == "contact_s":
        kw["contact_s"] = (float(v),)
    elif variable == "contacts":
        kw["contact_s"] = tuple(float(x) for x in np.linspace(0.5, 10.0, int(v)))
    else:
        kw[variable] = int(v)
    return SweepConfig(**kw)


def _sweep_one_scene(cfg):
    """What a sweep does per scene point: run it, assemble the table arrays; the chunks."""
    from designkit.sweep import assemble, run_scene

    chunks = run_scene(cfg)
    assemble(cfg, chunks)
    return chunks


def cost_curve(name: str, variable: str, values: Sequence[float], base: Mapping[str, Any],
               setting: str = "", relative_to_mb: float | None = None) -> CostCurve:
    """Run the engine on one scene point for each value of ``variable`` and fit the exponents.

    Parameters
    ----------
    name : str
        The curve's label.
    variable : str
        A :class:`~designkit.sweep.SweepConfig` field (``intervals``,
        ``trials``), ``contact_s`` (one contact time of that length) or
        ``contacts`` (that many contact times from 0.5 s to 10 s, swept with
        warm starts).
    values : sequence of float
        The sizes, in increasing order.
    base : mapping
        The other :class:`~designkit.sweep.SweepConfig` fields.
    setting : str
        What is held fixed, for the report.
    relative_to_mb : float, optional
        Memory baseline [MB] (the process after its imports, see
        :func:`cost_curves`); else each point's peak is above the resident
        set when the point started.

    Returns
    -------
    CostCurve
        Each point is ``run_scene`` + ``assemble`` (what a sweep does per scene).
    """
    xs, walls, fits, peaks, extra = [], [], [], [], []
    for v in values:
        chunks, wall, peak, above = measure(lambda cfg=_config(variable, v, base): _sweep_one_scene(cfg))
        xs.append(float(v))
        walls.append(wall)
        fits.append(int(sum(c.fits for c in chunks)))
        peaks.append(math.nan if peak is None else peak)
        if relative_to_mb is not None and peak is not None:
            above = max(peak - relative_to_mb, 0.0)
        extra.append(math.nan if above is None else above)
    return _fit_curve(name, variable, base, xs, walls, fits, peaks, np.asarray(extra), setting, relative_to_mb)


def _fit_curve(name, variable, base, xs, walls, fits, peaks, mem, setting, relative_to_mb) -> CostCurve:
    svm = base.get("fidelity") == "svm"
    usable = np.isfinite(mem) & (mem > 1.0)  # below 1 MB the high-water mark is noise
    per_fit = [w / f for w, f in zip(walls, fits)] if svm and all(fits) else None
    note = "" if per_fit is None else (f"time per SVM fit {', '.join(f'{x:.3g}' for x in per_fit)} s "
                                       f"(exponent {fit_exponent(xs, per_fit):.2f})")
    if relative_to_mb is not None:
        base_mb = float(relative_to_mb)
    else:
        base_mb = float(np.nanmax(np.asarray(peaks) - mem)) if np.isfinite(mem).any() else math.nan
    return CostCurve(
        name=name, variable=variable, fidelity=str(base.get("fidelity")), x=tuple(xs), wall_s=tuple(walls),
        fits=tuple(fits), peak_mb=tuple(float(m) for m in mem), base_mb=base_mb,
        time_exponent=fit_exponent(xs, walls),
        fits_exponent=fit_exponent(xs, fits) if svm else None,
        memory_exponent=fit_exponent(np.asarray(xs)[usable], mem[usable]) if np.count_nonzero(usable) >= 2 else None,
        setting=setting, note=note)


def _curve_in_fresh_process(name, variable, values, base, setting) -> CostCurve:
    """Body of :func:`cost_curves` in a child: warm up, take the baseline, run the curve."""
    import gc

    from designkit.sweep import SweepConfig

    _sweep_one_scene(SweepConfig(**{**base, "intervals": 4, "trials": 6, "contact_s": (0.5,)}))
    # imports, BLAS and libsvm are loaded before the baseline
    gc.collect()
    return cost_curve(name, variable, values, base, setting, relative_to_mb=resident_mb("VmRSS"))


def cost_curve_specs(quick: bool = True, seed: int = 0) -> list[tuple[str, str, tuple, dict[str, Any], str]]:
    """The curves :func:`cost_curves` measures: (name, variable, values, base config, setting).

    Examples
    --------
    >>> [s[0] for s in cost_curve_specs(quick=True)][:2]
    ['ideal: intervals', 'ideal: contact times per table']
    """
    ideal = dict(name="bench", fidelity="ideal", noise_ratio=(PAPER_RATIO,), contact_s=(2.0,), seed=seed)
    svm = dict(name="bench", fidelity="svm", noise_ratio=(PAPER_RATIO,), contact_s=(1.0,), seed=seed,
               intervals=12, trials=50, max_repeats=2)
    if quick:
        return [
            ("ideal: intervals", "intervals", (250, 500, 1000, 2000), ideal, "contact 2 s"),
            ("ideal: contact times per table", "contacts", (2, 4, 8), {**ideal, "intervals": 125},
             "125 intervals, contacts 0.5..10 s"),
            ("SVM: intervals", "intervals", (8, 16, 32), svm, "50 trials, contact 1 s"),
            ("SVM: trials per interval", "trials", (25, 50, 100), svm, "12 intervals, contact 1 s"),
            ("SVM: contact time", "contact_s", (0.5, 1.0, 2.0, 4.0), svm, "12 intervals, 50 trials"),
        ]
    svm16 = {**svm, "intervals": 16}
    return [
        ("ideal: intervals", "intervals", (125, 250, 500, 1000, 2000, 4000), ideal, "contact 2 s"),
        ("ideal: contact times per table", "contacts", (2, 4, 8, 16), {**ideal, "intervals": 250},
         "250 intervals, contacts 0.5..10 s"),
        ("SVM: intervals", "intervals", (10, 20, 40, 80), svm16, "50 trials, contact 1 s"),
        ("SVM: trials per interval", "trials", (25, 50, 100, 200), svm16, "16 intervals, contact 1 s"),
        ("SVM: contact time", "contact_s", (0.5, 1.0, 2.0, 4.0, 8.0), svm16, "16 intervals, 50 trials"),
    ]


def _in_fresh_process(spec) -> CostCurve:
    """One curve in a fresh process: its resident set holds nothing but the curve's own work."""
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=1, mp_context=mp.get_context("spawn")) as ex:
        return ex.submit(_curve_in_fresh_process, *spec).result()


def cost_curves(quick: bool = True, seed: int = 0, *, isolated: bool = True, only: Sequence[str] | None = None,
                progress: Callable[[str], None] | None = None) -> list[CostCurve]:
    """Wall time, SVM fits and peak memory of the engine against the size of the work.

    Ideal fidelity for the big ranges (intervals up to 2000-4000, up to 16
    contact times), SVM on small ones (intervals, trials per interval,
    contact time). One scene point each (sigma/dT 0.005); a whole table
    multiplies by the number of scene points. With ``isolated`` each curve
    runs in a fresh process, and its memory is the peak resident set above
    that process's resident set after imports (the points run in increasing
    order, so each peak is that point's). ``only`` names the curves to
    measure (default: all).

    Returns
    -------
    list of CostCurve
        In the order of :func:`cost_curve_specs`.
    """
    out = []
    for spec in cost_curve_specs(quick, seed):
        if only is not None and spec[0] not in only:
            continue
        if progress:
            progress(f"cost curve: {spec[0]}")
        out.append(_in_fresh_process(spec) if isolated else cost_curve(*spec))
    return out
