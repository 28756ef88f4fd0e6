"""The models :func:`~designkit.calibration.identify.identify` fits: candidates and their parameters.

A :class:`Candidate` is a registered forward model (:mod:`designkit.models`), which of its
parameters are free (:data:`PARAMS`: name, unit, transform, search range) and the measurement
chain around it (the host smoothing :data:`HOST_SMOOTHING`, a drifting heater, a contact area
that grows with the force). :data:`CANDIDATES` are the ones compared by default, simplest first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping

from .._validation import InputError

__all__ = ["CANDIDATES", "CHAIN_PARAMS", "HOST_SMOOTHING", "PARAMS", "Candidate", "Param", "candidate"]

#: The recordings' host smoothing: Savitzky-Golay window 99, order 3 (at 200 Hz).
HOST_SMOOTHING = (99, 3)


@dataclass(frozen=True)
class Param:
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


#: Every fittable parameter by name.
PARAMS: dict[str, Param] = {p.name: p for p in (
    Param("diffusivity_m2_s", "m^2/s", 1e-11, 1e-5, 1.2e-9,
          description="sensor (film) diffusivity alpha_s at the fixed thermistor depth"),
    Param("conductance_w_m2k", "W m^-2 K^-1", 1e-3, 1e4, 3.0, scale_with_es=True,
          description="sensor-object interface conductance h_c"),
    Param("film_thickness_m", "m", 1e-6, 1e-2, 150e-6, description="heater film thickness L"),
    Param("backing_effusivity_ws05_m2k", "J s^-1/2 K^-1 m^-2", 1e-3, 1e3, 0.5, scale_with_es=True,
          description="backing (finger) effusivity e_b"),
    Param("lag_s", "s", 1e-3, 20.0, 0.3, description="thermistor (and host filter) time constant"),
    Param("backing_thickness_m", "m", 1e-6, 1.0, 1e-3,
          description="backing thickness L_b (its far face held at Ts0)"),
    Param("backing_diffusivity_m2_s", "m^2/s", 1e-10, 1e-4, 1e-7, description="backing diffusivity alpha_b"),
    Param("contact_force_fraction", "", 0.0, 0.9, 0.3, log=False,
          description="force (share of the touch's plateau) at which the contact area starts to grow"),
)}
#: Fittable parameters that belong to the measurement chain, not to the forward model's fields.
CHAIN_PARAMS = ("contact_force_fraction",)


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
        unknown = [p for p in self.free if p not in PARAMS]
        if unknown:
            raise InputError(f"candidate {self.label}: no fittable parameter {', '.join(unknown)} "
                             f"(fittable: {', '.join(PARAMS)})")

    def chain(self, time_s, u, *, drift: bool | None = None):
        """The measurement chain on unsmoothed readings ``u`` (..., m) at ``time_s``: ``(v, b)``, the reading
        and the drift basis ``b = t (1 - u)`` (None unless ``drift``, by default the candidate's), both
        smoothed by the host's filter when ``smoothing`` (it is linear: ``Ts0 (1 - v) + s b + To v`` is the
        smoothed ``(Ts0 + s t)(1 - u) + To u``)."""
        b = time_s * (1.0 - u) if (self.drift if drift is None else drift) else None
        if self.smoothing:
            from ..models.layered import savgol_smooth

            u = savgol_smooth(u, *HOST_SMOOTHING)
            if b is not None:
                b = savgol_smooth(b, *HOST_SMOOTHING)
        return u, b


#: The candidates :func:`~designkit.calibration.compare.compare_models` tries by default, simplest first.
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
