"""Conversions of a channel's raw wire numbers to engineering values, and back.

Conversions are pairs of exact inverses: :meth:`Conversion.to_value` reads a
raw wire number, :meth:`Conversion.to_raw` gives the raw number a device would
send (the emulator uses it). Thermistor channels go through the voltage
divider and either the B-parameter equation
``1/T = 1/T0 + ln(R/R0)/B`` or the Steinhart-Hart equation
``1/T = A + B ln R + C (ln R)^3`` (Steinhart and Hart, Deep-Sea Research 15,
497, 1968), whose inverse is the one real root of an increasing cubic, found
by Newton's method from the ``C = 0`` root (monotone convergence). A device
profile (:mod:`~designkit.calibration.profiles`) names one per channel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["KELVIN", "Conversion", "Identity", "Linear", "Thermistor"]

KELVIN = 273.15


def _fmt_fixed(values: np.ndarray, decimals: int) -> list[str]:
    if decimals <= 0:
        return [str(int(v)) for v in np.rint(values)]
    return [f"{v:.{decimals}f}" for v in values.tolist()]


class Conversion:
    """Raw wire number <-> engineering value, exact inverses of each other."""

    kind = "conversion"

    def to_value(self, raw):  # pragma: no cover - abstract
        raise NotImplementedError

    def to_raw(self, value):  # pragma: no cover - abstract
        raise NotImplementedError

    def raw_invalid(self, raw: np.ndarray) -> np.ndarray:
        """Mask of raw numbers the conversion cannot accept (never NaN here)."""
        return np.zeros(np.shape(raw), dtype=bool)

    def encode(self, value) -> np.ndarray:
        """The raw number a device sends for ``value`` (rounded as it would be)."""
        return np.asarray(self.to_raw(value), dtype=np.float64)

    def format(self, raw: np.ndarray) -> list[str]:  # pragma: no cover - abstract
        raise NotImplementedError

    def to_dict(self) -> dict[str, Any]:  # pragma: no cover - abstract
        raise NotImplementedError


@dataclass(frozen=True)
class Identity(Conversion):
    """Already in engineering units. ``decimals``: how the emulator prints them."""

    decimals: int = 4
    kind = "none"

    def to_value(self, raw):
        return np.asarray(raw, dtype=np.float64)

    def to_raw(self, value):
        return np.asarray(value, dtype=np.float64)

    def encode(self, value):
        return np.round(np.asarray(value, dtype=np.float64), self.decimals)

    def format(self, raw):
        return _fmt_fixed(np.asarray(raw), self.decimals)

    def to_dict(self):
        return {"type": "none", "decimals": self.decimals}


@dataclass(frozen=True)
class Linear(Conversion):
    """``value = gain * raw + offset``; with ``adc_bits`` the raw numbers are
    integer counts in ``[0, 2^bits - 1]``."""

    gain: float
    offset: float = 0.0
    decimals: int = 0
    adc_bits: int | None = None
    kind = "linear"

    def to_value(self, raw):
        return self.gain * np.asarray(raw, dtype=np.float64) + self.offset

    def to_raw(self, value):
        return (np.asarray(value, dtype=np.float64) - self.offset) / self.gain

    def raw_invalid(self, raw):
        raw = np.asarray(raw, dtype=np.float64)
        if self.adc_bits is None:
            return np.zeros(raw.shape, dtype=bool)
        full = 2 ** self.adc_bits - 1
        return (raw != np.rint(raw)) | (raw < 0) | (raw > full)

    def encode(self, value):
        raw = self.to_raw(value)
        if self.adc_bits is not None:
            return np.clip(np.rint(raw), 0, 2 ** self.adc_bits - 1)
        return np.round(raw, self.decimals)

    def format(self, raw):
        return _fmt_fixed(np.asarray(raw), 0 if self.adc_bits is not None else self.decimals)

    def to_dict(self):
        out = {"type": "linear", "gain": self.gain, "offset": self.offset, "decimals": self.decimals}
        if self.adc_bits is not None:
            out["adc_bits"] = self.adc_bits
        return out


@dataclass(frozen=True)
class Thermistor(Conversion):
    """NTC thermistor in a voltage divider, read by an ADC.

    The divider is fed with ``v_supply`` [V]; the ADC has ``adc_bits`` bits and
    reference ``v_ref`` [V], so ``counts = V / v_ref * (2^bits - 1)``.
    ``thermistor_side="high"``: thermistor between supply and the ADC node,
    series resistor to ground (``V = Vs Rs / (Rs + Rt)``); ``"low"``: the other
    way round (``V = Vs Rt / (Rs + Rt)``). The thermistor is described either
    by ``beta_k``, ``r0_ohm`` at ``t0_c`` (B-parameter equation) or by
    Steinhart-Hart coefficients ``sh = (A, B, C)``.

    Counts at the rails (0 and full scale) mean an open or shorted thermistor
    and are refused, as are counts the divider cannot produce.
    """

    adc_bits: int
    v_ref: float
    series_ohm: float
    thermistor_side: str = "high"
    v_supply: float | None = None
    beta_k: float | None = None
    r0_ohm: float | None = None
    t0_c: float | None = None
    sh: tuple[float, float, float] | None = None
    kind = "thermistor"

    @property
    def full_scale(self) -> int:
        return 2 ** self.adc_bits - 1

    @property
    def supply(self) -> float:
        return self.v_ref if self.v_supply is None else self.v_supply

    # divider fraction r = V / Vs from counts, and back
    def _fraction(self, counts):
        return np.asarray(counts, dtype=np.float64) * (self.v_ref / self.full_scale) / self.supply

    def resistance_ohm(self, counts):
        """Thermistor resistance [ohm] from ADC counts (inf/0 outside the divider's range)."""
        r = self._fraction(counts)
        with np.errstate(divide="ignore", invalid="ignore"):
            if self.thermistor_side == "high":
                return self.series_ohm * (1.0 - r) / r
            return self.series_ohm * r / (1.0 - r)

    def _counts_from_resistance(self, rt):
        rt = np.asarray(rt, dtype=np.float64)
        # r = Rs/(Rs+Rt) or Rt/(Rs+Rt), written without cancellation
        if self.thermistor_side == "high":
            r = 1.0 / (1.0 + rt / self.series_ohm)
        else:
            r = 1.0 / (1.0 + self.series_ohm / rt)
        return r * self.supply / self.v_ref * self.full_scale

    def log_resistance_from_c(self, temp_c):
        """ln R [ln ohm] at temperature [degC]: the exact inverse of the thermistor equation."""
        inv_t = 1.0 / (np.asarray(temp_c, dtype=np.float64) + KELVIN)
        if self.sh is None:
            return math.log(self.r0_ohm) + self.beta_k * (inv_t - 1.0 / (self.t0_c + KELVIN))
        a, b, c = self.sh
        # C L^3 + B L = 1/T - A with B > 0, C >= 0: increasing in L, one real root. Newton from the
        # C = 0 root converges monotonically (the cubic is convex on that side of the root).
        y = inv_t - a
        log_r = y / b
        for _ in range(60):
            step = (c * log_r ** 3 + b * log_r - y) / (3.0 * c * log_r ** 2 + b)
            log_r = log_r - step
            if np.all(np.abs(step) <= 1e-15 * np.maximum(1.0, np.abs(log_r))):
                break
        return log_r

    def c_from_log_resistance(self, log_r):
        """Temperature [degC] from ln R (B-parameter or Steinhart-Hart)."""
        log_r = np.asarray(log_r, dtype=np.float64)
        if self.sh is None:
            inv_t = 1.0 / (self.t0_c + KELVIN) + (log_r - math.log(self.r0_ohm)) / self.beta_k
        else:
            a, b, c = self.sh
            inv_t = a + b * log_r + c * log_r ** 3
        with np.errstate(divide="ignore"):
            return 1.0 / inv_t - KELVIN

    def to_value(self, raw):
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.c_from_log_resistance(np.log(self.resistance_ohm(raw)))

    def to_raw(self, value):
        return self._counts_from_resistance(np.exp(self.log_resistance_from_c(value)))

    def raw_invalid(self, raw):
        raw = np.asarray(raw, dtype=np.float64)
        r = self._fraction(raw)
        return (raw != np.rint(raw)) | (raw <= 0) | (raw >= self.full_scale) | (r >= 1.0)

    @property
    def max_count(self) -> int:
        """Largest count the recorder accepts (below full scale and below the supply)."""
        top = min(self.full_scale - 1, int(math.ceil(self.full_scale * self.supply / self.v_ref)))
        while top > 1 and self.raw_invalid(np.array([float(top)]))[0]:
            top -= 1
        return top

    def encode(self, value):
        return np.clip(np.rint(self.to_raw(value)), 1, self.max_count)

    def format(self, raw):
        return [str(int(v)) for v in np.rint(np.asarray(raw))]

    def to_dict(self):
        out: dict[str, Any] = {"type": "thermistor", "adc_bits": self.adc_bits, "v_ref": self.v_ref,
                               "series_ohm": self.series_ohm, "thermistor_side": self.thermistor_side}
        if self.v_supply is not None:
            out["v_supply"] = self.v_supply
        if self.sh is None:
            out["beta"] = {"beta_k": self.beta_k, "r0_ohm": self.r0_ohm, "t0_c": self.t0_c}
        else:
            out["steinhart_hart"] = {"a": self.sh[0], "b": self.sh[1], "c": self.sh[2]}
        return out
