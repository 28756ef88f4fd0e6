"""What a calibration needs besides the fit: the materials' effusivity ranges, their object
temperatures, and the checks that make a calibration unusable.

The identification itself, of the paper's semi-infinite model (paper appendix) and of every other
sensor model, is one engine: :mod:`designkit.calibration.identify` (its ``semi-infinite``
candidate is the paper's fit: ``T = Ts0 + (To - Ts0) e_o/(e_s + e_o) erfc(sqrt(tau/(t - t_off)))``,
e_s from where the materials' ranges overlap).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np

from .._validation import InputError, check_positive, check_temperature
from .trials import Trial

if TYPE_CHECKING:  # pragma: no cover
    from .results import Identification

__all__ = [
    "CalibrationProblem",
    "MaterialRange",
    "check_calibration",
    "parse_object_temps",
    "parse_ranges",
    "resolve_ranges",
]


# ----------------------------------------------------------------- ranges
@dataclass(frozen=True)
class MaterialRange:
    """Effusivity range of one material [J s^-1/2 K^-1 m^-2] and where it came from."""

    name: str
    e_min: float
    e_max: float
    source: str

    def __post_init__(self) -> None:
        lo = check_positive(f"{self.name} effusivity minimum", self.e_min)
        hi = check_positive(f"{self.name} effusivity maximum", self.e_max)
        if hi < lo:
            raise InputError(f"effusivity range of {self.name} has min > max: {lo:g}:{hi:g}")


def parse_ranges(specs: Sequence[str]) -> dict[str, str]:
    """``["metal=12767:25972", "cold_wood=wood"]`` -> {name: spec}."""
    out: dict[str, str] = {}
    for spec in specs:
        name, sep, value = str(spec).partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise InputError(f"--range must look like NAME=MIN:MAX or NAME=DATABASE_NAME, got {spec!r}")
        if name in out:
            raise InputError(f"--range given twice for {name!r}")
        out[name] = value
    return out


def _database_range(name: str, database_name: str) -> MaterialRange:
    """The range of ``database_name`` in the materials database, for material ``name`` (InputError if unknown)."""
    from ..materials import get_material

    m = get_material(database_name)
    return MaterialRange(name, m.e_min, m.e_max, f"materials database: {m.name}")


def _range_from_spec(name: str, spec: str) -> MaterialRange:
    lo_text, sep, hi_text = spec.partition(":")
    if sep:
        try:
            lo, hi = float(lo_text), float(hi_text)
        except ValueError:
            raise InputError(f"--range {name}={spec}: MIN and MAX must be numbers") from None
        return MaterialRange(name, lo, hi, "--range")
    try:
        return _database_range(name, spec)
    except InputError as exc:
        raise InputError(f"--range {name}={spec}: not MIN:MAX and {exc}") from None


def resolve_ranges(materials: Sequence[str], overrides: Mapping[str, str]) -> dict[str, MaterialRange]:
    """A range for every material: ``--range`` first, then the materials database.

    Raises one InputError naming every material left without a range.
    """
    unknown = sorted(set(overrides) - set(materials))
    if unknown:
        raise InputError(f"--range names material(s) not in the index: {', '.join(unknown)} "
                         f"(it has {', '.join(materials)})")
    out: dict[str, MaterialRange] = {}
    missing: list[str] = []
    for name in materials:
        if name in overrides:
            out[name] = _range_from_spec(name, overrides[name])
            continue
        try:
            out[name] = _database_range(name, name)
        except InputError:
            missing.append(name)
    if missing:
        raise InputError(f"no effusivity range for {', '.join(missing)} (not a materials database name): "
                         f"give --range NAME=MIN:MAX or NAME=DATABASE_NAME, or leave them out with --only")
    return out


def parse_object_temps(specs: Sequence[str]) -> dict[str, str | float]:
    """``["cold_wood=free", "block=18.5"]`` -> {name: "passive" | "passive-end" | "free" | degC}."""
    out: dict[str, str | float] = {}
    for spec in specs:
        name, sep, value = str(spec).partition("=")
        name, value = name.strip(), value.strip().lower()
        if not sep or not name or not value:
            raise InputError(f"--object-temp must look like NAME=passive|passive-end|free|DEGC, got {spec!r}")
        if value in ("passive", "passive-end", "free"):
            out[name] = value
        else:
            try:
                out[name] = float(value)
            except ValueError:
                raise InputError(f"--object-temp {spec!r}: use passive, passive-end, free or a temperature "
                                 "in °C") from None
            check_temperature(f"--object-temp {name}", out[name])  # NaN was taken, and fitted
    return out


# --------------------------------------------------------------- checks
@dataclass(frozen=True)
class CalibrationProblem:
    """Something about a calibration a user must hear before trusting (or writing) its sensor file.

    Attributes
    ----------
    kind : str
        ``"conflict"``, ``"mislabelled"``, ``"wiring"``.
    message : str
        What is wrong, with the numbers that show it.
    suggestion : str
        What to do about it.
    fatal : bool
        The result is unusable: no sensor file is written (unless forced) and the exit is non-zero.
    """

    kind: str
    message: str
    suggestion: str
    fatal: bool = True

    def text(self) -> str:
        return f"{self.message}. {self.suggestion}"


def _normalized_drop(tr: Trial, at_s: float = 2.0) -> float:
    """(Ts0 - T(at_s)) / (Ts0 - To) of one touch (raw drop [degC] without a passive channel); NaN if too short."""
    late = np.abs(tr.time_s - at_s) <= 0.25
    if (tr.time_s < 0).sum() < 3 or not late.any():
        return math.nan
    ts0, to = tr.before_contact()
    drop = ts0 - float(np.mean(tr.sensor_c[late]))
    if math.isfinite(to):
        diff = ts0 - to
        return drop / diff if abs(diff) > 0.5 else math.nan
    return drop


#: Widest ratio of the e_s the materials allow (largest over smallest) that still counts as identified.
UNIDENTIFIED_ES_RATIO = 100.0


def check_calibration(result: "Identification | None", trials: Sequence[Trial]) -> list[CalibrationProblem]:
    """What makes a calibration unusable or suspect, each with a suggestion.

    * **wiring**: the heated sensor reads colder than the object before contact in most touches (a
      thermistor on the wrong side of its divider reads a plausible temperature mirrored about the
      divider's midpoint);
    * **mislabelled**: a touch whose normalized response at 2 s (``(Ts0 - T) / (Ts0 - To)``) lies
      within 2 robust SDs of another material's median and beyond 5 of its own's (touches recorded
      while another sample was under the sensor);
    * **conflict**: no e_s keeps every material inside its effusivity range under ``result``'s model
      (an :class:`~designkit.calibration.results.Identification`);
    * **no-response**: in most touches the sensor's reading moves by less than 5 pre-contact noise SDs
      (and 0.05 °C) over the contact: no heat flowed (the heater off, sensor and object at one
      temperature, a disconnected channel), so the touches hold nothing about e_s, whatever a fit says;
    * **unidentified**: the e_s every material allows under ``result``'s model spans more than a factor of
      ``UNIDENTIFIED_ES_RATIO`` (one material under a model with a film and a contact conductance fits any e_s).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(-200, 801) / 200.0
    >>> warming = np.where(t < 0, 20.0, 20.0 + 2.0 * (1.0 - np.exp(-np.maximum(t, 0.0))))
    >>> cold = Trial(t, warming, np.full(t.size, 25.0), np.zeros(t.size), "wood")
    >>> [p.kind for p in check_calibration(None, [cold, cold])]
    ['wiring']
    >>> flat = Trial(t, np.full(t.size, 35.0), np.full(t.size, 25.0), np.zeros(t.size), "wood")
    >>> [p.kind for p in check_calibration(None, [flat, flat])]
    ['no-response']
    """
    checks = (_no_response(trials), _wiring(trials), _mislabelled(trials), _conflict(result), _unidentified(result))
    return [p for p in checks if p is not None]


def _no_response(trials: Sequence[Trial]) -> CalibrationProblem | None:
    moved = []  # (largest move over the contact, pre-contact noise SD, sensor - object before contact) [degC]
    for tr in trials:
        pre, post = tr.time_s < 0, tr.time_s >= 0
        if pre.sum() >= 3 and post.sum() >= 3:
            ts0, to = tr.before_contact()
            moved.append((float(np.max(np.abs(tr.sensor_c[post] - ts0))), float(np.std(tr.sensor_c[pre])), ts0 - to))
    still = [m for m in moved if m[0] < max(5.0 * m[1], 0.05)]
    if not (moved and len(still) > len(moved) / 2):
        return None
    diffs = [m[2] for m in still if math.isfinite(m[2])]
    why = (f"; sensor minus object before contact {np.mean(diffs):+.2f} °C on average" if diffs else "")
    return CalibrationProblem(
        "no-response", f"the sensor's reading does not respond to contact in {len(still)} of {len(moved)} "
                       f"touches (it moves by at most {max(m[0] for m in still):.3g} °C, against a pre-contact "
                       f"noise of {np.mean([m[1] for m in still]):.2g} °C{why}): no heat flowed, so these "
                       "touches say nothing about the sensor",
        "Heat the sensor above the object (its set point), check that the thermistor channel is "
        "connected and that the object is under the sensor when a touch is recorded, then record again")


def _wiring(trials: Sequence[Trial]) -> CalibrationProblem | None:
    cold = [tr.before_contact() for tr in trials if (tr.time_s < 0).any()]
    cold = [(s, o) for s, o in cold if math.isfinite(o)]
    below = [(s, o) for s, o in cold if s < o - 0.2]
    if not (cold and len(below) > len(cold) / 2):
        return None
    s, o = np.mean([b[0] for b in below]), np.mean([b[1] for b in below])
    return CalibrationProblem(
        "wiring", f"the heated sensor reads colder than the object before contact in {len(below)} of "
                  f"{len(cold)} touches (sensor {s:.2f} °C, object {o:.2f} °C on average)",
        "A heated sensor should be the warmer one: check that each thermistor sits on the side of its "
        "divider that the profile's channel says (wired the other way, a thermistor reads a plausible "
        "but wrong temperature), and the heater's set point")


def _mislabelled(trials: Sequence[Trial]) -> CalibrationProblem | None:
    names = sorted({tr.material for tr in trials})
    drops = {n: [(i, _normalized_drop(tr)) for i, tr in enumerate(trials) if tr.material == n] for n in names}
    med = {n: float(np.nanmedian([d for _, d in v])) for n, v in drops.items()
           if sum(math.isfinite(d) for _, d in v) >= 2}
    # robust spread of each material's responses (1.4826 MAD, at least 0.005): materials made to look
    # alike (cold wood and metal) are not "mislabelled" just because their medians are close
    spread = {n: max(0.005, 1.4826 * float(np.nanmedian([abs(d - med[n]) for _, d in drops[n]]))) for n in med}
    if len(med) < 2:
        return None
    odd = []
    for n, v in drops.items():
        if n not in med:
            continue
        for i, d in v:
            if not math.isfinite(d):
                continue
            near = min(med, key=lambda m: abs(d - med[m]))
            if near != n and abs(d - med[near]) < 2.0 * spread[near] and abs(d - med[n]) > 5.0 * spread[n]:
                odd.append(f"{Path(trials[i].source).name or f'touch {i + 1}'} ({n}, looks like {near}: "
                           f"response {d:.3g} against {med[n]:.3g} for {n} and {med[near]:.3g} for {near})")
    if not odd:
        return None
    return CalibrationProblem(
        "mislabelled", f"{len(odd)} touch(es) look like another material: " + "; ".join(odd[:6])
        + (" ..." if len(odd) > 6 else ""),
        "Touches recorded while another sample was under the sensor get the wrong label; record "
        "those materials again (press Enter only once the sample is in place), or delete the odd "
        "trials from the index and run 'calibrate fit' on it")


def _conflict(result: "Identification | None") -> CalibrationProblem | None:
    if result is None or result.consistent is not False:
        return None
    allowed = "; ".join(f"{n} allows e_s in [{lo:.4g}, {hi:.4g}]" for n, (lo, hi) in result.es_allowed.items())
    noise = f", at {result.rms_c / result.noise_c:.0f}x the pre-contact noise" if result.noise_c > 0 else ""
    return CalibrationProblem(
        "conflict", f"the materials' effusivity ranges conflict under the {result.candidate.label} model "
                    f"({allowed}): no e_s keeps every material in range; residual {result.rms_c:.3g} °C{noise}",
        "Check each material's label, range (--range NAME=MIN:MAX) and object temperature "
        "(--object-temp NAME=free for an object not at room temperature); let calibrate choose among every "
        "sensor model ('calibrate fit --model all', the default); or write the file anyway with --force")


def _unidentified(result: "Identification | None") -> CalibrationProblem | None:
    if result is None or not result.es_allowed:
        return None
    lo = max(lo for lo, _ in result.es_allowed.values())
    hi = min(hi for _, hi in result.es_allowed.values())
    if lo > 0 and math.isfinite(hi) and hi <= UNIDENTIFIED_ES_RATIO * lo:
        return None
    one = len(result.es_allowed) == 1
    return CalibrationProblem(
        "unidentified", f"the touches do not identify the sensor's effusivity under the "
                        f"{result.candidate.label} model (e_s anywhere in [{lo:.4g}, {hi:.4g}]"
                        + (f", from one material, {next(iter(result.es_allowed))})" if one else ")"),
        "Record a second material whose effusivity range is known and far from the first (wood beside "
        "a metal, say) and fit both; or write the file anyway with --force")
