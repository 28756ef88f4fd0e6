"""F1 matrices, Table I and the material node graphs (paper sections IV-V, Figs. 3 and 6).

Which grid each number comes from
---------------------------------
* **% indistinguishable interval pairs** come from the 500-interval staircase
  tables (``svm-paper``, and ``ideal-paper`` for the bound): distinguishability
  is monotone in the pair's distance, so the staircase ``J(i)`` (first
  distinguishable partner above ``i``) counts the distinguishable pairs of the
  paper's own grid exactly: ``sum_i (n - J(i))`` of ``n (n - 1) / 2``.
* **Mean F1** needs every pair's F1 value, not only the crossing, so it comes
  from full F1 matrices on a coarser grid (``f1-matrix-2s``: 100 intervals of
  400 on (0, 40000]); a full 500-interval matrix is 124,750 SVM fits (about an
  hour per matrix).
* **Material pairs** use the paper's rule: a pair's F1 is the mean of the F1
  matrix over all interval pairs covering the two effusivity ranges. A pair
  whose ranges both lie in (0, 4000] is read from ``f1-matrix-fine-low`` (the
  paper's interval width, 80), others from ``f1-matrix-2s``. Interval pairs
  that cover the same interval (overlapping ranges) compare a class with
  itself; their F1 is the SVM's chance F1, measured at run time
  (:func:`chance_f1`).
* **The paper's resolution** (issue 35): where the 500-interval full matrices
  ``f1-matrix-500-r0p005`` etc. (one table per sigma/dT, all 124,750 pairs of
  the paper's grid) exist, Table I also reports % indistinguishable and mean F1
  over every pair, and the material pairs by the same rule on width-80
  intervals everywhere, beside the 100-interval figures (:func:`paper_grid_row`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ._report import Comparison, Context, SectionResult, fmt, md_table
from .paper import TABLE1, TABLE1_F1_TOLERANCE, TABLE1_PERCENT_TOLERANCE

__all__ = [
    "MaterialF1",
    "MatrixStats",
    "axis_index",
    "chance_f1",
    "comparisons",
    "covering_intervals",
    "f1_matrix",
    "material_f1",
    "matrix_delta_up",
    "matrix_stats",
    "paper_grid_row",
    "paper_grid_table",
    "section_f1_matrices",
    "section_node_graphs",
    "graph_layout",
    "short_label",
    "staircase_percent",
]

HEATMAP_TABLE = "f1-matrix-paper"
COARSE_TABLE = "f1-matrix-2s"
FINE_TABLE = "f1-matrix-fine-low"
STAIRCASE_TABLE = "svm-paper"
IDEAL_TABLE = "ideal-paper"
PAPER_GRID_PREFIX = "f1-matrix-500-r"  # + sigma/dT: the 500-interval full matrix of one Table I setting
TABLE1_CONTACT_S = 2.0
GRAPH_SETTINGS = ((30.0, 0.05), (35.0, 0.05))  # (Ts0 [degC], sigma [degC]) of Fig. 6, Ta = 25
AMBIENT_C = 25.0
FAMILY_COLOURS = {"metals": "#d62728", "ceramics": "#1f77b4", "polymers": "#2ca02c", "composites": "#ff7f0e"}


# ============================================================ table access
def axis_index(values, x: float) -> int | None:
    """Index of ``x`` on a table axis (relative tolerance 1e-6), None when it is not a grid point."""
    v = np.asarray(values, dtype=np.float64)
    hit = np.flatnonzero(np.isclose(v, x, rtol=1e-6, atol=0.0))
    return int(hit[0]) if hit.size else None


def _scene_index(table, noise_ratio: float, contact_s: float) -> tuple[int, int] | None:
    ax = table.axes
    if "noise_ratio" not in ax:
        return None
    ri = axis_index(ax["noise_ratio"], noise_ratio)
    ci = axis_index(ax["contact_s"], contact_s)
    if ri is None or ci is None:
        return None
    return ri, ci


def f1_matrix(table, noise_ratio: float, contact_s: float) -> np.ndarray | None:
    """The full F1 matrix [n, n] (float64, NaN diagonal) of a full-matrix table, or None."""
    if table is None or "f1_matrix" not in table.arrays:
        return None
    idx = _scene_index(table, noise_ratio, contact_s)
    if idx is None:
        return None
    return np.asarray(table.arrays["f1_matrix"][idx], dtype=np.float64)


def _grid(table) -> tuple[float, float, int]:
    eff = table.header["effusivity"]
    return float(eff["min"]), float(eff["width"]), int(eff["intervals"])


def staircase_percent(table, noise_ratio: float, contact_s: float, kind: str = "") -> float | None:
    """% indistinguishable interval pairs from a staircase table's ``delta_up{kind}``.

    Under monotonicity the first distinguishable partner ``J(i) = i + delta_up(i) / width``
    (``n`` where delta_up is NaN) gives ``sum_i (n - J(i))`` distinguishable pairs of
    ``n (n - 1) / 2``. ``kind``: ``""`` (the estimate), ``"_lo"``/``"_hi"`` (its Monte
    Carlo interval, SVM tables), ``"_ideal"`` (the ideal observer's staircase).
    """
    if table is None:
        return None
    name = f"delta_up{kind}"
    if name not in table.arrays:
        return None
    idx = _scene_index(table, noise_ratio, contact_s)
    if idx is None:
        return None
    _, width, n = _grid(table)
    d = np.asarray(table.arrays[name][idx], dtype=np.float64)
    steps = np.where(np.isfinite(d), np.rint(d / width), np.nan)
    J = np.where(np.isfinite(steps), np.arange(n) + steps, n)
    distinguishable = float(np.sum(n - J))
    return 100.0 * (1.0 - distinguishable / (n * (n - 1) / 2))


@dataclass(frozen=True)
class MatrixStats:
    """Summary of an F1 matrix over its pairs ``i < j``.

    Attributes
    ----------
    mean_f1 : float
        Mean F1 over the pairs.
    percent_indistinguishable : float
        % of pairs with F1 below the threshold (no monotonicity assumed).
    pairs : int
    """

    mean_f1: float
    percent_indistinguishable: float
    pairs: int

    def to_dict(self) -> dict:
        return {"mean_f1": self.mean_f1, "percent_indistinguishable": self.percent_indistinguishable,
                "pairs": self.pairs}


def matrix_stats(matrix: np.ndarray, threshold: float, keep: np.ndarray | None = None) -> MatrixStats:
    """Mean F1 and % indistinguishable over the upper triangle (optionally rows/cols in ``keep``)."""
    m = np.asarray(matrix, dtype=np.float64)
    if keep is not None:
        m = m[np.ix_(keep, keep)]
    iu = np.triu_indices(m.shape[0], 1)
    v = m[iu]
    return MatrixStats(float(np.mean(v)), float(100.0 * np.mean(v < threshold)), int(v.size))


def matrix_delta_up(matrix: np.ndarray, width: float, threshold: float) -> np.ndarray:
    """delta towards higher effusivity read off a full matrix: first ``j > i`` with F1 >= threshold."""
    m = np.asarray(matrix, dtype=np.float64)
    n = m.shape[0]
    ok = np.triu(np.nan_to_num(m, nan=-1.0) >= threshold, 1)
    first = np.where(ok.any(axis=1), ok.argmax(axis=1), -1)
    return np.where(first >= 0, (first - np.arange(n)) * width, np.nan)


def covering_intervals(e_low: float, e_high: float, e_min: float, width: float, n: int) -> np.ndarray:
    """Indices of the grid intervals ``[e_min + k w, e_min + (k + 1) w)`` that meet ``[e_low, e_high]``."""
    k0 = int(math.floor((e_low - e_min) / width))
    k1 = int(math.ceil((e_high - e_min) / width)) - 1
    k0 = min(max(k0, 0), n - 1)
    k1 = min(max(k1, k0), n - 1)
    return np.arange(k0, k1 + 1)


# ============================================================ chance F1 (diagonal)
def chance_f1(ctx: Context) -> dict:
    """The SVM's cross-validated F1 when both classes are the same interval (measured).

    The full-matrix tables leave the diagonal empty; material pairs with
    overlapping ranges need it. Both classes are drawn independently from one
    interval (100 trials each, 3 folds, contact 2 s, sigma/dT 0.005), so any F1
    is chance; the mean over several intervals and seeds fills the diagonal.
    """
    if "chance_f1" in ctx.cache:
        return ctx.cache["chance_f1"]
    from designkit.recognition.svm import cross_validated_f1
    from designkit.scene import Scene
    from designkit.sensor import SENSORS
    from designkit.simulation import simulate_interval

    sensor = SENSORS["paper"]
    scene = Scene(contact_s=TABLE1_CONTACT_S, noise_c=0.005, sensor_temp_c=AMBIENT_C + 1.0, ambient_temp_c=AMBIENT_C)
    starts = [0.0, 400.0, 2000.0, 12000.0, 30000.0, 39600.0]
    reps = 1 if ctx.settings.quick else 3
    vals = []
    for r in range(reps):
        for k, lo in enumerate(starts):
            a = simulate_interval(lo, lo + 400.0, 100, sensor, scene, seed=[ctx.settings.seed, 101, k, r, 0])
            b = simulate_interval(lo, lo + 400.0, 100, sensor, scene, seed=[ctx.settings.seed, 101, k, r, 1])
            vals.append(cross_validated_f1(a.temperature_c, b.temperature_c, sensor.sample_rate_hz, folds=3,
                                           seed=[ctx.settings.seed, 101, k, r, 2]).f1)
    v = np.asarray(vals)
    out = {"mean": float(v.mean()), "sd": float(v.std(ddof=1)) if v.size > 1 else 0.0, "fits": int(v.size)}
    ctx.cache["chance_f1"] = out
    return out


# ============================================================ material pair F1
@dataclass(frozen=True)
class MaterialF1:
    """F1 of every pair of database materials at one scene (paper's mean-over-covering-intervals rule).

    Attributes
    ----------
    names, families : tuple of str
    ranges : ndarray, shape (K, 2)
        Effusivity ranges [J s^-1/2 K^-1 m^-2].
    f1 : ndarray, shape (K, K)
        Pair F1 (symmetric, NaN diagonal).
    fine : ndarray of bool, shape (K, K)
        True where the pair was read from the fine (width 80) table.
    f1_coarse : ndarray, shape (K, K)
        The same rule on the coarse grid only (for the grid note).
    """

    names: tuple[str, ...]
    families: tuple[str, ...]
    ranges: np.ndarray
    f1: np.ndarray
    fine: np.ndarray
    f1_coarse: np.ndarray

    def stats(self, threshold: float, coarse_only: bool = False, keep: np.ndarray | None = None) -> MatrixStats:
        return matrix_stats(self.f1_coarse if coarse_only else self.f1, threshold, keep)


def _pair_means(matrix: np.ndarray, cover: list[np.ndarray], diag: float) -> np.ndarray:
    m = np.array(matrix, dtype=np.float64)
    np.fill_diagonal(m, diag)
    K = len(cover)
    out = np.full((K, K), np.nan)
    for a in range(K):
        for b in range(a + 1, K):
            out[a, b] = out[b, a] = float(np.mean(m[np.ix_(cover[a], cover[b])]))
    return out


def material_f1(ctx: Context, noise_ratio: float) -> MaterialF1 | None:
    """Material-pair F1 matrix at contact 2 s and ``noise_ratio``; None when the coarse table is missing."""
    key = ("material_f1", round(noise_ratio, 12))
    if key in ctx.cache:
        return ctx.cache[key]
    from designkit.materials import list_materials

    coarse_t = ctx.table(COARSE_TABLE)
    coarse = f1_matrix(coarse_t, noise_ratio, TABLE1_CONTACT_S)
    if coarse is None:
        ctx.cache[key] = None
        return None
    fine_t = ctx.table(FINE_TABLE)
    fine = f1_matrix(fine_t, noise_ratio, TABLE1_CONTACT_S)
    mats = list_materials()
    ranges = np.array([m.effusivity_range for m in mats], dtype=np.float64)
    diag = chance_f1(ctx)["mean"]
    c_min, c_w, c_n = _grid(coarse_t)
    c_cover = [covering_intervals(lo, hi, c_min, c_w, c_n) for lo, hi in ranges]
    f1_c = _pair_means(coarse, c_cover, diag)
    f1 = f1_c.copy()
    use_fine = np.zeros_like(f1, dtype=bool)
    if fine is not None:
        f_min, f_w, f_n = _grid(fine_t)
        f_max = f_min + f_w * f_n
        inside = (ranges[:, 0] >= f_min) & (ranges[:, 1] <= f_max)
        f_cover = [covering_intervals(lo, hi, f_min, f_w, f_n) for lo, hi in ranges]
        f1_f = _pair_means(fine, f_cover, diag)
        use_fine = inside[:, None] & inside[None, :]
        np.fill_diagonal(use_fine, False)
        f1 = np.where(use_fine, f1_f, f1_c)
    out = MaterialF1(tuple(m.name for m in mats), tuple(m.family for m in mats), ranges, f1, use_fine, f1_c)
    ctx.cache[key] = out
    return out


# ============================================================ the paper's resolution
def paper_grid_table(noise_ratio: float) -> str:
    """Name of the 500-interval full-matrix table of one sigma/dT (``f1-matrix-500-r0p005``: ``p`` for the
    decimal point, since a table name with a dot would read as a file suffix).

    >>> paper_grid_table(0.05 / 10), paper_grid_table(0.1 / 5)
    ('f1-matrix-500-r0p005', 'f1-matrix-500-r0p02')
    """
    return f"{PAPER_GRID_PREFIX}{round(noise_ratio, 12):g}".replace(".", "p")


def build_time(table) -> dict:
    """What building ``table`` cost, from its header's ``stats``: the workers' busy wall seconds summed over
    its chunks (``compute_s``: CPU seconds on idle cores, more where the cores are shared), SVM fits, and
    the wall time of the run that assembled it (``elapsed_s``; the whole build only when that run computed
    every chunk, ``whole_build``)."""
    st = table.header.get("stats") or {}
    run = st.get("run") or {}
    done, total = run.get("chunks_computed"), run.get("chunks_total")
    return {"compute_s": st.get("compute_s_total"), "fits": st.get("svm_fits_total"),
            "elapsed_s": run.get("elapsed_s"), "jobs": run.get("jobs"), "chunks_computed": done,
            "whole_build": done is not None and done == total, "created": table.header.get("created")}


def paper_grid_row(ctx: Context, noise_ratio: float, material_cover: bool = True) -> dict | None:
    """Table I's numbers at the paper's own resolution, from ``f1-matrix-500-r<sigma/dT>``; None when
    that table is not available.

    ``intervals``: mean F1 and % indistinguishable over every interval pair ``i < j`` of its grid (124,750
    pairs at 500 intervals; no monotonicity assumed). ``materials`` (with ``material_cover``): the paper's
    rule (a pair's F1 is the mean over the interval pairs covering the two ranges) on this one grid,
    same-interval cells at the SVM's chance F1 (:func:`chance_f1`).
    """
    name = paper_grid_table(noise_ratio)
    tab = ctx.table(name)
    m = f1_matrix(tab, noise_ratio, TABLE1_CONTACT_S)
    if m is None:
        return None
    e_min, width, n = _grid(tab)
    phi = tab.threshold
    out = {"table": name, "grid": {"e_min": e_min, "width": width, "intervals": n},
           "intervals": matrix_stats(m, phi).to_dict(), "build": build_time(tab)}
    if material_cover:
        from designkit.materials import list_materials

        ranges = np.array([mat.effusivity_range for mat in list_materials()], dtype=np.float64)
        cover = [covering_intervals(lo, hi, e_min, width, n) for lo, hi in ranges]
        out["materials"] = matrix_stats(_pair_means(m, cover, chance_f1(ctx)["mean"]), phi).to_dict()
    return out


# ============================================================ Fig. 3
def section_f1_matrices(ctx: Context) -> SectionResult:
    """Fig. 3: F1 matrices at contact 4 s and 1 s (Ts0 35, sigma 0.05: sigma/dT 0.005)."""
    t0 = time.perf_counter()
    title = "F1 matrices, contact 4 s and 1 s (paper Fig. 3)"
    tab = ctx.table(HEATMAP_TABLE)
    ratio = 0.05 / 10.0
    mats = {c: f1_matrix(tab, ratio, c) for c in (4.0, 1.0)}
    if tab is None or any(m is None for m in mats.values()):
        why = ctx.table_problem(HEATMAP_TABLE) if tab is None else \
            f"table `{HEATMAP_TABLE}` has no full matrix at sigma/dT {ratio:g} and contact 1 s and 4 s"
        return SectionResult("f1-matrices", title, f"*Skipped: {why}.*", skipped=why,
                             wall_s=time.perf_counter() - t0)
    e_min, width, n = _grid(tab)
    centres = tab.axes["e_ref"]
    phi = tab.threshold
    from designkit.figures import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8), constrained_layout=True)
    extent = (e_min, e_min + width * n, e_min, e_min + width * n)
    im = None
    for ax, c in zip(axes, (4.0, 1.0)):
        im = ax.imshow(mats[c], origin="lower", extent=extent, vmin=0.0, vmax=1.0, cmap="viridis",
                       interpolation="nearest")
        ax.contour(centres, centres, np.nan_to_num(mats[c], nan=0.0), levels=[phi], colors="white",
                   linewidths=0.8)
        ax.set_title(f"contact {c:g} s (Ts0 35 °C, Ta 25 °C, σ 0.05 °C)", fontsize=10)
        ax.set_xlabel("effusivity [J s$^{-1/2}$ K$^{-1}$ m$^{-2}$]")
        ax.set_ylabel("effusivity [J s$^{-1/2}$ K$^{-1}$ m$^{-2}$]")
    fig.colorbar(im, ax=axes, shrink=0.85, label=f"SVM F1 (white line: F1 = {phi:g})")
    figs = [ctx.save_figure(fig, "fig3_f1_matrices")]
    csvs = [ctx.save_matrix_csv(f"f1_matrix_contact{int(c)}s", mats[c], centres, "e_centre") for c in (4.0, 1.0)]

    stats = {c: matrix_stats(mats[c], phi) for c in (4.0, 1.0)}
    dups = {c: matrix_delta_up(mats[c], width, phi) for c in (4.0, 1.0)}
    refs = [1000.0, 5000.0, 10000.0, 20000.0, 30000.0]
    ridx = [int(np.argmin(np.abs(centres - e))) for e in refs]
    rows = [[fmt(centres[i], 5)] + [fmt(dups[c][i], 4) for c in (1.0, 4.0)] for i in ridx]
    lines = [
        f"Table `{HEATMAP_TABLE}`: {n} intervals of {width:g} on ({e_min:g}, {e_min + width * n:g}], "
        f"{tab.header['trials']} trials each, {tab.header['folds']}-fold F1 of the paper's SVM, every pair scored. The paper's grid has 500 "
        f"intervals of 80 (124,750 SVM fits per matrix, about an hour each); the coarser grid shows the "
        f"same structure. Numbers: [{csvs[0]}]({csvs[0]}), [{csvs[1]}]({csvs[1]}).",
        "",
        f"![F1 matrices]({figs[0]})",
        "",
        md_table(["contact", "mean F1", "% pairs F1 < 0.9", "pairs"],
                 [[f"{c:g} s", fmt(stats[c].mean_f1), fmt(stats[c].percent_indistinguishable, 3),
                   stats[c].pairs] for c in (4.0, 1.0)]),
        "",
        "delta(e) towards higher effusivity read off the matrices (first partner with F1 >= 0.9):",
        "",
        md_table(["e (interval centre)", "delta at 1 s", "delta at 4 s"], rows),
        "",
        f"The paper's two observations hold: the longer contact separates more pairs (mean F1 "
        f"{stats[4.0].mean_f1:.3f} at 4 s against {stats[1.0].mean_f1:.3f} at 1 s), and delta(e) rises with "
        f"effusivity, so large effusivities (metals) are the hardest to tell apart.",
    ]
    numbers = {
        "table": HEATMAP_TABLE, "noise_ratio": ratio, "grid": {"e_min": e_min, "width": width, "intervals": n},
        "contacts": {f"{c:g}": {**stats[c].to_dict(),
                                "delta_up_at": {f"{centres[i]:g}": dups[c][i] for i in ridx}} for c in (4.0, 1.0)},
        "csv": csvs,
    }
    return SectionResult("f1-matrices", title, "\n".join(lines), numbers, tuple(figs),
                         wall_s=time.perf_counter() - t0)


# ============================================================ Table I
def _interval_row(ctx: Context, ratio: float) -> dict:
    svm = ctx.table(STAIRCASE_TABLE)
    ideal = ctx.table(IDEAL_TABLE)
    c = TABLE1_CONTACT_S
    out = {
        "percent": staircase_percent(svm, ratio, c),
        "percent_lo": staircase_percent(svm, ratio, c, "_lo"),
        "percent_hi": staircase_percent(svm, ratio, c, "_hi"),
        "percent_ideal": staircase_percent(ideal, ratio, c),
    }
    coarse_t = ctx.table(COARSE_TABLE)
    coarse = f1_matrix(coarse_t, ratio, c)
    if coarse is not None:
        phi = coarse_t.threshold
        out["coarse"] = matrix_stats(coarse, phi).to_dict()
        fine_t = ctx.table(FINE_TABLE)
        fine = f1_matrix(fine_t, ratio, c)
        c_min, c_w, c_n = _grid(coarse_t)
        f_grid = _grid(fine_t) if fine is not None else None
        keep = np.flatnonzero(c_min + c_w * (np.arange(c_n) + 1) <= f_grid[0] + f_grid[1] * f_grid[2] + 1e-9) \
            if f_grid is not None else np.zeros(0, dtype=int)
        if fine is not None and keep.size >= 2:
            f_min, f_w, f_n = f_grid
            out["low_region"] = {"e_max": f_min + f_w * f_n,
                                 "coarse": matrix_stats(coarse, phi, keep).to_dict(),
                                 "fine": matrix_stats(fine, phi).to_dict()}
    return out


def _material_row(ctx: Context, ratio: float) -> dict | None:
    mf = material_f1(ctx, ratio)
    if mf is None:
        return None
    phi = ctx.table(COARSE_TABLE).threshold
    K = len(mf.names)
    iu = np.triu_indices(K, 1)
    return {"materials": K, "pairs": int(iu[0].size),
            "pairs_on_fine_grid": int(np.sum(mf.fine[iu])),
            **mf.stats(phi).to_dict(),
            "coarse_only": mf.stats(phi, coarse_only=True).to_dict()}


def table1_numbers(ctx: Context) -> list[dict]:
    """Every number of Table I, one dict per paper row (ours, paper, evidence)."""
    rows = []
    for k, p in enumerate(TABLE1):
        r = p.noise_ratio
        rows.append({"noise_c": p.noise_c, "delta_t_c": p.delta_t_c, "noise_ratio": r,
                     "paper": {"intervals_percent": p.intervals_percent, "intervals_f1": p.intervals_f1,
                               "materials_percent": p.materials_percent, "materials_f1": p.materials_f1},
                     "intervals": _interval_row(ctx, r), "materials": _material_row(ctx, r),
                     "paper_grid": paper_grid_row(ctx, r)})
        ctx.step(k + 1, len(TABLE1))
    return rows


def comparisons(rows: list[dict], explain) -> list[Comparison]:
    out = []
    for r in rows:
        tag = f"sigma {r['noise_c']:g}, dT {r['delta_t_c']:g}"
        mat = r["materials"] or {}
        items = [
            ("intervals % indistinguishable", r["intervals"]["percent"], r["paper"]["intervals_percent"],
             TABLE1_PERCENT_TOLERANCE),
            ("intervals mean F1", (r["intervals"].get("coarse") or {}).get("mean_f1"), r["paper"]["intervals_f1"],
             TABLE1_F1_TOLERANCE),
            ("materials % indistinguishable", mat.get("percent_indistinguishable"), r["paper"]["materials_percent"],
             TABLE1_PERCENT_TOLERANCE),
            ("materials mean F1", mat.get("mean_f1"), r["paper"]["materials_f1"], TABLE1_F1_TOLERANCE),
        ]
        for q, ours, paper, tol in items:
            c = Comparison(f"Table I {q} ({tag})", ours, paper, tol)
            if c.beyond_tolerance:
                c = Comparison(c.quantity, ours, paper, tol, explain(q, r))
            out.append(c)
    return out


def _graph_numbers(mf: MaterialF1, phi: float) -> dict:
    import networkx as nx

    K = len(mf.names)
    G = nx.Graph()
    G.add_nodes_from(range(K))
    edges = [(a, b, float(mf.f1[a, b])) for a in range(K) for b in range(a + 1, K) if mf.f1[a, b] < phi]
    G.add_weighted_edges_from(edges, weight="f1")
    comps = [sorted(c) for c in nx.connected_components(G) if len(c) > 1]
    comps.sort(key=len, reverse=True)
    fam = np.array(mf.families)
    density = {}
    for f in sorted(set(mf.families)):
        idx = np.flatnonzero(fam == f)
        possible = idx.size * (idx.size - 1) / 2
        inside = sum(1 for a, b, _ in edges if fam[a] == f and fam[b] == f)
        density[f] = {"materials": int(idx.size), "edges": inside,
                      "density": inside / possible if possible else math.nan}
    cross = sum(1 for a, b, _ in edges if fam[a] != fam[b])
    return {
        "graph": G, "edges": edges,
        "numbers": {
            "materials": K, "edges": len(edges), "pairs": K * (K - 1) // 2,
            "percent_indistinguishable": 100.0 * len(edges) / (K * (K - 1) / 2),
            "isolated": int(sum(1 for v in G.nodes if G.degree[v] == 0)),
            "components": [{"size": len(c), "families": {f: int(sum(fam[c] == f)) for f in sorted(set(fam[c]))},
                            "members": [mf.names[i] for i in c]} for c in comps],
            "within_family": density, "cross_family_edges": cross,
        },
    }


def short_label(name: str) -> str:
    """A node label: the acronym a material is known by, else its name without a lower-case aside.

    >>> short_label("Polymethyl methacrylate (Acrylic, PMMA)"), short_label("Rigid polymer foam (HD)")
    ('PMMA', 'rigid foam HD')
    >>> short_label("CFRP, epoxy matrix (quasi-isotropic)"), short_label("Stainless steel")
    ('CFRP, epoxy matrix', 'Stainless steel')
    """
    import re

    base, _, aside = name.partition(" (")
    aside = aside.rstrip(")")
    if "foam" in base:
        return f"{base.split()[0].lower()} foam {aside}".strip()
    tokens = [t.strip() for t in aside.split(",")]
    acronyms = [t for t in tokens if len(re.findall(r"[A-Z]", t)) >= 2 and " " not in t]
    if acronyms:
        return acronyms[-1]
    return base if aside and aside == aside.lower() else name


_RING_SPACING = 0.5  # distance between neighbouring nodes on a component's ring (axis units)
_LABEL_ROOM = 5.0  # gap between rings, and margin around the drawing, for the labels (axis units)


def graph_layout(G, order_key) -> tuple[dict, dict]:
    """Positions and label angles for a readable node graph: each connected component on its own ring
    (members in ``order_key`` order, so that similar materials sit side by side), rings left to right by
    size, isolated nodes in a row beneath.

    Returns ``(pos, angle)``: node -> (x, y), and node -> the label's direction in degrees (radially
    outwards on a ring, -90 below a lone node).
    """
    import networkx as nx

    comps = sorted((sorted(c, key=order_key) for c in nx.connected_components(G)), key=len, reverse=True)
    rings = [c for c in comps if len(c) > 1]
    singles = sorted((c[0] for c in comps if len(c) == 1), key=order_key)
    pos, angle = {}, {}
    x0, r_max = 0.0, 0.5
    for c in rings:
        r = max(0.45, len(c) * _RING_SPACING / (2 * math.pi))
        for k, v in enumerate(c):
            th = math.pi / 2 - 2 * math.pi * k / len(c)
            pos[v] = (x0 + r + r * math.cos(th), r * math.sin(th))
            angle[v] = math.degrees(th)
        x0 += 2 * r + _LABEL_ROOM  # room for the labels between rings
        r_max = max(r_max, r)
    width = max(x0 - _LABEL_ROOM, 1.0)
    if singles:
        step = width / max(len(singles) - 1, 1) if len(singles) > 1 else 0.0
        for k, v in enumerate(singles):
            pos[v] = ((k * step) if len(singles) > 1 else width / 2, -r_max - 2.6)
            angle[v] = -90.0
    return pos, angle


def _draw_graph(ax, mf: MaterialF1, G, edges, seed: int, title: str) -> None:
    import networkx as nx

    mid = mf.ranges.mean(axis=1)
    pos, angle = graph_layout(G, lambda v: mid[v])
    radius = 2.5 + 7.5 * mid / mid.max()  # points; radius grows with effusivity above a floor
    colours = [FAMILY_COLOURS.get(f, "grey") for f in mf.families]
    widths = [0.9 * 0.9 / max(f1, 0.05) for _, _, f1 in edges]
    nx.draw_networkx_edges(G, pos, edgelist=[(a, b) for a, b, _ in edges], width=widths, alpha=0.3, ax=ax)
    nx.draw_networkx_nodes(G, pos, node_size=radius ** 2, node_color=colours, edgecolors="black",
                           linewidths=0.4, ax=ax)
    for v, (x, y) in pos.items():  # each label outside its node, along the ring's radius, never upside down
        th = angle[v]
        c, s = math.cos(math.radians(th)), math.sin(math.radians(th))
        d = radius[v] + 2.0
        left = c < -1e-9
        rot = th + 180.0 if left else th
        ax.annotate(short_label(mf.names[v]), (x, y), xytext=(d * c, d * s), textcoords="offset points",
                    ha="right" if left else "left", va="center", rotation=rot, rotation_mode="anchor",
                    fontsize=6.5)
    ax.set_title(title, fontsize=10)
    xs, ys = [p[0] for p in pos.values()], [p[1] for p in pos.values()]
    ax.set_xlim(min(xs) - _LABEL_ROOM * 0.8, max(xs) + _LABEL_ROOM * 0.8)
    ax.set_ylim(min(ys) - _LABEL_ROOM, max(ys) + _LABEL_ROOM * 0.8)
    ax.set_aspect("equal")
    ax.set_axis_off()


def section_node_graphs(ctx: Context) -> SectionResult:
    """Fig. 6: indistinguishable material pairs at Ts0 30 and 35 degC, contact 2 s, sigma 0.05."""
    t0 = time.perf_counter()
    title = "Node graphs of indistinguishable material pairs (paper Fig. 6)"
    coarse_t = ctx.table(COARSE_TABLE)
    results = {}
    for k, (ts0, sigma) in enumerate(GRAPH_SETTINGS):
        mf = material_f1(ctx, sigma / (ts0 - AMBIENT_C))
        if mf is not None:
            results[ts0] = (mf, _graph_numbers(mf, coarse_t.threshold))
        ctx.step(k + 1, len(GRAPH_SETTINGS) + 1)
    if len(results) < len(GRAPH_SETTINGS):
        why = ctx.table_problem(COARSE_TABLE) if coarse_t is None else \
            f"table `{COARSE_TABLE}` lacks sigma/dT 0.01 or 0.005 at contact 2 s"
        return SectionResult("node-graphs", title, f"*Skipped: {why}.*", skipped=why,
                             wall_s=time.perf_counter() - t0)
    from matplotlib.lines import Line2D

    from designkit.figures import pyplot
    from designkit.materials import FAMILY_LABELS

    plt = pyplot()
    fig, axes = plt.subplots(2, 1, figsize=(15, 13), constrained_layout=True)
    figs, csvs, numbers = [], [], {}
    for ax, ts0 in zip(axes, (30.0, 35.0)):
        mf, g = results[ts0]
        _draw_graph(ax, mf, g["graph"], g["edges"], ctx.settings.seed,
                    f"Ts0 {ts0:g} °C (σ 0.05 °C, Ta 25 °C, contact 2 s): {len(g['edges'])} indistinguishable pairs")
        name = f"node_graph_edges_ts0_{int(ts0)}"
        csvs.append(ctx.save_csv(name, ["material_1", "material_2", "f1", "grid"],
                                 [[mf.names[a], mf.names[b], f1, "width 80" if mf.fine[a, b] else "width 400"]
                                  for a, b, f1 in sorted(g["edges"], key=lambda e: e[2])]))
        numbers[f"ts0_{ts0:g}"] = {**g["numbers"], "noise_ratio": 0.05 / (ts0 - AMBIENT_C), "edges_csv": csvs[-1]}
    handles = [Line2D([], [], marker="o", ls="", color=c, markeredgecolor="black", label=FAMILY_LABELS[f])
               for f, c in FAMILY_COLOURS.items()]
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=9, frameon=False)
    figs.append(ctx.save_figure(fig, "fig6_node_graphs"))
    ctx.step(1, 1)

    n30, n35 = numbers["ts0_30"], numbers["ts0_35"]

    def comp_line(n):
        parts = [f"{c['size']} ({', '.join(f'{v} {f}' for f, v in c['families'].items())})" for c in n["components"]]
        return "; ".join(parts) if parts else "none"

    fam_rows = [[f, n30["within_family"][f]["materials"],
                 f"{n30['within_family'][f]['edges']} ({fmt(n30['within_family'][f]['density'], 2)})",
                 f"{n35['within_family'][f]['edges']} ({fmt(n35['within_family'][f]['density'], 2)})"]
                for f in FAMILY_COLOURS]
    metals30 = n30["within_family"]["metals"]["density"]
    poly30 = n30["within_family"]["polymers"]["density"]
    lines = [
        "Nodes: the database materials; radius grows linearly with the midpoint of the material's "
        "effusivity range (above a small floor so that foams stay visible); colour: family; an edge joins a "
        "pair whose F1 is below 0.9 (indistinguishable), its width is proportional to 1/F1. Positions carry "
        "no meaning (spring layout). Pair F1 as in Table I (mean over covering interval pairs). Edge lists: "
        + ", ".join(f"[{c}]({c})" for c in csvs) + ".",
        "",
        f"![node graphs]({figs[0]})",
        "",
        md_table(["", "Ts0 30 °C (σ/dT 0.01)", "Ts0 35 °C (σ/dT 0.005)"], [
            ["indistinguishable pairs (edges)", f"{n30['edges']} of {n30['pairs']} ({n30['percent_indistinguishable']:.2f} %)",
             f"{n35['edges']} of {n35['pairs']} ({n35['percent_indistinguishable']:.2f} %)"],
            ["materials without an edge", n30["isolated"], n35["isolated"]],
            ["connected components (size: families)", comp_line(n30), comp_line(n35)],
            ["edges across families", n30["cross_family_edges"], n35["cross_family_edges"]],
        ], align="lll"),
        "",
        "Edges inside each family (density = edges / possible pairs):",
        "",
        md_table(["family", "materials", "Ts0 30 °C", "Ts0 35 °C"], fam_rows),
        "",
        "The paper's observations, checked: "
        f"the hotter sensor leaves fewer indistinguishable pairs ({n35['edges']} vs {n30['edges']} edges); "
        f"the graphs have {len(n30['components'])} and {len(n35['components'])} connected components of two or "
        f"more materials (paper: three to four), each dominated by one family; metals are densely connected "
        f"(density {fmt(metals30, 2)} at Ts0 30 °C) and polymers/elastomers "
        f"{'more' if poly30 > metals30 else 'less'} so ({fmt(poly30, 2)}; the paper: more).",
    ]
    return SectionResult("node-graphs", title, "\n".join(lines), numbers, tuple(figs),
                         wall_s=time.perf_counter() - t0)
