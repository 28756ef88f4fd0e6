"""The scene: what the world does to a touch (temperatures, noise, duration)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from ._validation import InputError, check_finite, check_nonnegative, check_positive

__all__ = ["Scene"]


@dataclass(frozen=True)
class Scene:
    """Conditions of one kind of touch (paper sections II-III).

    Parameters
    ----------
    contact_s : float
        Contact duration [s] (> 0).
    noise_c : float
        Standard deviation sigma of the i.i.d. Gaussian noise on each sample
        [degC] (paper eq. 4); 0 is noise-free.
    sensor_temp_c : float
        Initial sensor temperature Ts0 [degC] (the paper: 30 or 35).
    ambient_temp_c : float
        Ambient and initial object temperature Ta [degC] (the paper: 25).
    sensor_temp_spread_c, ambient_temp_spread_c : float
        Half-widths [degC] of per-trial uniform variation of Ts0 and Ta
        ("varied initial conditions"; the paper's robot used Ts0 uniform in
        30-35 degC, i.e. ``sensor_temp_c=32.5, sensor_temp_spread_c=2.5``).
        0 means fixed initial conditions.
    noise_correlation_s : float
        Correlation length [s] of the noise (0: white, the paper's i.i.d. noise). A real rig's
        misfit is a smooth wander from touch to touch, not sample-to-sample noise: with a length
        ``l`` > 0 the noise is a stationary Gaussian process with the Matern-3/2 autocorrelation
        ``(1 + sqrt(3) tau / l) exp(-sqrt(3) tau / l)`` and standard deviation ``noise_c``
        (:func:`designkit.simulation.correlate_noise`).
    onset_s : float
        Where the recorder's window starts [s of model time, >= 0]: a rig's controller detects
        contact after the first heat flow and its recognizer sees the samples from there to
        ``contact_s`` (0: from the first heat flow, the paper's).

    Examples
    --------
    >>> s = Scene.from_delta_t(contact_s=1.0, noise_c=0.05, delta_t_c=10.0)
    >>> s.sensor_temp_c, s.noise_ratio, s.fixed_initial_conditions
    (35.0, 0.005, True)
    """

    contact_s: float = 2.0
    noise_c: float = 0.05
    sensor_temp_c: float = 35.0
    ambient_temp_c: float = 25.0
    sensor_temp_spread_c: float = 0.0
    ambient_temp_spread_c: float = 0.0
    noise_correlation_s: float = 0.0
    onset_s: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "contact_s", check_positive("contact time [s]", self.contact_s))
        object.__setattr__(self, "noise_c", check_nonnegative("noise sigma [degC]", self.noise_c))
        object.__setattr__(self, "sensor_temp_c", check_finite("sensor temperature [degC]", self.sensor_temp_c))
        object.__setattr__(self, "ambient_temp_c", check_finite("ambient temperature [degC]", self.ambient_temp_c))
        object.__setattr__(self, "sensor_temp_spread_c",
                           check_nonnegative("sensor temperature spread [degC]", self.sensor_temp_spread_c))
        object.__setattr__(self, "ambient_temp_spread_c",
                           check_nonnegative("ambient temperature spread [degC]", self.ambient_temp_spread_c))
        object.__setattr__(self, "noise_correlation_s",
                           check_nonnegative("noise correlation length [s]", self.noise_correlation_s))
        object.__setattr__(self, "onset_s", check_nonnegative("recorder onset [s]", self.onset_s))
        if self.sensor_temp_c < -273.15 or self.ambient_temp_c < -273.15:
            raise InputError("temperatures must be above absolute zero (-273.15 degC)")

    @classmethod
    def from_delta_t(cls, *, contact_s: float = 2.0, noise_c: float = 0.05,
                     delta_t_c: float = 10.0, ambient_temp_c: float = 25.0,
                     sensor_temp_spread_c: float = 0.0) -> "Scene":
        """A scene with the sensor ``delta_t_c`` above ambient [degC]; with ``sensor_temp_spread_c`` > 0 each
        touch's sensor temperature is drawn within +-that of it (varied initial conditions), else fixed."""
        dt = check_finite("temperature difference [degC]", delta_t_c)
        amb = check_finite("ambient temperature [degC]", ambient_temp_c)
        return cls(contact_s=contact_s, noise_c=noise_c, sensor_temp_c=amb + dt, ambient_temp_c=amb,
                   sensor_temp_spread_c=sensor_temp_spread_c)

    @property
    def delta_t_c(self) -> float:
        """Sensor-object temperature difference ``Ts0 - Ta`` [K]."""
        return self.sensor_temp_c - self.ambient_temp_c

    @property
    def fixed_initial_conditions(self) -> bool:
        """True when Ts0 and Ta are the same in every trial."""
        return self.sensor_temp_spread_c == 0 and self.ambient_temp_spread_c == 0

    @property
    def noise_ratio(self) -> float:
        """sigma / |Ts0 - Ta|, dimensionless.

        With fixed initial conditions and standardized features, recognition
        depends on noise and temperature difference only through this ratio
        (docs/physics.md section 2). ``inf`` when there is no temperature difference.
        """
        dt = abs(self.delta_t_c)
        if dt == 0:
            return math.inf
        return self.noise_c / dt

    def window_s(self) -> float:
        """The recorder's window ``contact_s - onset_s`` [s] (at least 0: one sample, at the onset)."""
        return max(self.contact_s - self.onset_s, 0.0)

    def replace(self, **changes: Any) -> "Scene":
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, float]:
        """Plain-data form, with the derived ``delta_t_c`` and ``noise_ratio``."""
        out = dataclasses.asdict(self)
        for key in ("noise_correlation_s", "onset_s"):  # the rig's: stated only when they play
            if not out[key]:
                del out[key]
        out["delta_t_c"] = self.delta_t_c
        ratio = self.noise_ratio
        out["noise_ratio"] = ratio if math.isfinite(ratio) else None
        return out
