"""Model selection: every candidate fitted on some touches and scored on the others.

:func:`compare_models` fits each candidate (:data:`~designkit.calibration.candidates.CANDIDATES`)
on some touches (by default trial sets 1-4, :func:`~designkit.calibration.split.choose_split`) and
scores it on the others (residual RMS per material, each held-out touch with its own Ts0 and To),
with AIC and BIC on the fitted touches for reference (their sample count overstates the
information in correlated residuals: the held-out residual decides, by the one-standard-error
rule). :func:`plot_identification` draws the result.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from .candidates import CANDIDATES, PARAMS, Candidate, candidate
from .force import FORCE_SMOOTHING_S
from .identify import identify, residual_series, rms_by_material
from .results import Identification
from .trials import Trial

__all__ = ["Comparison", "compare_models", "plot_identification"]


@dataclass(frozen=True)
class Comparison:
    """Candidates side by side: fit on some touches, scored on the others.

    Attributes
    ----------
    results : tuple of Identification
        One per candidate (fitted on the fit touches).
    held_out_rms_c : tuple of dict
        Per candidate, residual RMS per material (and ``"all"``) on the held-out touches.
    selected : str
        Label of the candidate with the smallest held-out RMS (BIC without held-out touches) among
        those without conflicting ranges.
    n_fit, n_held_out : int
    total_time_s : float
    reason : str
        Why ``selected`` was chosen, with its held-out residuals and the paper model's.
    """

    results: tuple[Identification, ...]
    held_out_rms_c: tuple[Mapping[str, float], ...]
    selected: str
    n_fit: int
    n_held_out: int
    total_time_s: float
    reason: str = ""

    def table(self) -> list[dict[str, Any]]:
        """One row per candidate: label, fit and held-out RMS, AIC, BIC, rank, e_s and its consistency."""
        rows = []
        for res, held in zip(self.results, self.held_out_rms_c):
            rows.append({"model": res.candidate.label, "fit_rms_c": res.rms_c,
                         "held_out_rms_c": dict(held), "aic": res.aic, "bic": res.bic,
                         "rank": f"{res.rank}/{res.n_nonlinear}", "consistent": res.consistent,
                         "effusivity": None if res.effusivity is None else res.effusivity.to_dict(),
                         "fit_time_s": res.fit_time_s})
        return rows

    def to_dict(self) -> dict[str, Any]:
        return {"selected": self.selected, "reason": self.reason, "n_fit": self.n_fit, "n_held_out": self.n_held_out,
                "total_time_s": self.total_time_s, "table": self.table(),
                "results": [r.to_dict() for r in self.results]}


def _warm_start(cand: Candidate, done: Sequence[Identification]) -> np.ndarray | None:
    """Start a candidate from fitted ones nested in it.

    The base is the fitted candidate nested in ``cand`` that shares the most free parameters with it
    (the latest on a tie); a free parameter it lacks, and the time offset, come from the latest nested
    candidate with the same contact-area option where one has them (an area model's offset counts
    from the first share's contact, not from full contact), else the parameter's default start.
    Starting the layered area candidate from the layered drift fit (5 of its 6 parameters) rather than
    from the contact area fit (3 of 6) takes its fit on the 120 shared touches from 423 to fewer
    residual evaluations (docs/sensor-models.md, "Fit time").
    """
    nested = [prev for prev in done
              if (prev.candidate.model == cand.model or (prev.candidate.model in ("semi-infinite", "contact")
                                                         and cand.model in ("contact", "layered")))
              and set(prev.candidate.free) <= set(cand.free)]
    if not nested:
        return None
    base = max(reversed(nested), key=lambda r: len(set(r.candidate.free) & set(cand.free)))
    alike = [r for r in nested if r.candidate.force_area == cand.force_area]
    x = []
    for p in cand.free:
        src = base if p in base.candidate.free else next(
            (r for r in reversed(alike) if p in r.candidate.free), None)
        x.append(src.x[src.candidate.free.index(p)] if src is not None else PARAMS[p].to_x(PARAMS[p].start))
    rest = np.array(base.x[len(base.candidate.free):], dtype=np.float64)
    if alike and base.candidate.force_area != cand.force_area:
        rest[0] = alike[-1].x[len(alike[-1].candidate.free)]     # the time offset
    return np.concatenate([x, rest])


def compare_models(fit_trials: Sequence[Trial], held_out: Sequence[Trial],
                   candidates: Sequence["str | Candidate"] = CANDIDATES, **kwargs: Any) -> Comparison:
    """Fit every candidate on ``fit_trials``, score each on ``held_out``; select by held-out RMS.

    Each candidate starts from the fitted parameters of the last one nested in it. With no
    held-out touches the selection is by BIC (the scores are empty); candidates whose ranges
    conflict are passed over while another is consistent (:func:`_select`). Candidates with
    ``force_area`` are left out of a comparison of several when a touch has no force channel, or
    none to 1 s after the onset (where the force's plateau is read).

    ``kwargs`` go to :func:`~designkit.calibration.identify.identify` (``ranges``, ``object_temps``, ``depth_m``, ...).
    """
    t0 = time.perf_counter()
    results, held, touch_ms = [], [], []
    forced = all(np.isfinite(tr.force_n).all() and tr.time_s[-1] >= 1.0 + FORCE_SMOOTHING_S
                 for tr in list(fit_trials) + list(held_out))
    for c in candidates:
        c = c if isinstance(c, Candidate) else candidate(c)
        if c.force_area and not forced and len(candidates) > 1:
            continue   # a force-driven contact area needs the force channel of every touch
        res = identify(fit_trials, c, x0=_warm_start(c, results), **kwargs)
        results.append(res)
        if held_out:
            rows = residual_series(res, held_out, object_temps=kwargs.get("object_temps"))
            held.append(rms_by_material([(name, r) for name, _, r in rows]))
            touch_ms.append(np.array([float(np.mean(r ** 2)) for _, _, r in rows]))
        else:
            held.append({})
    best, reason = _select(results, held, touch_ms)
    return Comparison(tuple(results), tuple(held), results[best].candidate.label, len(fit_trials), len(held_out),
                      time.perf_counter() - t0, reason)


def _select(results: Sequence[Identification], held: Sequence[Mapping[str, float]],
            touch_ms: Sequence[np.ndarray] = ()) -> tuple[int, str]:
    """Index of the selected candidate and why.

    With held-out touches: the one-standard-error rule (Breiman et al. 1984; Hastie, Tibshirani and
    Friedman, *Elements of Statistical Learning* 7.10): the simplest candidate (fewest fitted
    parameters, per-touch ones included) whose held-out mean squared residual exceeds the best
    one's by at most one standard error of their difference, taken over the held-out touches
    (paired: the same touches score every candidate). On touches a simple model fits to the noise,
    a richer one no longer wins by a hair. Without held-out touches: the lowest BIC on the fitted
    touches. A candidate whose materials' ranges conflict (no one e_s keeps every material in
    range) is passed over while another is consistent: its sensor file would be refused.
    """
    ok = [i for i in range(len(results)) if results[i].consistent is not False] or list(range(len(results)))
    skipped = len(results) - len(ok)
    conflict = f"; {skipped} candidate(s) passed over for conflicting ranges" if skipped else ""
    scored = bool(held) and all(h for h in held) and len(touch_ms) == len(results)
    if len(results) == 1:
        return 0, f"{results[0].candidate.label}: the model asked for"
    if not scored:
        best = min(ok, key=lambda i: results[i].bic)
        return best, (f"{results[best].candidate.label}: the lowest BIC on the fitted touches among "
                      f"{len(results)} candidates (no touches held out){conflict}")
    low = min(ok, key=lambda i: (float(np.mean(touch_ms[i])), results[i].bic))
    simple = sorted(ok, key=lambda i: (results[i].n_parameters, i))
    best = low
    for i in simple:
        d = touch_ms[i] - touch_ms[low]
        se = float(np.std(d, ddof=1) / math.sqrt(d.size)) if d.size > 1 else 0.0
        if float(np.mean(d)) <= se:
            best = i
            break
    label = results[best].candidate.label
    per = ", ".join(f"{n} {v:.3f}" for n, v in held[best].items() if n != "all")
    how = ("the smallest residual on the held-out touches" if best == low else
           f"the simplest within one standard error of the smallest held-out residual ({results[low].candidate.label}"
           ": " + ", ".join(f"{n} {v:.3f}" for n, v in held[low].items() if n != "all") + " °C)")
    paper = next((h for r, h in zip(results, held) if r.candidate.label == "semi-infinite"), None)
    versus = "" if paper is None or label == "semi-infinite" else \
        "; the paper's semi-infinite model: " + ", ".join(f"{n} {v:.3f}" for n, v in paper.items() if n != "all") \
        + " °C"
    return best, (f"{label}: {how} among {len(results)} candidates, {per} °C RMS on "
                  f"{touch_ms[best].size} held-out touches{versus}{conflict}")


def plot_identification(results: Sequence[Identification], selected: str, fit_trials: Sequence[Trial],
                        held_out: Sequence[Trial], path: "Path | str", *,
                        held_out_rms_c: Sequence[Mapping[str, float]] = (),
                        object_temps: Mapping[str, Any] | None = None) -> Path:
    """Figure of an identification (``calibrate fit --model NAME --plot f.png``); returns ``path``.

    Left: the selected model's mean prediction (dashed) over the mean reading (solid) [degC] of each
    material's fitted touches, each touch with its own Ts0 and To (as :func:`~designkit.calibration.identify.score`). Middle: the
    mean residual (prediction - reading) [degC] on the fitted (solid) and held-out (dotted) touches.
    Right: residual RMS of every candidate on the fitted and on the held-out touches [degC].
    Where the touches of a material lie on different time grids, each is interpolated onto the
    first one's.
    """
    from ..figures import pyplot

    best = next(r for r in results if r.candidate.label == selected)

    def by_material(trials: Sequence[Trial]) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Per material: (time grid [s], mean reading, mean residual) over its touches."""
        if not trials:
            return {}
        rows = residual_series(best, trials, object_temps=object_temps)
        out: dict[str, list] = {}
        for tr, (name, t, r) in zip(trials, rows):
            grid = out.setdefault(name, [t, [], []])[0]
            out[name][1].append(np.interp(grid, t, tr.sensor_c))
            out[name][2].append(np.interp(grid, t, r))
        return {n: (g, np.mean(y, axis=0), np.mean(r, axis=0)) for n, (g, y, r) in out.items()}

    fitted, held = by_material(fit_trials), by_material(held_out)
    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(15.0, 4.2), constrained_layout=True,
                             gridspec_kw={"width_ratios": [1.0, 1.0, 0.9]})
    for k, (n, (t, y, r)) in enumerate(fitted.items()):
        count = sum(tr.material == n for tr in fit_trials)
        # the reading light and wide, the model dark and dashed on top: the model stays visible where it fits
        axes[0].plot(t, y, color=f"C{k}", lw=3.0, alpha=0.45, label=f"{n}: reading (mean of {count})")
        axes[0].plot(t, y + r, color="k", lw=1.2, ls=(0, (4, 2)), zorder=4,
                     label=f"model {selected}" if k == 0 else None)
        axes[1].plot(t, r, color=f"C{k}", lw=1.0, label=f"{n}, fitted touches")
        if n in held:
            th, _, rh = held[n]
            axes[1].plot(th, rh, color=f"C{k}", lw=1.0, ls=":", label=f"{n}, held-out touches")
    axes[0].set_xlabel("time after detected onset [s]")
    axes[0].set_ylabel("sensor temperature [°C]")
    axes[0].set_title("reading (wide) and the selected model (dashed)")
    axes[0].legend(fontsize=7)
    axes[1].axhline(0, color="k", lw=0.5)
    axes[1].set_xlabel("time after detected onset [s]")
    axes[1].set_ylabel("mean residual (model - reading) [°C]")
    axes[1].set_title("residual, each touch with its own Ts0 and To", fontsize=9)
    axes[1].legend(fontsize=7)
    ax = axes[2]
    labels = [r.candidate.label for r in results]
    pos = np.arange(len(results))
    fit_rms = [r.rms_c for r in results]
    held_rms = [h.get("all", math.nan) for h in held_out_rms_c] if held_out_rms_c else [math.nan] * len(results)
    ax.barh(pos - 0.2, fit_rms, height=0.4, color="C0", label="fitted touches")
    if np.isfinite(held_rms).any():
        ax.barh(pos + 0.2, held_rms, height=0.4, color="C1", label="held-out touches")
    ax.set_yticks(pos, [lab + (" *" if lab == selected else "") for lab in labels], fontsize=7)
    ax.set_ylim(len(results) - 0.2, -0.8)   # top to bottom, with room for the legend
    ax.set_xlabel("residual RMS [°C]")
    ax.set_title("candidates (* selected)", fontsize=9)
    ax.legend(fontsize=7)
    for a in axes:
        a.grid(alpha=0.3)
    from ..figures import save_figure

    return save_figure(fig, path, dpi=110)
