"""Recommend a sensor: the design whose limiting pair of materials separates in the shortest contact.

The ideal observer (closed form, :func:`designkit.query.ideal_bound.exact_ideal_min_contact`)
depends on a design only through the sensor's effusivity ``e_s`` (the skin material), its time
constant ``tau = x^2 / (4 alpha_s)`` (thermistor depth ``x`` under a skin of diffusivity
``alpha_s``), the sampling rate ``fs`` and the ratio ``sigma / dT`` (paper eqs. 1-4, white noise).
With white noise per sample, more samples and a larger ``dT`` never hurt the ideal observer, so the
recommended sampling rate and ``dT`` are the largest allowed (the trade-off curves show what each
costs); the search is over skin material x depth, exhaustive on a grid (vectorized over pairs).

Materials rule: each material is an 80-wide class (the paper's) at its identified effusivity when
the set gives one (``paper12``, the paper's calibration), else the hardest 80-wide classes of its
range (the nearest ends of two ranges: ranges that overlap cannot be separated by any design). For
"all at once" the limiting pair is the hardest one; for ordered classes it is always between
neighbours in effusivity (the ideal observer separates farther classes sooner), so only
neighbouring pairs are searched, and every pair is scored for the recommended design.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import InputError
from ..materials import get_material, list_materials
from ..query.ideal_bound import exact_ideal_min_contact
from ..sensor import Sensor, check_samples_per_touch

__all__ = ["SKIN_SET", "Constraints", "Design", "DesignResult", "Target", "confirm_with_svm", "recommend",
           "targets_from"]

#: Common skin materials of a heated tactile sensor (materials database names): polymers, ceramics, metals.
SKIN_SET = ("Polyetheretherketone (PEEK)", "Silicone elastomers", "Polytetrafluoroethylene (Teflon, PTFE)",
            "Epoxies", "Polyethylene terephthalate (PET)", "Silica glass", "Alumina", "Zirconia",
            "Stainless steel", "Titanium alloys")
WIDTH = 80.0
#: Width of the class of a material given by its identified effusivity (a point, to the J).
POINT_WIDTH = 1.0


@dataclass(frozen=True)
class Target:
    """One material to recognize, as the 80-wide class the design is judged on."""

    name: str
    e_low: float
    e_range: tuple[float, float]
    width: float = 80.0


#: Deepest thermistor considered [um]: 1 cm, a time constant of minutes under any skin.
MAX_DEPTH_UM = 1e4


@dataclass(frozen=True)
class Constraints:
    """What the design must respect.

    Attributes
    ----------
    max_contact_s : float
        Longest acceptable contact [s].
    noise_c : float
        Noise floor of the electronics, sigma per sample [degC].
    max_delta_t_c : float
        Largest temperature difference the heater can hold [degC].
    max_rate_hz : float
        Highest sampling rate [Hz].
    depth_um : (float, float)
        Thermistor depths that can be built [um].
    threshold : float
        F1 the limiting pair must reach (the paper's 0.9).
    """

    max_contact_s: float = 4.0
    noise_c: float = 0.05
    max_delta_t_c: float = 10.0
    max_rate_hz: float = 200.0
    depth_um: tuple[float, float] = (20.0, 500.0)
    threshold: float = 0.9

    def __post_init__(self) -> None:
        for name, v in (("longest contact [s]", self.max_contact_s), ("noise floor [degC]", self.noise_c),
                        ("largest temperature difference [degC]", self.max_delta_t_c),
                        ("highest sampling rate [Hz]", self.max_rate_hz)):
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"{name} must be positive and finite, got {v:g}")
        lo, hi = self.depth_um
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
            raise InputError(f"thermistor depths contradict each other: MIN must be positive and <= MAX, "
                             f"got {lo:g}:{hi:g} um")
        if hi > MAX_DEPTH_UM:  # 1e308 um was searched
            raise InputError(f"thermistor depth must be at most {MAX_DEPTH_UM:g} um (1 cm: a time constant of minutes "
                             f"under any skin), got {hi:g} um")
        if not 0.5 < self.threshold < 1.0:
            raise InputError(f"F1 threshold must lie in (0.5, 1), got {self.threshold:g}")
        if self.max_contact_s * self.max_rate_hz < 1.0:
            raise InputError(f"constraints contradict each other: {self.max_contact_s:g} s at {self.max_rate_hz:g} Hz "
                             "is less than one sample after contact")
        check_samples_per_touch(self.max_contact_s, self.max_rate_hz, "the longest contact",
                                "lower --max-contact or --max-rate")  # the search ran without end (8 GB)


@dataclass(frozen=True)
class Design:
    """A sensor design and its ideal-observer contact time for the limiting pair."""

    skin: str
    e_sensor: float
    diffusivity_m2_s: float
    depth_um: float
    tau_s: float
    sample_rate_hz: float
    delta_t_c: float
    min_contact_s: float
    limiting_pair: tuple[str, str]

    def sensor(self) -> Sensor:
        return Sensor(self.e_sensor, self.diffusivity_m2_s, self.depth_um * 1e-6, self.sample_rate_hz,
                      name=f"design: {self.skin}, {self.depth_um:.3g} um")

    def to_dict(self) -> dict:
        return {"skin": self.skin, "e_sensor": self.e_sensor, "diffusivity_m2_s": self.diffusivity_m2_s,
                "depth_um": self.depth_um, "tau_s": self.tau_s, "sample_rate_hz": self.sample_rate_hz,
                "delta_t_c": self.delta_t_c, "min_contact_s": _num(self.min_contact_s),
                "limiting_pair": list(self.limiting_pair)}


@dataclass(frozen=True)
class DesignResult:
    """The recommendation, the trade-off curves and every pair for the recommended design."""

    best: Design | None
    designs: tuple[Design, ...]
    pairs: tuple[tuple[str, str, float], ...]
    pareto: tuple[tuple[float, float], ...]
    constraints: Constraints
    reason: str

    def to_dict(self) -> dict:
        c = self.constraints
        return {"best": None if self.best is None else self.best.to_dict(), "reason": self.reason,
                "constraints": {"max_contact_s": c.max_contact_s, "noise_c": c.noise_c,
                                "max_delta_t_c": c.max_delta_t_c, "max_rate_hz": c.max_rate_hz,
                                "depth_um": list(c.depth_um), "threshold": c.threshold},
                "pairs": [{"pair": [a, b], "ideal_min_contact_s": _num(t)} for a, b, t in self.pairs],
                "pareto_noise_ratio_vs_contact": [{"noise_ratio": r, "min_contact_s": _num(t)} for r, t in self.pareto],
                "designs_searched": len(self.designs)}


def _num(x):
    return None if x is None or not math.isfinite(x) else float(x)


def targets_from(names=(), set_name: str | None = None) -> list[Target]:
    """Materials (names, ``NAME=MIN:MAX``, ``NAME=E``, or a named set) as design targets, sorted by effusivity."""
    out = []
    mats = list(list_materials(set=set_name)) if set_name else []
    for m in mats:
        e = m.identified
        out.append(Target(m.name, float(e), (float(m.e_min), float(m.e_max)), POINT_WIDTH)
                   if e else _range_target(m.name, (float(m.e_min), float(m.e_max))))
    for spec in names:
        name, sep, value = str(spec).partition("=")
        if sep:
            lo, colon, hi = value.partition(":")
            try:
                rng = (float(lo), float(hi)) if colon else (float(lo), float(lo) + WIDTH)
            except ValueError:
                raise InputError(f"material {spec!r}: give NAME=MIN:MAX or NAME=E [J s^-1/2 K^-1 m^-2]") from None
            if not (all(math.isfinite(x) and x > 0 for x in rng) and rng[0] <= rng[1]):
                raise InputError(f"material {spec!r}: effusivities must be positive, MIN <= MAX")
            out.append(Target(name.strip(), rng[0], rng) if not colon else _range_target(name.strip(), rng))
        else:
            m = get_material(name.strip())
            out.append(_range_target(m.name, (float(m.e_min), float(m.e_max))))
    if len(out) < 2:
        raise InputError(f"a design needs at least two materials to tell apart, got {len(out)}")
    names_ = [t.name for t in out]
    if len(set(names_)) != len(names_):
        raise InputError(f"materials named twice: {sorted({n for n in names_ if names_.count(n) > 1})}")
    return sorted(out, key=lambda t: t.e_low if math.isfinite(t.e_low) else 0.5 * (t.e_range[0] + t.e_range[1]))


def _range_target(name: str, rng: tuple[float, float]) -> Target:
    # the class is chosen per pair (nearest ends); e_low marks a range with NaN
    return Target(name, math.nan, rng)


def _class_edges(a: Target, b: Target) -> tuple[float, float, float]:
    """Lower edges and width of the classes judged for a pair (lower material first), overlapping or not."""
    w = min(a.width, b.width)
    lo = a.e_low if math.isfinite(a.e_low) else max(a.e_range[1] - w, a.e_range[0])
    hi = b.e_low if math.isfinite(b.e_low) else b.e_range[0]
    return lo, hi, w


def _pair_classes(a: Target, b: Target) -> tuple[float, float, float] | None:
    """Lower edges and width of the classes judged for a pair (lower material first), None if they overlap."""
    lo, hi, w = _class_edges(a, b)
    return None if hi < lo + w else (lo, hi, w)


def _grid(c: Constraints, n_depth: int) -> np.ndarray:
    lo, hi = c.depth_um
    return np.unique(np.geomspace(lo, hi, n_depth)) if hi > lo else np.array([lo])


def recommend(targets: list[Target], constraints: Constraints, *, skins=SKIN_SET, n_depth: int = 8,
              progress=None) -> DesignResult:
    """Search skin x depth with the ideal observer; the design with the shortest limiting contact wins.

    Examples
    --------
    >>> t = targets_from(["a=20000", "b=35000"])
    >>> r = recommend(t, Constraints(max_contact_s=4.0), skins=("Polyetheretherketone (PEEK)",), n_depth=3)
    >>> r.best.depth_um, r.best.limiting_pair
    (20.0, ('a', 'b'))
    """
    c = constraints
    ratio = c.noise_c / c.max_delta_t_c
    pairs = [(targets[i], targets[i + 1]) for i in range(len(targets) - 1)]
    edges = [_pair_classes(a, b) for a, b in pairs]
    bad = [(a, b) for (a, b), e in zip(pairs, edges) if e is None]
    if bad:
        a, b = bad[0]
        lo, hi, w = _class_edges(a, b)
        # the classes judged, with their width: two single values 50 apart "overlapped" with no word of why
        return DesignResult(None, (), (), (), c, f"{a.name} [{lo:g}, {lo + w:g}) and {b.name} [{hi:g}, {hi + w:g}) "
                                                 f"overlap in effusivity (each material is judged as a class {w:g} "
                                                 "J s^-1/2 K^-1 m^-2 wide; NAME=E is the class [E, E + "
                                                 f"{w:g})): no sensor separates every object of one from every "
                                                 "object of the other")
    lo = np.array([e[0] for e in edges])
    hi = np.array([e[1] for e in edges])
    wd = np.array([e[2] for e in edges])
    depths = _grid(c, n_depth)
    designs = []
    for skin in skins:
        m = get_material(skin)
        e_s = math.sqrt(m.e_min * m.e_max)
        alpha = math.sqrt(m.diffusivity_min_m2_s * m.diffusivity_max_m2_s)
        for d in depths:
            sensor = Sensor(e_s, alpha, d * 1e-6, c.max_rate_hz)
            t = exact_ideal_min_contact(sensor, lo, hi, ratio, width=wd, threshold=c.threshold,
                                        max_contact_s=c.max_contact_s)
            worst = np.where(np.isnan(t), np.inf, t)
            k = int(np.argmax(worst))
            designs.append(Design(m.name, e_s, alpha, float(d), sensor.tau_s, c.max_rate_hz, c.max_delta_t_c,
                                  float(worst[k]), (pairs[k][0].name, pairs[k][1].name)))
            if progress is not None:
                progress()
    best = min(designs, key=lambda x: (x.min_contact_s, x.tau_s))
    if not math.isfinite(best.min_contact_s):
        hard = best.limiting_pair
        return DesignResult(None, tuple(designs), (), (), c,
                            f"no allowed design separates {hard[0]} from {hard[1]} within {c.max_contact_s:g} s "
                            f"(noise {c.noise_c:g} degC, dT {c.max_delta_t_c:g} degC, {c.max_rate_hz:g} Hz)")
    sensor = best.sensor()
    # every pair of targets, one vectorized call for the separable ones (overlapping ones have no answer)
    ij = [(i, j) for i in range(len(targets)) for j in range(i + 1, len(targets))]
    cls = [_pair_classes(targets[i], targets[j]) for i, j in ij]
    sep = [e for e in cls if e is not None]
    t_sep = iter(exact_ideal_min_contact(sensor, *(np.array([e[k] for e in sep]) for k in (0, 1)), ratio,
                                         width=np.array([e[2] for e in sep]), threshold=c.threshold,
                                         max_contact_s=c.max_contact_s).tolist() if sep else [])
    all_pairs = [(targets[i].name, targets[j].name, next(t_sep) if e is not None else math.nan)
                 for (i, j), e in zip(ij, cls)]
    # trade-off: the best design's limiting contact against sigma/dT (noise floor and dT enter only so)
    ratios = ratio * np.geomspace(0.125, 8.0, 13)
    t = exact_ideal_min_contact(sensor, lo[None, :], hi[None, :], ratios[:, None], width=wd[None, :],
                                threshold=c.threshold, max_contact_s=c.max_contact_s)
    worst = np.max(np.where(np.isnan(t), np.inf, t), axis=1)
    front = [(float(r), float(x)) for r, x in zip(ratios, worst)]
    reason = (f"{best.skin} skin (e_s {best.e_sensor:.0f}), thermistor {best.depth_um:.3g} um deep (tau "
              f"{best.tau_s:.3g} s), {best.sample_rate_hz:g} Hz, dT {best.delta_t_c:g} degC: the limiting pair "
              f"{best.limiting_pair[0]} / {best.limiting_pair[1]} separates (ideal F1 >= {c.threshold:g}) after "
              f"{best.min_contact_s:.3g} s")
    return DesignResult(best, tuple(designs), tuple(all_pairs), tuple(front), c, reason)


def confirm_with_svm(result: DesignResult, targets: list[Target], *, trials: int = 100, seeds: int = 3,
                     step_s: float = 0.05) -> dict:
    """The paper's SVM on the recommended design's limiting pair: the shortest contact (on a ``step_s`` grid,
    from the ideal bound up) whose mean F1 over ``seeds`` runs reaches the threshold."""
    from ..objects import ObjectClass
    from ..recognition.svm import pair_f1
    from ..scene import Scene

    best, c = result.best, result.constraints
    by_name = {t.name: t for t in targets}
    a, b = (by_name[n] for n in best.limiting_pair)
    lo, hi, w = _pair_classes(a, b)
    sensor = best.sensor()
    t = best.min_contact_s
    while t <= c.max_contact_s + 1e-9:
        scene = Scene.from_delta_t(contact_s=t, noise_c=c.noise_c, delta_t_c=c.max_delta_t_c)
        f1 = [pair_f1(ObjectClass("lo", (lo, lo + w)), ObjectClass("hi", (hi, hi + w)), sensor, scene,
                      trials=trials, seed=[s, 17]).f1 for s in range(seeds)]
        if float(np.mean(f1)) >= c.threshold:
            return {"svm_min_contact_s": round(t, 6), "svm_f1": float(np.mean(f1)), "ideal_min_contact_s": best.min_contact_s,
                    "svm_minus_ideal_s": round(t - best.min_contact_s, 6), "grid_step_s": step_s,
                    "trials": trials, "seeds": seeds}
        t = round(t + step_s, 9)
    return {"svm_min_contact_s": None, "ideal_min_contact_s": best.min_contact_s, "svm_minus_ideal_s": None,
            "grid_step_s": step_s, "trials": trials, "seeds": seeds,
            "note": f"the SVM does not reach F1 {c.threshold:g} by {c.max_contact_s:g} s"}
