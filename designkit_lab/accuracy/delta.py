"""Section ``delta``: the delta(e) search and the effusivity grid against their references.

The staircase search against the full F1 matrix (SVM, a coarse grid where
the full matrix is affordable); coarse effusivity grids (125, 250, 500
intervals) against a fine one (ideal fidelity: an SVM sweep at 2000+
intervals is unaffordable, so this isolates what the grid alone costs).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Callable, Sequence

import numpy as np

from .instruments import timed
from .results import PAPER_RATIO, Row, p95, worst

__all__ = ["delta_rows", "grid_rows", "staircase_vs_full"]


def _answer_diff(a: np.ndarray, b: np.ndarray, width: float, e_max: float) -> np.ndarray:
    """|a - b| in intervals; an answer on one side only counts as the distance to the grid's end."""
    both_nan = np.isnan(a) & np.isnan(b)
    one_nan = np.isnan(a) ^ np.isnan(b)
    d = np.where(both_nan, 0.0, np.abs(np.nan_to_num(a, nan=0.0) - np.nan_to_num(b, nan=0.0)) / width)
    return np.where(one_nan, np.abs(np.nan_to_num(a, nan=e_max) - np.nan_to_num(b, nan=e_max)) / width, d)


def _differing(cfg, stair, full) -> list[dict[str, Any]]:
    """The references whose first distinguishable partner differs between the two runs."""
    return [{"i": int(i), "e_centre": float(cfg.centres[i]), "J_staircase": int(stair.J[i]),
             "J_full": int(full.J[i]), "J_lo": int(stair.J_lo[i]), "J_hi": int(stair.J_hi[i])}
            for i in np.flatnonzero(stair.J != full.J)]


def staircase_vs_full(intervals: int, *, contact_s: float = 1.0, noise_ratio: float = PAPER_RATIO,
                      trials: int = 100, seed: int = 0, max_repeats: int = 4,
                      e_max: float = 40000.0) -> dict[str, Any]:
    """delta(e) for every reference at one scene: staircase search against the full matrix.

    Both runs use the same per-pair seeds, so every pair the staircase scores
    has exactly the F1 the full matrix gives it; the answers can differ only
    where F1 is not monotone in the distance (Monte Carlo noise).

    Returns
    -------
    dict
        ``intervals``, ``fits_staircase``, ``fits_full``, ``wall_staircase_s``,
        ``wall_full_s``, ``max_diff_intervals`` (largest difference of the
        first distinguishable partner, in intervals, over all references and
        both directions), ``n_differ`` (references whose answer differs),
        ``J_staircase``, ``J_full``.
    """
    from designkit.sweep import SweepConfig, delta_from_staircase, run_chunk

    base = SweepConfig(name="bench", fidelity="svm", intervals=int(intervals), e_max=e_max, trials=trials,
                       seed=seed, max_repeats=max_repeats, noise_ratio=(noise_ratio,), contact_s=(contact_s,))
    stair, t_stair = timed(lambda: run_chunk(base, (0,), 0, 0))
    full_cfg = replace(base, full_matrix=True)
    full, t_full = timed(lambda: run_chunk(full_cfg, (0,), 0, 0))
    up_s, down_s = delta_from_staircase(stair.J, base.width)
    up_f, down_f = delta_from_staircase(full.J, base.width)
    d_all = np.concatenate([_answer_diff(up_s, up_f, base.width, e_max),
                            _answer_diff(down_s, down_f, base.width, e_max)])
    # the staircase's Monte Carlo interval [J_lo, J_hi] (z standard errors): does it hold the matrix's answer?
    covered = (full.J >= stair.J_lo) & (full.J <= stair.J_hi)
    return {"intervals": int(intervals), "contact_s": contact_s, "noise_ratio": noise_ratio, "trials": trials,
            "fits_staircase": int(stair.fits), "fits_full": int(full.fits), "pairs_full": intervals * (intervals - 1) // 2,
            "wall_staircase_s": t_stair, "wall_full_s": t_full,
            "max_diff_intervals": float(d_all.max()), "n_differ": int(np.count_nonzero(d_all > 0)),
            "full_in_staircase_interval": int(np.count_nonzero(covered)),
            "differing_references": _differing(base, stair, full),
            "J_staircase": stair.J.tolist(), "J_full": full.J.tolist(),
            "J_lo": stair.J_lo.tolist(), "J_hi": stair.J_hi.tolist()}


def _ideal_delta_curves(n: int, ratio: float, contact: float):
    """Grid centres, delta up and down, and wall time of an ideal sweep of ``n`` intervals at one scene."""
    from designkit.sweep import SweepConfig, delta_from_staircase, run_chunk

    cfg = SweepConfig(name="bench", fidelity="ideal", intervals=n, noise_ratio=(ratio,), contact_s=(contact,))
    res, sec = timed(lambda: run_chunk(cfg, (0,), 0, 0))
    up, down = delta_from_staircase(res.J, cfg.width)
    return cfg.centres, up, down, sec


def _grid_errors(xc, coarse_vals, xf, fine_vals, n):
    """Absolute errors of a coarse delta curve against the fine one, and relative ones where delta_fine >= 5 widths."""
    ok_f = np.isfinite(fine_vals)
    ref = np.interp(xc, xf[ok_f], fine_vals[ok_f], left=np.nan, right=np.nan)
    ok = np.isfinite(coarse_vals) & np.isfinite(ref) & (xc >= xf[ok_f][0]) & (xc <= xf[ok_f][-1])
    big = ok & (ref >= 5 * 40000.0 / n)
    return np.abs(coarse_vals[ok] - ref[ok]), np.abs(coarse_vals[big] - ref[big]) / ref[big]


def grid_rows(quick: bool = True, coarse: Sequence[int] = (125, 250, 500),
              progress: Callable[[str], None] | None = None) -> list[Row]:
    """Coarse effusivity grids against a fine one, at ideal fidelity.

    delta(e) of each grid (towards higher and lower e) is interpolated
    linearly to the same points (the coarse grid's centres) and compared
    with the fine grid's; the error is relative. Part of it is the class
    width itself (a class of a coarse grid is wider, hence harder to
    separate), which is what a coarse table gets wrong about a point pair.
    An SVM sweep of 2000+ intervals is unaffordable; the ideal observer
    shows what the grid alone costs.

    Returns
    -------
    list of Row
        One per coarse grid.
    """
    fine = 2000 if quick else 4000
    scenes = [(PAPER_RATIO, 1.0), (PAPER_RATIO, 4.0)] if quick else \
        [(PAPER_RATIO, 1.0), (PAPER_RATIO, 2.0), (PAPER_RATIO, 4.0), (0.001, 2.0), (0.02, 2.0)]
    errs: dict[int, list[float]] = {n: [] for n in coarse}
    rel: dict[int, list[float]] = {n: [] for n in coarse}
    times: dict[int, float] = {n: 0.0 for n in coarse}
    fine_time = 0.0
    for ratio, contact in scenes:
        if progress:
            progress(f"delta(e): fine grid {fine} at sigma/dT {ratio:g}, {contact:g} s")
        xf, upf, downf, sec = _ideal_delta_curves(fine, ratio, contact)
        fine_time += sec
        for n in coarse:
            xc, upc, downc, sec = _ideal_delta_curves(n, ratio, contact)
            times[n] += sec
            for c_vals, f_vals in ((upc, upf), (downc, downf)):
                a, r = _grid_errors(xc, c_vals, xf, f_vals, n)
                errs[n].extend(a)
                rel[n].extend(r)
    k = len(scenes)
    rows = []
    for n in coarse:
        e = np.asarray(errs[n])
        rows.append(Row("delta(e) grid", "ideal sweep", f"{n} intervals (width {40000 / n:g})",
                        "|delta - delta_fine| [J s^-1/2 K^-1 m^-2]", p95(e), worst(e), times[n] / k,
                        f"ideal sweep, {fine} intervals (width {40000 / fine:g})", fine_time / k, e.size,
                        f"{k} scenes, both directions; where delta_fine >= 5 widths the relative error is "
                        f"{100 * p95(rel[n]):.0f} % (p95), {100 * worst(rel[n]):.0f} % (worst); a grid cannot "
                        f"resolve a delta below one width, and its wider classes are harder to separate"))
    return rows


def delta_rows(quick: bool = True, seed: int = 0,
               progress: Callable[[str], None] | None = None) -> list[Row]:
    """Staircase search against the full matrix (SVM), and grid coarseness (ideal).

    Returns
    -------
    list of Row
        The staircase rows (one per grid size), then :func:`grid_rows`.
    """
    sizes = (16,) if quick else (20, 40)
    rows = []
    for n in sizes:
        if progress:
            progress(f"delta(e): staircase vs full matrix, {n} intervals")
        r = staircase_vs_full(n, seed=seed)
        rows.append(Row("delta(e)", "staircase search (SVM)", f"{n} intervals, contact 1 s, sigma/dT 0.005",
                        "max |delta - delta_full| [intervals]", r["max_diff_intervals"], r["max_diff_intervals"],
                        r["wall_staircase_s"], f"full matrix ({r['pairs_full']} pairs)", r["wall_full_s"], 2 * n,
                        f"{r['fits_staircase']} vs {r['fits_full']} SVM fits "
                        f"({r['fits_full'] / max(r['fits_staircase'], 1):.1f}x fewer); {r['n_differ']} of {2 * n} "
                        f"answers differ; the matrix's answer lies in the staircase's Monte Carlo interval for "
                        f"{r['full_in_staircase_interval']} of {n} references; benchmarks/bench_delta_e.py scales "
                        f"this up"))
    rows.extend(grid_rows(quick, progress=progress))
    return rows
