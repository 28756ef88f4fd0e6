"""Identify any registered sensor model from recorded touches, and choose between models.

:mod:`designkit.calibration.fit` identifies the paper's semi-infinite model
(e_s and tau). On real touches that model's *shape* is wrong (issue 14): its
residual is 30-40 times the noise and the materials ask for conflicting e_s.
This module fits any forward model of :mod:`designkit.models` behind one
least-squares problem and compares them on touches the fit has not seen.

The problem
-----------
Trial ``i`` of material ``m`` on its own time grid (contact detected at 0,
heat flowing from ``t_off``)::

    T_i(t) = Ts0_i (1 - v_m(t)) + To_i v_m(t),    v_m = S[ u(t - t_off; e_o,m / e_s, theta) ]

``u`` is the model's normalized reading (0 before contact), ``S`` the
recordings' host smoothing (Savitzky-Golay over the whole trial, as the host
did) when the candidate includes it, ``theta`` the model's sensor parameters.

* Every model here is linear in the temperatures and changes nothing when all
  effusivities (and h_c) are scaled together, so the fit runs with ``e_s = 1``:
  it identifies ratios ``rho_m = e_o,m / e_s``, ``e_b / e_s`` and ``h_c / e_s``.
  e_s itself comes from the materials' handbook ranges, as in the paper: each
  material allows ``e_s`` in ``[e_min,m / rho_m, e_max,m / rho_m]``; one e_s
  consistent with every range exists when these overlap (else: *conflict*).
* Each touch's own initial temperatures: the sensor's ``Ts0_i`` is fitted
  (closed form, variable projection; the pre-contact samples are in the fit),
  the object's ``To_i`` is the passive thermistor before contact where it sits
  still, ambient (a number) where there is none, or fitted per touch where the
  object is not at room temperature (its passive channel moves in contact).
* Nonlinear parameters (transformed: logs of positive quantities) by
  :func:`scipy.optimize.least_squares` (trust-region reflective, bounded,
  finite-difference Jacobian of the projected residual).

Uncertainty and identifiability
-------------------------------
Residuals of a smoothed, imperfect model are correlated along a touch, so the
covariance is the cluster-robust sandwich with touches as clusters (as in
:mod:`~designkit.calibration.fit`), bias-reduced for few touches (CR2: each
touch's residuals un-shrunk by its block of the hat matrix), and each interval
takes Student's t with that parameter's Bell-McCaffrey degrees of freedom: a
parameter carried by a few touches gets few (:func:`_sandwich`; measured by
the pty round trips of :mod:`~designkit_lab.roundtrip`). The Jacobian's singular values (columns
scaled to unit norm) give its numerical rank; a parameter is reported *not
identified* when the Jacobian is rank-deficient along it, its interval spans
more than a factor of 10, or it sits on a search bound.

Model selection
---------------
:func:`compare_models` fits each candidate on some touches (by default trial
sets 1-4) and scores it on the others (residual RMS per material, each
held-out touch with its own Ts0 and To), with AIC and BIC on the fitted
touches for reference (their sample count overstates the information in
correlated residuals: the held-out residual decides).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from .._validation import InputError
from ..models.ramp import area_share
from .trials import Trial

__all__ = [
    "CANDIDATES",
    "FORCE_NOISE_BAND_SD",
    "FORCE_SMOOTHING_S",
    "HOST_SMOOTHING",
    "Candidate",
    "Comparison",
    "IdentifiedParameter",
    "Identification",
    "candidate",
    "compare_models",
    "contact_area",
    "force_noise",
    "identify",
    "nominal_force_profile",
    "plot_identification",
    "relative_force",
    "residual_series",
    "score",
    "Split",
    "choose_split",
    "split_by_trial_set",
    "trial_sets",
]

#: The recordings' host smoothing: Savitzky-Golay window 99, order 3 (at 200 Hz).
HOST_SMOOTHING = (99, 3)
_LOG_RATIO_LIMIT = 12.0
_LOG_TOUCH_HC = 4.0   # search range of a touch's ln(h_c,i / h_c)
_AFFINE_OFFSET_C, _AFFINE_SLOPE = 5.0, 2.0   # search range of a passive channel's offset [degC] and slope
#: Talbot nodes of the fitted readings (12: error < 1e-8 of the temperature difference).
FIT_TALBOT_NODES = 12


# ------------------------------------------------------------ candidates
@dataclass(frozen=True)
class _Param:
    """A nonlinear parameter: its name, unit, transform and search range (natural units)."""

    name: str
    unit: str
    lo: float
    hi: float
    start: float
    log: bool = True
    scale_with_es: bool = False   # an effusivity or conductance: fitted as a ratio to e_s
    description: str = ""

    def to_x(self, v: float) -> float:
        return math.log(v) if self.log else float(v)

    def from_x(self, x: float) -> float:
        return math.exp(min(max(float(x), -700.0), 700.0)) if self.log else float(x)


_SENSOR_DIFF = _Param("diffusivity_m2_s", "m^2/s", 1e-11, 1e-5, 1.2e-9,
                      description="sensor (film) diffusivity alpha_s at the fixed thermistor depth")
_PARAMS: dict[str, _Param] = {p.name: p for p in (
    _SENSOR_DIFF,
    _Param("conductance_w_m2k", "W m^-2 K^-1", 1e-3, 1e4, 3.0, scale_with_es=True,
           description="sensor-object interface conductance h_c"),
    _Param("film_thickness_m", "m", 1e-6, 1e-2, 150e-6, description="heater film thickness L"),
    _Param("backing_effusivity_ws05_m2k", "J s^-1/2 K^-1 m^-2", 1e-3, 1e3, 0.5, scale_with_es=True,
           description="backing (finger) effusivity e_b"),
    _Param("lag_s", "s", 1e-3, 20.0, 0.3, description="thermistor (and host filter) time constant"),
    _Param("backing_thickness_m", "m", 1e-6, 1.0, 1e-3,
           description="backing thickness L_b (its far face held at Ts0)"),
    _Param("backing_diffusivity_m2_s", "m^2/s", 1e-10, 1e-4, 1e-7, description="backing diffusivity alpha_b"),
    _Param("contact_force_fraction", "", 0.0, 0.9, 0.3, log=False,
           description="force (share of the touch's plateau) at which the contact area starts to grow"),
)}
#: Fittable parameters that belong to the measurement chain, not to the forward model's fields.
_CHAIN_PARAMS = ("contact_force_fraction",)


@dataclass(frozen=True)
class Candidate:
    """One model to identify: a registered forward model, which of its parameters are free, the chain.

    Parameters
    ----------
    label : str
        Name in reports (``"layered+lag+smoothing"``).
    model : str
        Registered model name (:data:`designkit.models.MODELS`).
    free : tuple of str
        Parameters fitted besides the time offset and the objects' ratios:
        ``diffusivity_m2_s`` (the sensor's) and model fields among
        ``conductance_w_m2k``, ``film_thickness_m``,
        ``backing_effusivity_ws05_m2k``, ``lag_s``.
    fixed : mapping
        Model fields held at a value (effusivities and h_c as ratios to e_s).
    smoothing : bool
        Apply the host smoothing (:data:`HOST_SMOOTHING`) to the prediction.
    drift : bool
        Each touch's sensor drifts before contact (the heater still warming
        towards its set point, about 0.1 degC/s on the shared recordings) and
        the drift goes on on the sensor's side of the contact: the baseline
        ``Ts0`` becomes ``Ts0 + s_i t`` in ``T = (Ts0 + s_i t)(1 - u) + To u``
        (smoothed as a whole when ``smoothing``), ``s_i`` [degC/s] one more
        per-touch linear coefficient beside ``Ts0_i`` (closed form, fitted to the
        whole touch like ``Ts0_i``, on held-out touches too; on the shared
        recordings it is a slow trend of the touch, not the rate measured
        before contact: docs/sensor-models.md).
    force_area : bool
        The contact area grows with the touch's own force while the finger
        presses in: the reading is the area-weighted sum of step responses
        started as each share of the area comes into contact (parallel
        columns, lateral conduction neglected),
        ``u_i(t) = sum_j dA_i(t_j) u(t - t_j - t_off)``, with the area share
        ``A_i = clip((F_i - c F_p,i) / ((1 - c) F_p,i), 0, 1)`` from the
        measured force ``F_i`` and its plateau ``F_p,i`` (median from 1 s after
        the onset); ``c`` (``contact_force_fraction``, the force share at which
        the area starts to grow) is fitted when free, else 0. Needs a force
        channel on a uniform grid.
    """

    label: str
    model: str
    free: tuple[str, ...] = ("diffusivity_m2_s",)
    fixed: Mapping[str, Any] = field(default_factory=dict)
    smoothing: bool = False
    drift: bool = False
    force_area: bool = False

    def __post_init__(self) -> None:
        unknown = [p for p in self.free if p not in _PARAMS]
        if unknown:
            raise InputError(f"candidate {self.label}: no fittable parameter {', '.join(unknown)} "
                             f"(fittable: {', '.join(_PARAMS)})")


#: The candidates :func:`compare_models` tries by default, simplest first.
CANDIDATES: tuple[Candidate, ...] = (
    Candidate("semi-infinite", "semi-infinite"),
    Candidate("contact", "contact", ("diffusivity_m2_s", "conductance_w_m2k")),
    Candidate("contact+smoothing", "contact", ("diffusivity_m2_s", "conductance_w_m2k"), smoothing=True),
    Candidate("layered", "layered", ("diffusivity_m2_s", "conductance_w_m2k", "film_thickness_m",
                                     "backing_effusivity_ws05_m2k")),
    Candidate("layered+lag", "layered", ("diffusivity_m2_s", "conductance_w_m2k", "film_thickness_m",
                                         "backing_effusivity_ws05_m2k", "lag_s")),
    Candidate("layered+lag+smoothing", "layered", ("diffusivity_m2_s", "conductance_w_m2k", "film_thickness_m",
                                                   "backing_effusivity_ws05_m2k", "lag_s"), smoothing=True),
    Candidate("layered+lag+smoothing+drift", "layered", ("diffusivity_m2_s", "conductance_w_m2k",
                                                         "film_thickness_m", "backing_effusivity_ws05_m2k", "lag_s"),
              smoothing=True, drift=True),
    Candidate("contact+smoothing+drift+area", "contact", ("diffusivity_m2_s", "conductance_w_m2k",
                                                          "contact_force_fraction"),
              smoothing=True, drift=True, force_area=True),
    Candidate("layered+lag+smoothing+drift+area", "layered",
              ("diffusivity_m2_s", "conductance_w_m2k", "film_thickness_m", "backing_effusivity_ws05_m2k", "lag_s",
               "contact_force_fraction"), smoothing=True, drift=True, force_area=True),
)


def candidate(name: str) -> Candidate:
    """A default candidate by label, or the fullest one of a registered model name.

    The fullest one of a model name is the last of :data:`CANDIDATES` for it without the chain
    options ``drift`` and ``force_area`` (those need to be asked for by label: ``force_area`` needs
    a force channel).

    Examples
    --------
    >>> candidate("layered+lag+smoothing").smoothing
    True
    >>> candidate("contact").free
    ('diffusivity_m2_s', 'conductance_w_m2k')
    """
    key = str(name).strip().lower()
    for c in CANDIDATES:
        if c.label == key:
            return c
    fullest = [c for c in CANDIDATES if c.model == key and not (c.drift or c.force_area)]
    if fullest:
        return fullest[-1]
    from ..models import model_class

    labels = ", ".join(dict.fromkeys(c.label for c in CANDIDATES))
    try:
        cls = model_class(key)
    except InputError:  # the registry's error would list models, not what can be identified
        raise InputError(f"no sensor model {name!r} to identify: give one of {labels} (or all)") from None
    raise InputError(f"no identification set up for model {cls.name!r}; candidates: {labels}")


# ------------------------------------------------------------ data
@dataclass(frozen=True)
class _Group:
    """Trials of one material on one time grid: they share one predicted shape."""

    material: int
    time_s: np.ndarray     # (m,)
    y: np.ndarray          # (n, m) sensor [degC]
    to: np.ndarray         # (n,) object temperature [degC] (nan: fitted per touch)
    free_to: bool
    trials: tuple[int, ...]
    affine: bool = False   # To = passive + offset + slope (passive - reference): a rig calibration of the channel
    force: np.ndarray | None = None       # (n, m) force / its plateau, each touch (force-area candidates)
    force_band: np.ndarray | None = None  # (n,) the plateau's noise band of each touch's relative force


@dataclass(frozen=True)
class _Data:
    groups: tuple[_Group, ...]
    names: tuple[str, ...]
    modes: Mapping[str, "str | float"]
    noise_c: float
    sample_rate_hz: float
    n_trials: int
    refs: Mapping[str, float] = field(default_factory=dict)   # reference passive reading of affine materials
    noise_lag: int = 1     # first lag [samples] at which the pre-contact noise's autocorrelation falls below 0.5

    @property
    def n_samples(self) -> int:
        return int(sum(g.y.size for g in self.groups))


def trial_sets(trials: Sequence[Trial], index_csv: Path | str | None = None) -> list[int | None]:
    """Trial set of each trial: the index's ``trial_set`` column, else from ``setNN_`` file names."""
    import re

    by_file: dict[str, int] = {}
    if index_csv is not None:
        from .trials import read_index_rows

        for r in read_index_rows(Path(index_csv)):
            v = (r.get("trial_set") or "").strip()
            if r.get("file") and v.isdigit():
                by_file[r["file"]] = int(v)
    out: list[int | None] = []
    for tr in trials:
        name = Path(tr.source).name
        if name in by_file:
            out.append(by_file[name])
            continue
        m = re.match(r"set(\d+)_", name)
        out.append(int(m.group(1)) if m else None)
    return out


def split_by_trial_set(trials: Sequence[Trial], fit_sets: Sequence[int],
                       index_csv: Path | str | None = None) -> tuple[list[Trial], list[Trial]]:
    """(trials of ``fit_sets``, the others): :func:`choose_split` with the fit sets given."""
    sp = choose_split(trials, index_csv, fit_sets=fit_sets)
    return list(sp.fit), list(sp.held_out)


#: Share of the trial sets present that :func:`choose_split` fits by default (the first ones, at least one):
#: 4 of the shared recordings' 20 sets. A recording without trial
#: sets (one session, touches in order) fits the first half of each material's touches.
FIT_SHARE = 0.2
FIT_SHARE_TOUCH_ORDER = 0.5
#: Touches of each material a recording without trial sets needs before some are held out.
MIN_TOUCHES_TO_HOLD_OUT = 4


@dataclass(frozen=True)
class Split:
    """Disjoint calibration (fitted) and test (held-out) touches, and how they were chosen.

    Attributes
    ----------
    fit, held_out : tuple of Trial
    fit_sets, held_sets : tuple of int
        The trial sets on each side; where the recording has none, the touches' places in their
        material's order (touch k of every material counted as set k).
    by : str
        ``"trial set"`` or ``"touch order"``.
    reason : str
        How the sides were chosen, or why nothing is held out (then ``held_out`` is empty).
    """

    fit: tuple[Trial, ...]
    held_out: tuple[Trial, ...]
    fit_sets: tuple[int, ...]
    held_sets: tuple[int, ...]
    by: str
    reason: str

    def describe(self) -> str:
        """One phrase: 'fitted on trial sets 1-4 (24 touches), scored on sets 5-20 (96)'."""
        what = "trial sets" if self.by == "trial set" else "touch numbers"
        if not self.held_out:
            return f"fitted on all {len(self.fit)} touches, none held out ({self.reason})"
        return (f"fitted on {what} {_ranges_text(self.fit_sets)} ({len(self.fit)} touches), scored on "
                f"{what} {_ranges_text(self.held_sets)} ({len(self.held_out)} touches)")

    def to_dict(self) -> dict[str, Any]:
        return {"by": self.by, "fit_sets": list(self.fit_sets), "held_out_sets": list(self.held_sets),
                "n_fit": len(self.fit), "n_held_out": len(self.held_out), "reason": self.reason}


def _ranges_text(values: Sequence[int]) -> str:
    """``[1, 2, 3, 5]`` -> ``'1-3, 5'``."""
    vals = sorted(set(int(v) for v in values))
    out, i = [], 0
    while i < len(vals):
        j = i
        while j + 1 < len(vals) and vals[j + 1] == vals[j] + 1:
            j += 1
        out.append(f"{vals[i]}" if i == j else f"{vals[i]}-{vals[j]}")
        i = j + 1
    return ", ".join(out)


def choose_split(trials: Sequence[Trial], index_csv: Path | str | None = None,
                 fit_sets: Sequence[int] | None = None, *, require: bool = False,
                 fit_share: float | None = None, sets: Sequence[int | None] | None = None) -> Split:
    """Choose disjoint fitted and held-out touches from the trial sets present.

    Trial sets come from ``sets`` (one per touch, None where unknown) or :func:`trial_sets` (the
    index's ``trial_set`` column or ``setNN_`` file names); a recording without them is split in
    touch order (touch k of each material counts as set k, so sessions recorded one after another
    stay apart). ``fit_sets`` given: those sets are
    fitted and every other set present is held out; otherwise the first ``ceil(fit_share * n)``
    sets of the ``n`` present (at least one; ``fit_share`` by default :data:`FIT_SHARE`, or
    :data:`FIT_SHARE_TOUCH_ORDER` in touch order). Every material must have touches on both sides.

    Where no split exists (one trial set; fewer than :data:`MIN_TOUCHES_TO_HOLD_OUT` touches of a
    material without trial sets; a material only on one side) nothing is held out and ``reason``
    says why, unless ``fit_sets`` is given or ``require`` is set: then a one-line InputError.

    Examples
    --------
    >>> t = np.arange(-200, 400) / 200.0
    >>> trs = [Trial(t, t, t, t, m, f"set{s:02d}_{m}_0.csv") for s in (3, 4, 7, 9, 11) for m in ("a", "b")]
    >>> sp = choose_split(trs)
    >>> sp.fit_sets, sp.held_sets, sp.describe()
    ((3,), (4, 7, 9, 11), 'fitted on trial sets 3 (2 touches), scored on trial sets 4, 7, 9, 11 (8 touches)')
    """
    sets = trial_sets(trials, index_csv) if sets is None else list(sets)
    names = sorted({tr.material for tr in trials})
    if not trials:
        raise InputError("no touches to split")
    if all(s is not None for s in sets):
        by, labels = "trial set", [int(s) for s in sets]
    else:
        by, seen, labels = "touch order", {}, []
        for tr in trials:
            seen[tr.material] = seen.get(tr.material, 0) + 1
            labels.append(seen[tr.material])
    present = sorted(set(labels))
    word = "trial sets" if by == "trial set" else "touch numbers"
    aside = "" if by == "trial set" else " (no trial sets: touch k of each material counts as set k)"

    def refuse(why: str) -> Split:
        if fit_sets is not None or require:
            raise InputError(why)
        return Split(tuple(trials), (), tuple(present), (), by, why)

    if fit_sets is not None:
        keep = sorted(set(int(s) for s in fit_sets))
        unknown = [s for s in keep if s not in present]
        if unknown:
            return refuse(f"--fit-sets names {word} {_ranges_text(unknown)} that the recording does not have "
                          f"(it has {_ranges_text(present)}){aside}")
        held = [s for s in present if s not in keep]
        if not held:
            return refuse(f"fit sets {_ranges_text(keep)} leave no touches to score: the recording has only "
                          f"{word} {_ranges_text(present)}{aside} (leave out --fit-sets, or give 'all' to fit every "
                          "touch)")
        how = f"{word} {_ranges_text(keep)} fitted as asked{aside}, the others held out"
    else:
        if len(names) < 2 and require:
            raise InputError(f"the recording has one material ({names[0]}): a test of recognition needs two")
        if len(present) < 2:
            return refuse(f"the recording has one trial set ({present[0]}): no touches to hold out"
                          if by == "trial set" else "one touch per material: no touches to hold out")
        if by == "touch order":
            few = {n: sum(tr.material == n for tr in trials) for n in names}
            short = [f"{n} ({k})" for n, k in few.items() if k < MIN_TOUCHES_TO_HOLD_OUT]
            if short:
                return refuse(f"no trial sets and fewer than {MIN_TOUCHES_TO_HOLD_OUT} touches of "
                              f"{', '.join(short)}: too few to hold some out")
        if fit_share is None:
            fit_share = FIT_SHARE if by == "trial set" else FIT_SHARE_TOUCH_ORDER
        n_fit = min(len(present) - 1, max(1, math.ceil(fit_share * len(present) - 1e-9)))
        keep, held = present[:n_fit], present[n_fit:]
        how = (f"the first {n_fit} of the {len(present)} {word} present fitted{aside} "
               f"(a share of {fit_share:g}, at least one), the others held out")
    fit = [tr for tr, s in zip(trials, labels) if s in set(keep)]
    out = [tr for tr, s in zip(trials, labels) if s not in set(keep)]
    for side, group in (("fitted", fit), ("held-out", out)):
        missing = [n for n in names if not any(tr.material == n for tr in group)]
        if missing:
            return refuse(f"the {side} {word} {_ranges_text(keep if side == 'fitted' else held)}{aside} "
                          f"have no touches of {', '.join(missing)}")
    return Split(tuple(fit), tuple(out), tuple(keep), tuple(held), by, how)


_OBJECT_MODES = ("passive", "passive-end", "free", "passive-affine", "passive-end-affine")


#: The force is averaged over this window [s] (centred) before it sets the contact area: the force sensor's
#: white noise, clipped where the area is whole, reads the plateau's area low (errors in variables;
#: :data:`FORCE_NOISE_BAND_SD` removes the rest; docs/sensor-models.md). A finger presses over 0.3 s or more:
#: 25 ms rounds only the ramp's corners.
FORCE_SMOOTHING_S = 0.025


def relative_force(trial: Trial) -> np.ndarray:
    """The touch's force divided by its plateau (median from 1 s after the onset), on its grid.

    The force is first averaged over :data:`FORCE_SMOOTHING_S` (a centred moving
    average, :func:`scipy.ndimage.uniform_filter1d`, ends held): a linear ramp
    is unchanged but for its corners.

    Examples
    --------
    >>> t = np.arange(-200, 1000) / 200.0
    >>> tr = Trial(t, np.zeros(t.size), np.zeros(t.size), np.clip(t, 0.0, 1.0) * 4.0, "wood")
    >>> relative_force(tr)[[0, 300, 398, 400, 402]].round(4).tolist()
    [0.0, 0.5, 0.99, 0.997, 1.0]
    """
    t, f = np.asarray(trial.time_s), np.asarray(trial.force_n, dtype=np.float64)
    late = (t >= 1.0) & np.isfinite(f)
    if not late.any() or not np.isfinite(f).all():
        raise InputError(f"trial {trial.source}: a force-driven contact area needs the force channel on every "
                         "sample, to 1 s after the onset or later")
    f = _averaged_force(f, _force_window(trial))
    plateau = float(np.median(f[late]))
    if plateau <= 0:
        raise InputError(f"trial {trial.source}: the force's plateau is {plateau:.3g} N (no contact?)")
    return f / plateau


def _force_window(trial: Trial) -> int:
    """Samples of the :data:`FORCE_SMOOTHING_S` average (odd); InputError on a non-uniform grid."""
    dt = np.diff(np.asarray(trial.time_s))
    if dt.size == 0 or not np.allclose(dt, dt[0], rtol=1e-6, atol=1e-9):
        raise InputError(f"trial {trial.source}: a force-driven contact area needs a uniform time grid")
    return 2 * int(round(0.5 * FORCE_SMOOTHING_S / float(dt[0]))) + 1


def _averaged_force(f: np.ndarray, width: int) -> np.ndarray:
    from scipy.ndimage import uniform_filter1d

    return uniform_filter1d(f, width, mode="nearest") if width > 1 else f


#: The contact area is capped at its whole only where the measured force exceeds its plateau by more than this
#: many SDs of its own noise (:func:`force_noise`). On the plateau the true force *is* the plateau, so half the
#: noisy samples lie above it; capping those at once reads the area low by ``0.4 sigma / (1 - c)`` on average
#: (errors in variables: granite's e_o/e_s +0.20 % in the pty round trips, interval coverage 0.74), a bias that
#: does not shrink with more touches. Within the band the map stays linear, so the noise averages out; beyond
#: it (an overshoot of the press, larger than noise) the cap holds. The bias left is ``sigma psi(-3) / (1 - c)``,
#: a thousandth of the capped map's (``psi(z) = z Phi(z) + phi(z)``); an overshoot reads at most ``3 sigma /
#: (1 - c)`` too much area. Not tuned: three SDs, the usual band of a Gaussian noise. A noise-free force (a
#: smoothed recording) keeps today's map.
FORCE_NOISE_BAND_SD = 3.0


def force_noise(trial: Trial) -> float:
    """SD of the white noise on :func:`relative_force`'s plateau (a share of the plateau force).

    From the force's own residuals: the second differences of the raw force from 1 s
    after the onset (where the plateau is taken), whose spread is ``sqrt(6) sigma``
    for white noise of SD ``sigma`` and hardly feels a slow drift or a ramp's corner
    (median absolute deviation, 1.4826 MAD for a Gaussian), divided by the square
    root of the :data:`FORCE_SMOOTHING_S` average's width and by the plateau. A
    smoothed recording's force reads nearly 0.

    Examples
    --------
    >>> t = np.arange(-200, 1400) / 200.0
    >>> f = np.clip(t, 0.0, 1.0) * 10.0 + 0.02 * np.random.default_rng(0).standard_normal(t.size)
    >>> tr = Trial(t, np.zeros(t.size), np.zeros(t.size), f, "wood")
    >>> round(force_noise(tr) / (0.02 / 10 / 5 ** 0.5), 1)     # 0.02 N on 10 N, averaged over 5 samples
    1.0
    """
    t, f = np.asarray(trial.time_s), np.asarray(trial.force_n, dtype=np.float64)
    late = t >= 1.0
    width = _force_window(trial)
    d2 = np.diff(f[late], 2)
    if d2.size < 10:
        return 0.0
    sigma = 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / math.sqrt(6.0)
    plateau = float(np.median(_averaged_force(f, width)[late]))
    return sigma / math.sqrt(width) / plateau if plateau > 0 else 0.0


def contact_area(force_rel, fraction: float, band=0.0) -> np.ndarray:
    """Share of the final contact area in contact, ``clip((F / F_p - c) / (1 - c), 0, (1 + b - c) / (1 - c))``.

    The forward model's rule (:func:`designkit.models.ramp.area_share`, ``b = 0``) on a
    measured force: the cap applies only beyond the plateau's noise band ``b``
    (:data:`FORCE_NOISE_BAND_SD` times :func:`force_noise`; broadcast against
    ``force_rel``), so the force's noise does not read the plateau's area low.

    Examples
    --------
    >>> contact_area([0.1, 0.3, 0.65, 1.0, 1.002, 1.2], 0.3).round(4).tolist()
    [0.0, 0.0, 0.5, 1.0, 1.0, 1.0]
    >>> contact_area([0.1, 0.3, 0.65, 1.0, 1.002, 1.2], 0.3, band=0.003).round(4).tolist()
    [0.0, 0.0, 0.5, 1.0, 1.0029, 1.0043]
    """
    if np.all(np.asarray(band) == 0):
        return area_share(force_rel, fraction)
    c = float(fraction)
    area_share(0.0, c)  # validates c
    b = np.asarray(band, dtype=np.float64)
    return np.clip((np.asarray(force_rel, dtype=np.float64) - c) / (1.0 - c), 0.0, (1.0 + b - c) / (1.0 - c))


def _prepare(trials: Sequence[Trial], names: Sequence[str], object_temps: Mapping[str, Any],
             moving_passive_c: float = 1.0, refs: Mapping[str, float] | None = None,
             force_area: bool = False) -> _Data:
    """Group trials by material and time grid; decide each material's object temperature."""
    if not trials:
        raise InputError("no trials to fit")
    idx = {n: k for k, n in enumerate(names)}
    modes: dict[str, str] = {}
    info = []
    ssr, dof, rates = 0.0, 0, []
    acf = np.zeros(41)
    for tr in trials:
        pre = tr.time_s < 0
        if pre.sum() < 3:
            raise InputError(f"trial {tr.source}: fewer than 3 samples before contact (time_s < 0)")
        t, s = tr.time_s[pre], tr.sensor_c[pre]
        early = t < t[0] + 0.5 * (t[-1] - t[0]) if t.size >= 20 else np.ones(t.size, bool)
        coef = np.polyfit(t[early], s[early], 1)
        e = s[early] - np.polyval(coef, t[early])
        ssr += float(e @ e)
        lags = min(acf.size, e.size)
        acf[:lags] += [float(e[:e.size - k] @ e[k:]) for k in range(lags)]
        dof += int(early.sum()) - 2
        obj = tr.object_c[pre]
        to = float(np.mean(obj[np.isfinite(obj)])) if np.isfinite(obj).any() else math.nan
        post = tr.object_c[tr.time_s >= 0]
        moved = float(np.nanmax(np.abs(post - to))) if math.isfinite(to) and np.isfinite(post).any() else math.nan
        info.append((to, moved))
        rates.append(1.0 / float(np.median(np.diff(tr.time_s))))
    for n in names:
        mode = object_temps.get(n)
        if mode is None:
            moves = [mv for tr, (_, mv) in zip(trials, info) if tr.material == n and math.isfinite(mv)]
            if not moves:
                raise InputError(f"trials of {n} have no passive (object) channel: give its object temperature "
                                 f"({n}=DEGC, the ambient) or {n}=free")
            mode = "free" if float(np.median(moves)) > moving_passive_c else "passive"
        if isinstance(mode, str) and mode not in _OBJECT_MODES:
            try:
                mode = float(mode)
            except ValueError:
                raise InputError(f"object temperature of {n}: {', '.join(_OBJECT_MODES)} or DEGC, got {mode!r}") \
                    from None
        modes[n] = mode if isinstance(mode, str) else float(mode)
    groups: dict[tuple[int, bytes], list[int]] = {}
    for i, tr in enumerate(trials):
        if tr.material not in idx:
            raise InputError(f"trial {tr.source}: material {tr.material!r} not among {', '.join(names)}")
        ok = np.isfinite(tr.sensor_c)
        if not ok.all():
            raise InputError(f"trial {tr.source}: the sensor channel has missing values")
        groups.setdefault((idx[tr.material], np.round(tr.time_s, 6).tobytes()), []).append(i)
    out = []
    for (k, _), members in groups.items():
        n = names[k]
        mode = modes[n]
        tos = []
        for i in members:
            if mode in ("passive-end", "passive-end-affine"):
                tr = trials[i]
                last = (tr.time_s >= tr.time_s[-1] - 1.0) & np.isfinite(tr.object_c)
                if not last.any():
                    raise InputError(f"trial {tr.source} has no passive reading at its end for {n}={mode}")
                tos.append(float(np.mean(tr.object_c[last])))
            elif mode in ("passive", "passive-affine"):
                if not math.isfinite(info[i][0]):
                    raise InputError(f"trial {trials[i].source} has no passive reading before contact: give "
                                     f"{n}=DEGC")
                tos.append(info[i][0])
            elif mode == "free":
                tos.append(math.nan)
            else:
                tos.append(float(mode))
        out.append(_Group(k, trials[members[0]].time_s.copy(), np.array([trials[i].sensor_c for i in members]),
                          np.array(tos), mode == "free", tuple(members),
                          isinstance(mode, str) and mode.endswith("-affine"),
                          np.array([relative_force(trials[i]) for i in members]) if force_area else None,
                          np.array([FORCE_NOISE_BAND_SD * force_noise(trials[i]) for i in members])
                          if force_area else None))
    noise = math.sqrt(ssr / dof) if dof > 0 else math.nan
    ref = dict(refs or {})
    for n in names:  # the reference reading of an affine channel: the fitted touches' mean (kept for scoring)
        if isinstance(modes[n], str) and modes[n].endswith("-affine") and n not in ref:
            ref[n] = float(np.mean(np.concatenate([g.to for g in out if names[g.material] == n])))
    below = np.flatnonzero(acf < 0.5 * acf[0]) if acf[0] > 0 else np.array([1])
    lag = int(below[0]) if below.size else acf.size
    return _Data(tuple(out), tuple(names), modes, noise, float(np.median(rates)), len(trials), ref, max(lag, 1))


# ------------------------------------------------------------ the problem
def _reading(model, t: np.ndarray, e_object: float, sensor, interp_points: int | None) -> np.ndarray:
    """The model's unsmoothed normalized reading at times ``t > 0``.

    Models solved numerically (``solved_numerically``) are evaluated at
    ``interp_points`` log-spaced times and interpolated by a cubic spline in
    ``log t`` (error below 1e-6 of the temperature difference for smooth
    readings, tested), which makes a residual evaluation cheaper.
    The Talbot inversion uses :data:`FIT_TALBOT_NODES` nodes (error below
    1e-8 of the temperature difference against 32 nodes over the fitted
    parameter range, docs/sensor-models.md; the noise is about 1e-3 of it).
    """
    if not model.solved_numerically:
        return model.conduction(t, [e_object], sensor)[0]
    if not interp_points or t.size <= 2 * interp_points:
        return model.conduction(t, [e_object], sensor, nodes=FIT_TALBOT_NODES)[0]
    from scipy.interpolate import CubicSpline

    # the grid starts at half a sample, not at the smallest t: that moves by a whole sample when the
    # contact offset crosses one, and would make the residual kink there (the optimizer then sticks)
    lo = 0.5 / float(sensor.sample_rate_hz)
    hi = max(float(t.max()), 2.0 * lo)
    grid = np.geomspace(lo, hi, interp_points)
    u = model.conduction(grid, [e_object], sensor, nodes=FIT_TALBOT_NODES)[0]
    out = CubicSpline(np.log(grid), u)(np.log(np.maximum(t, lo)))
    early = t < lo
    if early.any():
        out[early] = model.conduction(t[early], [e_object], sensor, nodes=FIT_TALBOT_NODES)[0]
    return out


def _area_weighted(step, time_s: np.ndarray, area: np.ndarray, offset_s: float) -> np.ndarray:
    """Readings of touches whose contact area grows: ``u_i(t_k) = sum_j dA_ij u(t_k - t_j - offset)``.

    ``step(t)`` is the full-contact reading at times ``t > 0``; ``area`` (n, m)
    the share of the final area in contact at each sample of the uniform grid
    ``time_s`` (what is in contact at the first sample counts from there). A
    discrete convolution (:func:`scipy.signal.fftconvolve`) of the area's
    increments with the step response on the lags of the grid.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(-5, 20) * 0.1
    >>> full = _area_weighted(lambda tt: 1.0 - np.exp(-tt), t, np.ones((1, t.size)) * (t >= 0), 0.0)
    >>> bool(np.allclose(full[0], np.where(t > 0, 1.0 - np.exp(-np.maximum(t, 0.0)), 0.0)))
    True
    """
    from scipy.signal import fftconvolve

    m = time_s.size
    dt = float(time_s[1] - time_s[0])
    # out[k] = sum_j dA_j u(k dt - j dt - offset): only lags k - j in [-(m-1), m-1] with a positive argument
    # matter, so the kernel starts at the first positive one (index i0 on that lag grid) and the convolution
    # is of length about 2m rather than 3m (a third of a fit's time went to this FFT)
    lags = np.arange(-(m - 1), m) * dt - offset_s
    pos = np.flatnonzero(lags > 0)
    if pos.size == 0:
        return np.zeros(area.shape)
    i0 = int(pos[0])
    u1 = step(lags[i0:])
    d_area = np.diff(area, axis=-1, prepend=0.0)
    shift = i0 - (m - 1)                      # out[k] = full[k - shift] of the convolution with u1
    if shift >= m:
        return np.zeros(area.shape)
    u1 = u1[:m - shift]                        # kernel entries needed: k - j - shift <= m - 1 - shift
    full = fftconvolve(d_area, u1[None, :], axes=-1)
    out = np.zeros(area.shape)
    k = np.arange(m)
    src = k - shift
    ok = (src >= 0) & (src < full.shape[-1])
    out[:, ok] = full[:, src[ok]]
    return out


class _Problem:
    """Projected residuals of one candidate on prepared data; x = [model params, t_off, log rho_m]."""

    def __init__(self, cand: Candidate, data: _Data, depth_m: float, offset_bounds_s: tuple[float, float],
                 constrained: np.ndarray, stride: int = 1, touch_conductance: Sequence[str] = ()):
        from ..models import get_model

        self.stride = max(int(stride), 1)   # residual rows: every stride-th sample (shapes on the full grid)

        self.cand = cand
        self.data = data
        self.depth_m = depth_m
        self.params = [_PARAMS[p] for p in cand.free]
        self.n_model = len(self.params)
        self.n_mat = len(data.names)
        self.constrained = constrained
        self._get_model = get_model
        self.interp_points: int | None = 80
        #: materials whose To is the passive reading through a fitted offset and slope: x gets both
        self.affine = [k for k, n in enumerate(data.names) if isinstance(data.modes[n], str)
                       and data.modes[n].endswith("-affine")]
        lo = [p.to_x(p.lo) for p in self.params] + [offset_bounds_s[0]] + [-_LOG_RATIO_LIMIT] * self.n_mat
        hi = [p.to_x(p.hi) for p in self.params] + [offset_bounds_s[1]] + [_LOG_RATIO_LIMIT] * self.n_mat
        lo += [-_AFFINE_OFFSET_C, -_AFFINE_SLOPE] * len(self.affine)
        hi += [_AFFINE_OFFSET_C, _AFFINE_SLOPE] * len(self.affine)
        self.lo, self.hi = np.array(lo), np.array(hi)
        # a material none of whose touches has a known object temperature: its ratio still shapes the
        # curve (not for shared-shape models, where it is not identified at all)
        self.names = [p.name for p in self.params] + ["time_offset_s"] + [f"log_ratio[{n}]" for n in data.names]
        for k in self.affine:
            self.names += [f"passive_offset_c[{data.names[k]}]", f"passive_slope[{data.names[k]}]"]
        # each touch of these materials its own contact conductance: h_c,i = h_c exp(x_i), x_i last in x
        unknown = sorted(set(touch_conductance) - set(data.names))
        if unknown:
            raise InputError(f"per-touch contact conductance for {', '.join(unknown)}: not among the fitted "
                             f"materials {', '.join(data.names)}")
        if touch_conductance and "conductance_w_m2k" not in cand.free:
            raise InputError(f"per-touch contact conductance needs a candidate that fits h_c, not {cand.label}")
        self.touch_cols: dict[int, int] = {}
        self.n_global = len(self.names)
        for gi, g in enumerate(data.groups):
            if data.names[g.material] in touch_conductance:
                self.touch_cols[gi] = len(self.names)
                self.names += [f"log_hc_touch[{data.names[g.material]}#{t}]" for t in g.trials]
        n_touch = len(self.names) - self.n_global
        self.lo = np.concatenate([self.lo, np.full(n_touch, -_LOG_TOUCH_HC)])
        self.hi = np.concatenate([self.hi, np.full(n_touch, _LOG_TOUCH_HC)])

    # -------------------------------------------------------- model
    def model_and_sensor(self, x: np.ndarray):
        from ..sensor import Sensor

        vals = {p.name: p.from_x(v) for p, v in zip(self.params, x[:self.n_model])}
        for k in _CHAIN_PARAMS:
            vals.pop(k, None)
        alpha = vals.pop("diffusivity_m2_s", _SENSOR_DIFF.start)
        sensor = Sensor(effusivity=1.0, diffusivity_m2_s=alpha, depth_m=self.depth_m,
                        sample_rate_hz=self.data.sample_rate_hz, name="identify")
        kw = {k: v for k, v in self.cand.fixed.items()}
        kw.update(vals)
        model = self._get_model(self.cand.model, **kw)
        return model, sensor

    def shapes(self, x: np.ndarray) -> list[np.ndarray]:
        """Predicted normalized reading v of each group on its grid (smoothed when the candidate says)."""
        return [v for v, _ in self.shapes_and_drift(x)]

    def shapes_and_drift(self, x: np.ndarray) -> list[tuple[np.ndarray, np.ndarray | None]]:
        """Per group (v, b): the normalized reading and, with ``drift``, the drift's basis ``t (1 - u)``.

        Both smoothed by the host's filter when the candidate says (the filter is linear: the
        prediction ``Ts0 (1 - v) + s b + To v`` is the smoothed ``(Ts0 + s t)(1 - u) + To u``).
        """
        model, sensor = self.model_and_sensor(x)
        off = x[self.n_model]
        rho = np.exp(x[self.n_model + 1:self.n_model + 1 + self.n_mat])
        out = []
        cache: dict[tuple[int, bytes], tuple[np.ndarray, np.ndarray | None]] = {}
        for g in self.data.groups:
            gi = len(out)
            if gi in self.touch_cols:  # one shape per touch, each with its own h_c
                u = self._touch_shapes(g, model, sensor, off, rho[g.material],
                                       x[self.touch_cols[gi]:self.touch_cols[gi] + len(g.trials)], x)
                out.append(self._chain(g.time_s, u))
                continue
            if g.force is not None:  # one shape per touch: its contact area grows with its own force
                area = self.contact_area(g, x)
                out.append(self._chain(g.time_s, _area_weighted(
                    lambda tt: _reading(model, tt, rho[g.material], sensor, self.interp_points),
                    g.time_s, area, off)))
                continue
            key = (g.material, g.time_s.tobytes())
            if key not in cache:
                tt = g.time_s - off
                u = np.zeros(tt.size)
                pos = tt > 0
                if pos.any():
                    u[pos] = _reading(model, tt[pos], rho[g.material], sensor, self.interp_points)
                cache[key] = self._chain(g.time_s, u)
            out.append(cache[key])
        return out

    def contact_area(self, g: _Group, x: np.ndarray) -> np.ndarray | None:
        """Share of the final contact area (n, m) of a force-area group's touches (None: full contact)."""
        if g.force is None:
            return None
        band = 0.0 if g.force_band is None else g.force_band[:, None]
        return contact_area(g.force, self.params_value(x, "contact_force_fraction", 0.0), band)

    def params_value(self, x: np.ndarray, name: str, default: float) -> float:
        """A free parameter's natural value in ``x`` (``default`` when the candidate does not fit it)."""
        for i, p in enumerate(self.params):
            if p.name == name:
                return p.from_x(x[i])
        return default

    def _chain(self, time_s: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """The measurement chain on unsmoothed readings ``u``: (v, drift basis or None)."""
        b = time_s * (1.0 - u) if self.cand.drift else None
        if self.cand.smoothing:
            from ..models.layered import savgol_smooth

            u = savgol_smooth(u, *HOST_SMOOTHING)
            if b is not None:
                b = savgol_smooth(b, *HOST_SMOOTHING)
        return u, b

    def _touch_shapes(self, g: _Group, model, sensor, off: float, rho: float, log_dev: np.ndarray,
                      x: np.ndarray) -> np.ndarray:
        """Unsmoothed readings (n, m) of a group whose touches each have their own h_c."""
        import dataclasses

        tt = g.time_s - off
        pos = tt > 0
        out = np.zeros((log_dev.size, g.time_s.size))
        area = self.contact_area(g, x)
        for i, d in enumerate(log_dev):
            m = dataclasses.replace(model, conductance_w_m2k=model.conductance_w_m2k * math.exp(float(d)))
            if area is not None:
                out[i] = _area_weighted(lambda t: _reading(m, t, rho, sensor, self.interp_points), g.time_s,
                                        area[i:i + 1], off)[0]
            elif pos.any():
                out[i, pos] = _reading(m, tt[pos], rho, sensor, self.interp_points)
        return out

    def jacobian(self, x: np.ndarray, touch_only: bool = False) -> np.ndarray:
        """Forward differences (step 1e-6 max(1, |x|)); all per-touch columns from one evaluation.

        A touch's residuals depend on its own h_c only (its Ts0 and To are its own), so perturbing
        every touch's h_c at once gives each touch's column on its own rows.
        """
        r0 = self.residuals(x)
        J = np.zeros((r0.size, x.size))
        steps = 1e-6 * np.maximum(1.0, np.abs(x))
        steps = np.where(x + steps > self.hi, -steps, steps)
        for j in range(0 if touch_only else self.n_global):
            xp = x.copy()
            xp[j] += steps[j]
            J[:, j] = (self.residuals(xp) - r0) / steps[j]
        if self.touch_cols:
            xp = x.copy()
            xp[self.n_global:] += steps[self.n_global:]
            d = self.residuals(xp) - r0
            pos = 0
            for gi, g in enumerate(self.data.groups):
                m = self.fitted_y(g).shape[1]
                if gi in self.touch_cols:
                    for i in range(len(g.trials)):
                        j = self.touch_cols[gi] + i
                        J[pos + i * m:pos + (i + 1) * m, j] = d[pos + i * m:pos + (i + 1) * m] / steps[j]
                pos += g.y.shape[0] * m
        return J

    def fitted_y(self, g: _Group) -> np.ndarray:
        """The samples of group ``g`` the residual uses (every ``stride``-th)."""
        return g.y[:, ::self.stride] if self.stride > 1 else g.y

    def project(self, x: np.ndarray):
        """(residuals, per-group linear coefficients): Ts0 (and To where free) in closed form.

        A group's shape is one curve (m,) or one per touch (n, m); the sums run over the last axis.
        """
        res, coefs = [], []
        for g, (v, b) in zip(self.data.groups, self.shapes_and_drift(x)):
            y = self.fitted_y(g)
            v = v[..., ::self.stride]
            a = 1.0 - v
            if b is not None:  # per touch: [Ts0, s] (and To where free) by least squares on its own basis
                b = b[..., ::self.stride]
                n = y.shape[0]
                cols = [np.broadcast_to(a, y.shape), np.broadcast_to(b, y.shape)]
                target = y
                if g.free_to:
                    cols.append(np.broadcast_to(v, y.shape))
                else:
                    to = self.object_temps(g, x)
                    target = y - to[:, None] * v
                B = np.stack(cols, axis=1)                       # (n, k, m)
                G = np.einsum("nkm,nlm->nkl", B, B)
                c = np.linalg.solve(G, np.einsum("nkm,nm->nk", B, target)[..., None])[..., 0]
                if g.free_to:
                    to = c[:, 2]
                pred = np.einsum("nk,nkm->nm", c, B) + (0.0 if g.free_to else to[:, None] * v)
                res.append((pred - y).ravel())
                coefs.append(np.vstack([c[:, 0], np.broadcast_to(to, (n,)), c[:, 1]]))
                continue
            saa = np.sum(a * a, axis=-1)
            if g.free_to:  # per touch: [Ts0, To] from the 2x2 normal equations (well scaled)
                sav, svv = np.sum(a * v, axis=-1), np.sum(v * v, axis=-1)
                ya, yv = np.sum(y * a, axis=-1), np.sum(y * v, axis=-1)
                det = saa * svv - sav * sav
                ts0 = (svv * ya - sav * yv) / det
                to = (saa * yv - sav * ya) / det
            else:
                to = self.object_temps(g, x)
                ts0 = np.sum((y - to[:, None] * v) * a, axis=-1) / saa
            pred = ts0[:, None] * a + to[:, None] * v
            res.append((pred - y).ravel())
            coefs.append(np.vstack([ts0, to]))
        return np.concatenate(res), coefs

    def residuals(self, x):
        return self.project(x)[0]

    def object_temps(self, g: _Group, x: np.ndarray) -> np.ndarray:
        """Each touch's object temperature [degC]: the group's, through the fitted offset and slope if affine."""
        if not g.affine:
            return g.to
        j = self.n_model + 1 + self.n_mat + 2 * self.affine.index(g.material)
        ref = self.data.refs[self.data.names[g.material]]
        return g.to + x[j] + x[j + 1] * (g.to - ref)

    def start(self) -> np.ndarray:
        x = [p.to_x(p.start) for p in self.params] + [0.3]
        return np.array(x + [0.0] * self.n_mat + [0.0, 0.0] * len(self.affine) + [0.0] * (self.lo.size - self.n_global))

    def rows_of(self, k: int) -> np.ndarray:
        """Residual rows of material ``k``."""
        mask = [np.full(self.fitted_y(g).size, g.material == k) for g in self.data.groups]
        return np.concatenate(mask)

    def n_linear(self) -> int:
        per = (2 if self.cand.drift else 1)
        return int(sum(len(g.trials) * (per + (1 if g.free_to else 0)) for g in self.data.groups))


def _initial_ratios(prob: _Problem, x: np.ndarray) -> np.ndarray:
    """Log ratios e_o/e_s from a coarse 1-D search per material (the other parameters at their start)."""
    x = x.copy()
    for k in range(prob.n_mat):
        best = None
        for lr in np.linspace(-6.0, 6.0, 25):
            x[prob.n_model + 1 + k] = lr
            r = prob.residuals(x)
            sse = float(np.sum(r[prob.rows_of(k)] ** 2))
            if best is None or sse < best[0]:
                best = (sse, lr)
        x[prob.n_model + 1 + k] = best[1]
    return x


# ------------------------------------------------------------ results
@dataclass(frozen=True)
class IdentifiedParameter:
    """An identified quantity: value, 95 % interval, unit, and whether the data identify it.

    ``identifiable`` is False when the Jacobian is rank-deficient along it, its
    interval spans more than a factor of 10 (positive quantities) or it sits
    on a search bound (``note`` says which).
    """

    name: str
    value: float
    ci95: tuple[float, float]
    unit: str = ""
    identifiable: bool = True
    note: str = ""

    def interval(self) -> dict[str, float]:
        """The 95 % interval in the schema's shape (docs/schema.md, ``interval``): ``{low, high, coverage}``."""
        return {"low": float(self.ci95[0]), "high": float(self.ci95[1]), "coverage": 0.95}

    def to_dict(self) -> dict[str, Any]:
        """The schema's shape (docs/schema.md): ``interval: {low, high, coverage}``, ``identifiable`` a bool."""
        return {"name": self.name, "value": self.value, "interval": self.interval(),
                "unit": self.unit, "identifiable": bool(self.identifiable), "note": self.note}


@dataclass(frozen=True)
class Identification:
    """What :func:`identify` found for one candidate.

    Attributes
    ----------
    candidate : Candidate
    parameters : tuple of IdentifiedParameter
        Sensor and model parameters in physical units (e_s from the ranges,
        effusivities and h_c scaled by it), the time offset, and each
        material's e_o.
    ratios : dict
        ``e_o / e_s`` per material (IdentifiedParameter).
    effusivity : IdentifiedParameter or None
        e_s; None where no material constrains it.
    consistent : bool or None
        One e_s keeps every constrained material within its handbook range
        (None: no ranges given).
    es_allowed : dict
        Per material, the e_s interval its range allows (with the ratio's 95 % interval).
    rms_c : float
        Residual RMS on the fitted touches [degC].
    rms_by_material_c : dict
    n_samples, n_parameters : int
        Samples fitted; parameters (nonlinear + each touch's linear ones).
    aic, bic : float
        Gaussian information criteria on the fitted samples.
    rank, n_nonlinear : int
        Numerical rank of the scaled Jacobian of the nonlinear parameters, and their number.
    singular_values : ndarray
    fit_time_s : float
    x : ndarray
        The transformed parameter vector (for :func:`score`).
    notes : tuple of str
    """

    candidate: Candidate
    parameters: tuple[IdentifiedParameter, ...]
    ratios: Mapping[str, IdentifiedParameter]
    effusivity: IdentifiedParameter | None
    consistent: bool | None
    es_allowed: Mapping[str, tuple[float, float]]
    rms_c: float
    rms_by_material_c: Mapping[str, float]
    n_samples: int
    n_parameters: int
    aic: float
    bic: float
    rank: int
    n_nonlinear: int
    singular_values: np.ndarray
    fit_time_s: float
    noise_c: float
    x: np.ndarray
    names: tuple[str, ...]
    depth_m: float
    sample_rate_hz: float
    object_modes: Mapping[str, "str | float"]
    notes: tuple[str, ...] = ()
    object_refs: Mapping[str, float] = field(default_factory=dict)
    touch_conductance: tuple[str, ...] = ()
    force_profile: Mapping[str, Any] | None = None
    #: the rig's operating conditions in the fitted touches (:func:`designkit.rig.rig_conditions`, as a dict)
    conditions: Mapping[str, Any] | None = None

    def parameter(self, name: str) -> IdentifiedParameter:
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(name)

    def model(self):
        """The identified forward model in physical units (e_s from the ranges; smoothing when fitted with it)."""
        from ..models import get_model

        es = self.effusivity.value if self.effusivity is not None else 1.0
        kw = dict(self.candidate.fixed)
        for p in self.parameters:
            if p.name in _PARAMS and p.name != "diffusivity_m2_s" and p.name not in _CHAIN_PARAMS:
                kw[p.name] = p.value
        for k, v in list(kw.items()):
            if k in _PARAMS and _PARAMS[k].scale_with_es and k not in {p.name for p in self.parameters}:
                kw[k] = v * es
        if self.candidate.smoothing and self.candidate.model == "layered":
            kw["smoothing_window"], kw["smoothing_order"] = HOST_SMOOTHING
        return get_model(self.candidate.model, **kw)

    def reading(self, time_s, material: str, *, conductance_factor=None, force=None, force_time_s=None,
                drift: bool = False, force_band=0.0):
        """The identified normalized reading ``v`` of ``material`` at times after the detected onset.

        ``T = Ts0 + (To - Ts0) v`` (``+ s b`` for a candidate with ``drift``): with the fitted time
        offset and, for a candidate with the host smoothing, smoothed as the host smoothed a
        recording (1 s before contact to 7 s after, or to the last time).

        Parameters
        ----------
        time_s : array_like, shape (m,)
            Times after the detected onset [s], uniformly sampled at the fit's rate.
        material : str
            A fitted material (its e_o / e_s).
        conductance_factor : array_like of float, shape (k,), optional
            Multiplies h_c (a touch's own contact, e.g. drawn from the fitted per-touch spread);
            one reading per factor.
        force : array_like, shape (k, p), optional
            For a ``force_area`` candidate: each simulated touch's force divided by its plateau
            (:func:`relative_force`) on ``force_time_s`` (held at its end values outside it); one
            reading per row. Without it a ``force_area`` candidate reads as full contact from the
            offset on.
        force_time_s : array_like, shape (p,), optional
            Times of ``force`` after the detected onset [s].
        force_band : float or array_like, shape (k,)
            Each ``force`` row's noise band (:func:`contact_area`): for a measured force
            ``FORCE_NOISE_BAND_SD * force_noise(trial)``, as the fit reads it; 0 (default) caps the
            area at the plateau, right for a noise-free or smoothed force.
        drift : bool
            Also return the drift basis ``b`` (smoothed ``t (1 - u)``, see :class:`Candidate`).

        Returns
        -------
        ndarray, shape (m,) or (k, m); with ``drift`` a pair (v, b) of them.
        """
        import dataclasses

        from ..models.layered import savgol_smooth

        if material not in self.ratios:
            raise InputError(f"no identified material {material!r} (fitted: {', '.join(self.ratios)})")
        t = np.asarray(time_s, dtype=np.float64)
        fs = self.sample_rate_hz
        k0 = int(math.floor(min(-1.0, float(t.min())) * fs))
        k1 = int(math.ceil(max(7.0, float(t.max())) * fs))
        grid = np.arange(k0, k1 + 1) / fs
        es = self.effusivity.value if self.effusivity is not None else 1.0
        model = self.model()
        if self.candidate.smoothing and hasattr(model, "smoothing_window"):
            model = dataclasses.replace(model, smoothing_window=0)
        sensor = self.sensor()
        eo = self.ratios[material].value * es
        off = self.parameter("time_offset_s").value
        tt = grid - off
        pos = tt > 0
        factors = [None] if conductance_factor is None else list(np.atleast_1d(conductance_factor))
        areas = [None]
        if force is not None and self.candidate.force_area:
            if force_time_s is None:
                raise InputError("reading: force needs force_time_s")
            ft = np.asarray(force_time_s, dtype=np.float64)
            c = self.parameter("contact_force_fraction").value if "contact_force_fraction" in self.candidate.free \
                else 0.0
            rows = np.atleast_2d(force)
            bands = np.broadcast_to(np.asarray(force_band, dtype=np.float64), (rows.shape[0],))
            areas = [contact_area(np.interp(grid, ft, row), c, b) for row, b in zip(rows, bands)]
        n = max(len(factors), len(areas))
        if len(factors) not in (1, n) or len(areas) not in (1, n):
            raise InputError(f"reading: {len(factors)} conductance factors and {len(areas)} force rows")
        out = np.zeros((n, grid.size))
        for i in range(n):
            f, area = factors[i % len(factors)], areas[i % len(areas)]
            m = model if f is None else dataclasses.replace(model, conductance_w_m2k=model.conductance_w_m2k * f)

            def step(tp, m=m):
                return m.conduction(tp, [eo], sensor)[0]

            if area is not None:
                out[i] = _area_weighted(step, grid, area[None, :], off)[0]
            elif pos.any():
                out[i, pos] = step(tt[pos])
        b = grid * (1.0 - out)
        if self.candidate.smoothing:
            out = savgol_smooth(out, *HOST_SMOOTHING)
            b = savgol_smooth(b, *HOST_SMOOTHING)
        single = conductance_factor is None and (force is None or np.ndim(force) == 1)
        res = np.array([np.interp(t, grid, row) for row in out])
        res = res[0] if single else res
        if not drift:
            return res
        bres = np.array([np.interp(t, grid, row) for row in b])
        return res, (bres[0] if single else bres)

    def sensor(self, name: str = "identified"):
        """The identified :class:`~designkit.sensor.Sensor` (e_s from the ranges, alpha_s at the fixed depth)."""
        from ..sensor import Sensor

        from ..rig import record_start_s

        es = self.effusivity.value if self.effusivity is not None else 1.0
        alpha = self.parameter("diffusivity_m2_s").value if "diffusivity_m2_s" in self.candidate.free \
            else _SENSOR_DIFF.start
        record = self.model_record()
        conditions = None
        if self.conditions is not None:
            start = record_start_s(record)
            conditions = {**dict(self.conditions), "onset_offset_s": None if start is None else round(start, 4)}
        return Sensor(effusivity=es, diffusivity_m2_s=alpha, depth_m=self.depth_m,
                      sample_rate_hz=self.sample_rate_hz, name=name, noise_c=self.noise_c,
                      provenance={"method": f"designkit.calibration.identify ({self.candidate.label})",
                                  "rms_c": self.rms_c, "consistent": self.consistent,
                                  "parameters": [p.to_dict() for p in self.parameters],
                                  "notes": list(self.notes)},
                      model=record, conditions=conditions)

    def model_record(self) -> dict[str, Any]:
        """What a sensor file records of the identified model (:data:`designkit.sensor.MODEL_KEYS`).

        ``params``: the model's fields in physical units (effusivities and h_c
        scaled by the identified e_s; the host smoothing when fitted with it);
        ``contact_spread``: per material fitted with per-touch conductances, the
        geometric standard deviation of the touches' h_c,i; ``object_temperature``:
        how each material's temperature was taken (passive, free, a number);
        ``contact_area`` (a ``force_area`` candidate): the threshold c
        (``force_fraction``, its 95 % interval ``force_fraction_interval``) and the fitted touches' median
        force over its plateau (:func:`nominal_force_profile`), which questions
        play as the nominal ramp; ``drift`` (a ``drift`` candidate):
        ``"per-touch"``, a nuisance fitted for each touch, not a sensor property.
        """
        spread = {}
        for p in self.parameters:
            if p.name.startswith("conductance_spread[") and math.isfinite(p.value):
                spread[p.name[len("conductance_spread["):-1]] = float(p.value)
        return {"name": self.candidate.model, "params": self.model().parameters(),
                "time_offset_s": float(self.parameter("time_offset_s").value),
                "contact_spread": spread or None,
                "object_temperature": {k: (v if isinstance(v, str) else float(v))
                                       for k, v in self.object_modes.items()},
                "candidate": self.candidate.label,
                "contact_area": self._contact_area_record(),
                "drift": "per-touch" if self.candidate.drift else None}

    def _contact_area_record(self) -> dict[str, Any] | None:
        if not self.candidate.force_area or self.force_profile is None:
            return None
        if "contact_force_fraction" in self.candidate.free:
            p = self.parameter("contact_force_fraction")
            c, ci = float(p.value), p.interval()
        else:
            c, ci = 0.0, None
        return {"force_fraction": c, "force_fraction_interval": ci, **dict(self.force_profile)}

    def to_dict(self) -> dict[str, Any]:
        return {
            "candidate": self.candidate.label, "model": self.model().to_dict(),
            "parameters": [p.to_dict() for p in self.parameters],
            "ratios": {k: v.to_dict() for k, v in self.ratios.items()},
            "effusivity": None if self.effusivity is None else self.effusivity.to_dict(),
            "consistent": self.consistent,
            "es_allowed": {k: list(v) for k, v in self.es_allowed.items()},
            "rms_c": self.rms_c, "rms_by_material_c": dict(self.rms_by_material_c),
            "n_samples": self.n_samples, "n_parameters": self.n_parameters, "aic": self.aic, "bic": self.bic,
            "rank": self.rank, "n_nonlinear": self.n_nonlinear,
            "singular_values": [float(v) for v in self.singular_values], "fit_time_s": self.fit_time_s,
            "noise_c": self.noise_c, "object_temperature": dict(self.object_modes), "object_reference_c": dict(self.object_refs),
            "notes": list(self.notes), "force_profile": None if self.force_profile is None else dict(self.force_profile),
            "conditions": None if self.conditions is None else dict(self.conditions),
        }


def _exp(v: float) -> float:
    """exp that saturates at the float range instead of raising."""
    return math.exp(min(max(float(v), -700.0), 700.0)) if math.isfinite(v) else (math.inf if v > 0 else 0.0)


def _sandwich(J: np.ndarray, r: np.ndarray, clusters: np.ndarray,
              df_columns: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Cluster-robust covariance (touches as clusters), bias-reduced (CR2), and each parameter's t degrees of freedom.

    ``V = B (sum_g J_g' A_g r_g r_g' A_g J_g) B`` with ``B = (J'J)^+`` and
    ``A_g = (I - H_gg)^(-1/2)``, ``H_gg = J_g B J_g'`` the touch's block of the
    hat matrix (Bell & McCaffrey, Survey Methodology 28 (2002) 169; Imbens &
    Kolesar, Rev. Econ. Stat. 98 (2016) 701): the residuals of a touch that
    weighs much in a parameter are shrunk by the fit, and ``A_g`` undoes it
    (CR2); the plain sandwich, even with the CR1 factor
    ``G/(G-1) (N-1)/(N-K)`` used before, is biased low then. Directions a touch
    determines alone (its own contact conductance, ``H_gg`` eigenvalue 1) take
    the Moore-Penrose inverse (their residual is orthogonal to them anyway).

    The degrees of freedom of parameter k's t quantile are Bell and McCaffrey's
    Satterthwaite approximation ``(sum lambda)^2 / sum lambda^2``, lambda the
    eigenvalues of ``G' G``, whose column g is ``(I - H) E_g A_g J_g B e_k``
    (``E_g`` puts touch g's rows in place; working model: white residuals). A
    parameter that a few touches carry gets few degrees of freedom, not
    touches - 1: the force-area threshold c is carried by the granite touches,
    and among them by those of extreme press speed (df about 7 of 19 in the pty
    round trips, docs/sensor-models.md). scipy and statsmodels offer only the
    CR0/CR1 sandwich; this is written out (low-rank ``H_gg``: a thin QR per
    touch, no m x m matrix).

    Parameters
    ----------
    J : ndarray, shape (N, K)
        Jacobian of the residuals at the estimate.
    r : ndarray, shape (N,)
        Residuals.
    clusters : ndarray of int, shape (N,)
        Each residual's touch.
    df_columns : int, optional
        Degrees of freedom are computed for the first ``df_columns`` parameters
        (default all); the others get ``G - 1``.

    Returns
    -------
    cov : ndarray, shape (K, K)
    df : ndarray, shape (K,)
        In ``[1, G - 1]``.

    Examples
    --------
    A mean (one column of ones) on 6 touches of 20 samples: every touch has
    leverage 1/6, so CR2 is the sum of squared touch scores times G/(G-1)
    and the degrees of freedom are G - 1 = 5 exactly.

    >>> rng = np.random.default_rng(0)
    >>> cl, r = np.repeat(np.arange(6), 20), rng.normal(size=120)
    >>> cov, df = _sandwich(np.ones((120, 1)), r, cl)
    >>> sums = np.bincount(cl, weights=r)
    >>> bool(np.isclose(cov[0, 0], 6 / 5 * np.sum(sums ** 2) / 120 ** 2)), round(float(df[0]), 6)
    (True, 5.0)
    """
    n, k = J.shape
    groups, idx = np.unique(clusters, return_inverse=True)
    g_n = groups.size
    B = np.linalg.pinv(J.T @ J)
    order = np.argsort(idx, kind="stable")
    bounds = np.searchsorted(idx[order], np.arange(g_n + 1))
    scores = np.zeros((g_n, k))
    blocks = []
    for g in range(g_n):
        rows = order[bounds[g]:bounds[g + 1]]
        Jg = J[rows]
        Q, R = np.linalg.qr(Jg)                      # H_gg = Q (R B R') Q'
        lam, V = np.linalg.eigh(R @ B @ R.T)
        U = Q @ V
        one = lam > 1.0 - 1e-8
        adj = np.where(one, -1.0, 1.0 / np.sqrt(np.clip(1.0 - lam, 1e-300, None)) - 1.0)
        rg = r[rows]
        scores[g] = Jg.T @ (rg + U @ (adj * (U.T @ rg)))
        blocks.append((rows, Jg, U, adj))
    cov = B @ (scores.T @ scores) @ B
    df = np.full(k, float(max(g_n - 1, 1)))
    for j in range(k if df_columns is None else min(int(df_columns), k)):
        l = B[:, j]
        if not np.any(l):
            continue
        # G'G = W'(I - H)W = diag(w_g'w_g) - (W'J) B (J'W), column g of W being E_g A_g J_g B e_j
        diag = np.zeros(g_n)
        wj = np.zeros((g_n, k))
        for g, (rows, Jg, U, adj) in enumerate(blocks):
            w = Jg @ l
            w = w + U @ (adj * (U.T @ w))
            diag[g] = w @ w
            wj[g] = w @ Jg
        lam = np.linalg.eigvalsh(np.diag(diag) - wj @ B @ wj.T)
        lam = np.clip(lam, 0.0, None)
        if lam.sum() > 0:
            df[j] = float(np.clip(lam.sum() ** 2 / np.sum(lam ** 2), 1.0, max(g_n - 1, 1)))
    return cov, df


def _critical(df) -> "float | np.ndarray":
    """Two-sided 95 % quantile of Student's t with ``df`` degrees of freedom (from :func:`_sandwich`):
    2.36 for 7, 2.09 for 19, 1.96 in the limit.

    >>> round(float(_critical(7)), 2)
    2.36
    """
    from scipy.stats import t

    return t.ppf(0.975, np.maximum(df, 1.0))


def _clusters(data: _Data, stride: int = 1) -> np.ndarray:
    out = []
    for g in data.groups:
        m = g.y[:, ::stride].shape[1]
        out.append(np.repeat(np.asarray(g.trials), m))
    return np.concatenate(out)


def identify(trials: Sequence[Trial], model: "str | Candidate" = "layered+lag+smoothing", *,
             ranges: Mapping[str, Any] | None = None, object_temps: Mapping[str, Any] | None = None,
             depth_m: float = 80e-6, offset_bounds_s: tuple[float, float] = (-1.5, 1.5),
             start: Mapping[str, float] | None = None, x0: np.ndarray | None = None,
             max_nfev: int = 100, fit_rate_hz: "float | str | None" = "auto",
             touch_conductance: Sequence[str] = ()) -> Identification:
    """Fit one candidate model to touches.

    Parameters
    ----------
    trials : sequence of Trial
        Touches (time 0 = detected contact onset, samples before it).
    model : str or Candidate
        A label of :data:`CANDIDATES` or a registered model name (its fullest candidate).
    ranges : mapping material -> MaterialRange (or (e_min, e_max)), optional
        Handbook effusivity ranges [J s^-1/2 K^-1 m^-2]; they set e_s's scale.
    object_temps : mapping, optional
        Per material ``"passive"``, ``"free"`` or a temperature [degC]; by
        default the passive channel, or ``"free"`` when it moves in contact.
    depth_m : float
        Thermistor depth [m], fixed (only x^2/alpha_s is identifiable).
    offset_bounds_s : (float, float)
        Search range of the contact-time offset [s].
    start : mapping, optional
        Starting values of free parameters (physical units; effusivities and
        h_c as ratios to e_s).
    x0 : ndarray, optional
        A transformed start vector (from another fit's ``x``).
    max_nfev : int
        Most residual evaluations of the optimizer.
    fit_rate_hz : float, "auto" or None
        The least-squares fit uses every k-th sample, ``k = round(fs /
        fit_rate_hz)`` (None: every sample; ``"auto"``: k = the lag at which
        the pre-contact noise's autocorrelation falls below 0.5, so white
        noise keeps every sample). The model's shapes (and the host
        smoothing) are still computed on the full grid, and the reported
        RMS, AIC and BIC are of the full grid. A host-smoothed recording gets
        a stride of several samples (docs/sensor-models.md). The
        cluster-robust covariance does not depend on the stride.
    touch_conductance : sequence of str
        Materials whose touches each get their own contact conductance
        ``h_c,i = h_c exp(d_i)`` (a per-touch nuisance: contact area and
        pressure differ from touch to touch); needs a candidate fitting h_c.
        Held-out touches of them get their own ``d_i`` fitted in :func:`score`.

    Returns
    -------
    Identification
    """
    from scipy.optimize import least_squares

    from ..rig import rig_conditions

    t0 = time.perf_counter()
    cand = model if isinstance(model, Candidate) else candidate(model)
    names = tuple(sorted({tr.material for tr in trials}))
    data = _prepare(trials, names, dict(object_temps or {}), force_area=cand.force_area)
    rng = {n: _as_range(ranges[n]) for n in names if ranges and n in ranges}
    constrained = np.array([n in rng and data.modes[n] != "free" for n in names])
    if fit_rate_hz == "auto":
        stride = data.noise_lag
    else:
        stride = 1 if not fit_rate_hz else max(1, int(round(data.sample_rate_hz / float(fit_rate_hz))))
    prob = _Problem(cand, data, depth_m, offset_bounds_s, constrained, stride=stride,
                    touch_conductance=tuple(touch_conductance))
    if x0 is None:
        x = prob.start()
        for k, v in dict(start or {}).items():
            if k == "time_offset_s":
                x[prob.n_model] = float(v)
            elif k in cand.free:
                x[cand.free.index(k)] = _PARAMS[k].to_x(float(v))
        x = _initial_ratios(prob, x)
    else:
        x = np.asarray(x0, dtype=np.float64)[:prob.n_global].copy()
    x = np.concatenate([x[:prob.n_global], np.zeros(prob.lo.size - prob.n_global)])
    x = np.clip(x, prob.lo + 1e-9, prob.hi - 1e-9)
    with _one_blas_thread():  # tall, thin SVDs: threads only contend
        jac = dict(jac=prob.jacobian) if prob.touch_cols else dict(diff_step=1e-6)
        sol = least_squares(prob.residuals, x, bounds=(prob.lo, prob.hi), method="trf", x_scale="jac",
                            xtol=1e-8, ftol=1e-8, gtol=1e-8, max_nfev=max_nfev, **jac)
    x = sol.x
    r = sol.fun
    J = sol.jac
    # ------------------------------------------------ identifiability
    norms = np.linalg.norm(J, axis=0)
    Js = J / np.where(norms > 0, norms, 1.0)
    sv = np.linalg.svd(Js, compute_uv=False)
    rank = int(np.sum(sv > sv[0] * 1e-6)) if sv.size else 0
    _, _, vt = np.linalg.svd(Js, full_matrices=False)
    weak = set()
    for j in range(rank, len(sv)):
        weak |= {int(i) for i in np.flatnonzero(np.abs(vt[j]) > 0.3)}
    weak |= {int(i) for i in np.flatnonzero(norms == 0)}
    clusters = _clusters(data, prob.stride)
    cov, dof = _sandwich(J, r, clusters, df_columns=prob.n_global)
    q = _critical(dof)   # per parameter, the 95 % intervals' half-width in standard errors
    if prob.stride > 1:  # fit quality on every sample
        prob.stride = 1
        r = prob.residuals(x)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    at_bound = (np.abs(x - prob.lo) < 1e-6) | (np.abs(x - prob.hi) < 1e-6)
    # ------------------------------------------------ e_s from the ranges
    ratios: dict[str, IdentifiedParameter] = {}
    allowed: dict[str, tuple[float, float]] = {}
    point_lo, point_hi, wide_lo, wide_hi = [], [], [], []
    for k, n in enumerate(names):
        j = prob.n_model + 1 + k
        lr, s = x[j], sd[j]
        qm = q[j]   # mostly its own touches inform it: its degrees of freedom say how many
        ident = j not in weak and not at_bound[j] and 2 * qm * s < math.log(10.0)
        why = ("at the search limit: the touches ask for the full temperature difference (e_o/e_s -> inf)"
               if lr > 0 and at_bound[j] else "at the search limit (e_o/e_s -> 0)" if at_bound[j]
               else "95 % interval wider than a factor of 10" if not ident else "")
        ratios[n] = IdentifiedParameter(f"e_o/e_s[{n}]", _exp(lr), (_exp(lr - qm * s), _exp(lr + qm * s)),
                                        "", ident, why)
        if constrained[k]:
            e_lo, e_hi = rng[n]
            allowed[n] = (e_lo / _exp(lr + qm * s), e_hi / _exp(lr - qm * s))
            point_lo.append(math.log(e_lo) - lr)
            point_hi.append(math.log(e_hi) - lr)
            wide_lo.append(math.log(min(max(allowed[n][0], 1e-300), 1e300)))
            wide_hi.append(math.log(min(max(allowed[n][1], 1e-300), 1e300)))
    notes: list[str] = []
    es_p: IdentifiedParameter | None = None
    consistent: bool | None = None
    if point_lo:
        a, b = max(point_lo), min(point_hi)
        wa, wb = max(wide_lo), min(wide_hi)
        consistent = bool(wa <= wb)
        if a <= b:
            les = 0.5 * (a + b)
            note = "set-identified: every e_s in the interval keeps all materials in range"
        elif consistent:
            les = 0.5 * (wa + wb)
            note = "the ranges touch only within the ratios' uncertainty"
        else:
            les = 0.5 * (a + b)
            note = "conflict: no e_s keeps every material in its range"
        ci = (_exp(wa), _exp(wb)) if consistent else (math.nan, math.nan)
        es_p = IdentifiedParameter("effusivity", _exp(les), ci, "J s^-1/2 K^-1 m^-2", consistent, note)
        if not consistent:
            notes.append("the materials' ranges conflict under this model: " + "; ".join(
                f"{n} allows e_s in [{lo:.4g}, {hi:.4g}]" for n, (lo, hi) in allowed.items()))
    es = es_p.value if es_p is not None else 1.0
    es_ci = es_p.ci95 if es_p is not None and consistent else (es, es)
    # ------------------------------------------------ parameters in physical units
    params: list[IdentifiedParameter] = []
    for i, p in enumerate(prob.params):
        v = p.from_x(x[i])
        lo, hi = p.from_x(x[i] - q[i] * sd[i]), p.from_x(x[i] + q[i] * sd[i])
        if p.scale_with_es:
            v, lo, hi = v * es, lo * es_ci[0], hi * es_ci[1]
        why = []
        if i in weak:
            why.append("Jacobian rank-deficient along it")
        if at_bound[i]:
            why.append("at a search bound")
        if p.log and 2 * q[i] * sd[i] > math.log(10.0):
            why.append("95 % interval wider than a factor of 10")
        params.append(IdentifiedParameter(p.name, v, (lo, hi), p.unit, not why, "; ".join(why)))
    j = prob.n_model
    params.append(IdentifiedParameter("time_offset_s", float(x[j]), (x[j] - q[j] * sd[j], x[j] + q[j] * sd[j]),
                                      "s", j not in weak and not at_bound[j]))
    for k, n in enumerate(names):
        rp = ratios[n]
        params.append(IdentifiedParameter(f"e_o[{n}]", rp.value * es, (rp.ci95[0] * es_ci[0], rp.ci95[1] * es_ci[1]),
                                          "J s^-1/2 K^-1 m^-2", rp.identifiable, rp.note))
    for gi, j0 in prob.touch_cols.items():
        g = data.groups[gi]
        d = x[j0:j0 + len(g.trials)]
        n = names[g.material]
        sdl = float(np.std(d, ddof=1)) if d.size > 1 else math.nan
        hc = _PARAMS["conductance_w_m2k"].from_x(x[prob.params.index(_PARAMS["conductance_w_m2k"])]) * es
        inside = bool(np.all(~at_bound[j0:j0 + d.size]))
        params.append(IdentifiedParameter(
            f"conductance_w_m2k[{n} touches]", hc * _exp(float(np.mean(d))),
            (hc * _exp(float(np.min(d))), hc * _exp(float(np.max(d)))), "W m^-2 K^-1", inside,
            "geometric mean of the touches' own h_c,i; interval: their smallest and largest (not a CI)"))
        params.append(IdentifiedParameter(
            f"conductance_spread[{n}]", _exp(sdl) if math.isfinite(sdl) else math.nan,
            (math.nan, math.nan), "factor", inside, "geometric standard deviation of the touches' h_c,i"))
    for i, k in enumerate(prob.affine):
        for j, name, unit in ((prob.n_model + 1 + prob.n_mat + 2 * i, "passive_offset_c", "degC"),
                              (prob.n_model + 2 + prob.n_mat + 2 * i, "passive_slope", "")):
            ok = j not in weak and not at_bound[j]
            params.append(IdentifiedParameter(
                f"{name}[{names[k]}]", float(x[j]), (x[j] - q[j] * sd[j], x[j] + q[j] * sd[j]), unit, ok,
                "" if ok else "at a search bound or rank-deficient"))
    # ------------------------------------------------ fit quality
    res_by: dict[str, list[np.ndarray]] = {n: [] for n in names}
    pos = 0
    for g in data.groups:
        res_by[names[g.material]].append(r[pos:pos + g.y.size])
        pos += g.y.size
    rms_by = {n: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) for n, v in res_by.items() if v}
    n_s = r.size
    k_par = x.size + prob.n_linear()
    ssr = float(r @ r)
    aic = n_s * math.log(ssr / n_s) + 2 * k_par
    bic = n_s * math.log(ssr / n_s) + k_par * math.log(n_s)
    if rank < x.size:
        notes.append(f"the Jacobian has rank {rank} of {x.size}: "
                     + ", ".join(prob.names[i] for i in sorted(weak)) + " not separately identified")
    if "diffusivity_m2_s" in cand.free:
        notes.append(f"alpha_s is identified at the fixed thermistor depth x = {depth_m * 1e6:g} um "
                     "(only x^2/alpha_s matters)")
    return Identification(cand, tuple(params), ratios, es_p, consistent, allowed, float(np.sqrt(np.mean(r ** 2))),
                          rms_by, n_s, k_par, aic, bic, rank, x.size, sv, time.perf_counter() - t0,
                          data.noise_c, x, names, depth_m, data.sample_rate_hz, dict(data.modes), tuple(notes),
                          dict(data.refs), tuple(touch_conductance),
                          nominal_force_profile(data) if cand.force_area else None,
                          rig_conditions(trials, pre_contact_noise_c=data.noise_c,
                                         residual_rms_c=float(np.sqrt(np.mean(r ** 2))),
                                         onset_offset_s=math.nan, residuals=_touch_rows(data, r),
                                         sample_rate_hz=data.sample_rate_hz).to_dict())


def _touch_rows(data: "_Data", r: np.ndarray) -> list[np.ndarray]:
    """The residual ``r`` (groups one after the other, each touch a row) cut into one series per touch."""
    rows, pos = [], 0
    for g in data.groups:
        rows.extend(r[pos:pos + g.y.size].reshape(g.y.shape))
        pos += g.y.size
    return rows


#: The nominal force ramp a sensor file records: F / F_p from 1 s before the onset to 1.5 s after, every 20 ms.
FORCE_PROFILE_S = (-1.0, 1.5, 0.02)


def nominal_force_profile(data: "_Data | Sequence[Trial]") -> dict[str, Any]:
    """The median over touches of the force over its plateau (:func:`relative_force`), after the onset.

    What a question plays for a ``force_area`` model (it has no force trace of its
    own): ``{"time_s": [...], "force_share": [...], "n_touches": n, "touch_force_share": [[...], ...]}`` (the
    median, and each touch's own, from which a simulated touch draws its press) on
    :data:`FORCE_PROFILE_S`. The median of the area shares is the area share of
    the median force (the share is a non-decreasing function of the force). The share is 0.006, not 0, at the
    onset below: the force is averaged over :data:`FORCE_SMOOTHING_S`, which rounds the foot of the ramp.

    Examples
    --------
    >>> t = np.arange(-200, 1000) / 200.0
    >>> trs = [Trial(t, np.zeros(t.size), np.zeros(t.size), np.clip(t / r, 0.0, 1.0) * 4.0, "wood")
    ...        for r in (0.4, 0.5, 0.6)]
    >>> p = nominal_force_profile(trs)
    >>> p["n_touches"], p["time_s"][50:53], p["force_share"][50:53]
    (3, [0.0, 0.02, 0.04], [0.006, 0.04, 0.08])
    """
    lo, hi, step = FORCE_PROFILE_S
    grid = np.round(np.arange(round((hi - lo) / step) + 1) * step + lo, 9)
    if isinstance(data, _Data):
        rows = [np.interp(grid, g.time_s, f) for g in data.groups if g.force is not None for f in g.force]
    else:
        rows = [np.interp(grid, tr.time_s, relative_force(tr)) for tr in data]
    if not rows:
        raise InputError("a nominal force profile needs touches with a force channel")
    med = np.median(np.array(rows), axis=0)
    return {"time_s": [float(v) for v in grid], "force_share": [round(float(v), 4) for v in med],
            "n_touches": len(rows), "touch_force_share": [[round(float(v), 3) for v in r] for r in rows]}


def _one_blas_thread():
    """A context limiting BLAS to one thread (a no-op without threadpoolctl)."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - scikit-learn depends on it
        import contextlib

        return contextlib.nullcontext()
    return threadpool_limits(1)


def _as_range(r) -> tuple[float, float]:
    if hasattr(r, "e_min"):
        return float(r.e_min), float(r.e_max)
    lo, hi = r
    return float(lo), float(hi)


def score(result: Identification, trials: Sequence[Trial], *,
          object_temps: Mapping[str, Any] | None = None) -> dict[str, float]:
    """Residual RMS [degC] per material of an identified model on (held-out) touches.

    Nothing of the fit is changed but each touch's own initial temperatures:
    Ts0 fitted in closed form, To from its passive channel (or fitted where the
    material's object temperature is free). Materials the fit did not see are
    refused (their e_o is unknown).
    """
    data, r = _held_out(result, trials, object_temps)
    names = result.names
    out: dict[str, list[np.ndarray]] = {}
    pos = 0
    for g in data.groups:
        out.setdefault(names[g.material], []).append(r[pos:pos + g.y.size])
        pos += g.y.size
    per = {n: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) for n, v in out.items()}
    per["all"] = float(np.sqrt(np.mean(r ** 2)))
    return per


def residual_series(result: Identification, trials: Sequence[Trial], *,
                    object_temps: Mapping[str, Any] | None = None) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """Each touch's residual (prediction - reading) [degC] on its own grid, as :func:`score` computes it.

    Returns
    -------
    list of (material, time_s, residual), in the order of ``trials``.
    """
    data, r = _held_out(result, trials, object_temps)
    rows: dict[int, tuple[str, np.ndarray, np.ndarray]] = {}
    pos = 0
    for g in data.groups:
        n, m = g.y.shape
        block = r[pos:pos + n * m].reshape(n, m)
        pos += n * m
        for i, k in enumerate(g.trials):
            rows[k] = (result.names[g.material], g.time_s, block[i])
    return [rows[k] for k in range(len(trials))]


def _held_out(result: Identification, trials: Sequence[Trial],
              object_temps: Mapping[str, Any] | None) -> tuple[_Data, np.ndarray]:
    """(prepared data, residuals) of an identified model on touches, each with its own nuisances."""
    names = result.names
    unknown = sorted({tr.material for tr in trials} - set(names))
    if unknown:
        raise InputError(f"cannot score {', '.join(unknown)}: not among the fitted materials {', '.join(names)}")
    modes = dict(result.object_modes)
    modes.update(dict(object_temps or {}))
    data = _prepare(trials, names, modes, refs=result.object_refs, force_area=result.candidate.force_area)
    prob = _Problem(result.candidate, data, result.depth_m, (-math.inf, math.inf),
                    np.zeros(len(names), dtype=bool), stride=1, touch_conductance=result.touch_conductance)
    x = np.concatenate([result.x[:prob.n_global], np.zeros(prob.lo.size - prob.n_global)])
    if prob.touch_cols:  # each held-out touch's own h_c (the sensor's parameters stay as fitted)
        from scipy.optimize import least_squares

        glob = x[:prob.n_global]
        free = slice(prob.n_global, None)
        prob.stride = data.noise_lag
        with _one_blas_thread():
            sol = least_squares(lambda d: prob.residuals(np.concatenate([glob, d])), x[free],
                                jac=lambda d: prob.jacobian(np.concatenate([glob, d]), touch_only=True)[:, free],
                                bounds=(prob.lo[free], prob.hi[free]), method="trf", x_scale="jac", max_nfev=50)
        x = np.concatenate([glob, sol.x])
        prob.stride = 1
    r, _ = prob.project(x)
    return data, r


# ------------------------------------------------------------ comparison
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
        x.append(src.x[src.candidate.free.index(p)] if src is not None else _PARAMS[p].to_x(_PARAMS[p].start))
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

    ``kwargs`` go to :func:`identify` (``ranges``, ``object_temps``, ``depth_m``, ...).
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
            per: dict[str, list[np.ndarray]] = {}
            for name, _, r in rows:
                per.setdefault(name, []).append(r)
            sc = {n: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) for n, v in per.items()}
            sc["all"] = float(np.sqrt(np.mean(np.concatenate([r for _, _, r in rows]) ** 2)))
            held.append(sc)
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
    best, margin = low, 0.0
    for i in simple:
        d = touch_ms[i] - touch_ms[low]
        se = float(np.std(d, ddof=1) / math.sqrt(d.size)) if d.size > 1 else 0.0
        if float(np.mean(d)) <= se:
            best, margin = i, se
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


# ------------------------------------------------------------------ figure
def plot_identification(results: Sequence[Identification], selected: str, fit_trials: Sequence[Trial],
                        held_out: Sequence[Trial], path: "Path | str", *,
                        held_out_rms_c: Sequence[Mapping[str, float]] = (),
                        object_temps: Mapping[str, Any] | None = None) -> Path:
    """Figure of an identification (``calibrate fit --model NAME --plot f.png``); returns ``path``.

    Left: the selected model's mean prediction (dashed) over the mean reading (solid) [degC] of each
    material's fitted touches, each touch with its own Ts0 and To (as :func:`score`). Middle: the
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
