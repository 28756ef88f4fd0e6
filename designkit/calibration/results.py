"""What an identification found: parameters with intervals, the identified model and sensor.

:class:`Identification` is what :func:`~designkit.calibration.identify.identify` returns for one
candidate: each :class:`IdentifiedParameter` with its 95 % interval and whether the touches
identify it, the fit's quality, the identified forward model (:meth:`Identification.model`), its
readings (:meth:`Identification.reading`) and the :class:`~designkit.sensor.Sensor` a sensor file
records (:meth:`Identification.sensor`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from .._validation import InputError
from .candidates import CHAIN_PARAMS, HOST_SMOOTHING, PARAMS, Candidate
from .force import area_weighted, contact_area

__all__ = ["IdentifiedParameter", "Identification"]


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
    """What :func:`~designkit.calibration.identify.identify` found for one candidate.

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
        The transformed parameter vector (for :func:`~designkit.calibration.identify.score`).
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
            if p.name in PARAMS and p.name != "diffusivity_m2_s" and p.name not in CHAIN_PARAMS:
                kw[p.name] = p.value
        for k, v in list(kw.items()):
            if k in PARAMS and PARAMS[k].scale_with_es and k not in {p.name for p in self.parameters}:
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
            (:func:`~designkit.calibration.force.relative_force`) on ``force_time_s`` (held at its end values outside it); one
            reading per row. Without it a ``force_area`` candidate reads as full contact from the
            offset on.
        force_time_s : array_like, shape (p,), optional
            Times of ``force`` after the detected onset [s].
        force_band : float or array_like, shape (k,)
            Each ``force`` row's noise band (:func:`~designkit.calibration.force.contact_area`): for a measured force
            ``FORCE_NOISE_BAND_SD * force_noise(trial)``, as the fit reads it; 0 (default) caps the
            area at the plateau, right for a noise-free or smoothed force.
        drift : bool
            Also return the drift basis ``b`` (smoothed ``t (1 - u)``, see :class:`~designkit.calibration.candidates.Candidate`).

        Returns
        -------
        ndarray, shape (m,) or (k, m); with ``drift`` a pair (v, b) of them.
        """
        import dataclasses

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

            out[i] = area_weighted(step, grid, None if area is None else area[None, :], off)
        out, b = self.candidate.chain(grid, out, drift=drift)
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
            else PARAMS["diffusivity_m2_s"].start
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
        force over its plateau (:func:`~designkit.calibration.force.nominal_force_profile`), which questions
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
