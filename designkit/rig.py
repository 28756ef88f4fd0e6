"""The rig as calibrated: its operating conditions, recorded in the sensor file, as a question's defaults.

Calibration sees the rig at work: the heated sensor's and the objects' temperatures before each
touch (so the temperature difference dT and its spread from touch to touch), the noise, how the
force ramps up, and the rule by which its recorder detects contact. :func:`rig_conditions`
records them (a sensor file's ``conditions``); :func:`resolve_scene` makes them the scene of a
question about that sensor unless the user gives a value, and says where each value came from
(``"user"``, ``"sensor file"`` or ``"default"``).

Contact time. A rig's controller counts contact from its detected onset; the model counts from
the first heat flow, ``onset_offset_s`` from the onset (negative: before it; for a force-driven
contact area, the first share's contact). A question about a calibrated sensor takes and gives
contact times from the detected onset: the model's contact is the asked one minus the offset
(:func:`to_model_contact`, :func:`from_model_contact`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from ._validation import InputError
from .sensor import CONDITION_KEYS

__all__ = ["CONDITION_KEYS", "DEFAULTS", "RigConditions", "RigScene", "for_rig", "from_model_contact",
           "model_start_s", "residual_correlation_s", "resolve_scene", "rig_arguments", "rig_conditions",
           "rig_scene", "to_model_contact"]

#: A question's scene without a sensor file's conditions (and for the paper's sensor): noise [degC], dT [degC].
DEFAULTS = {"noise_c": 0.05, "delta_t_c": 10.0, "sensor_temp_spread_c": 0.0}
@dataclass(frozen=True)
class RigConditions:
    """Operating conditions of a rig as its calibration touches show them.

    Attributes
    ----------
    noise_c : float
        The noise a question plays [degC per sample]: the larger of the pre-contact noise and the
        identified model's residual on the calibration touches (what the model does not explain of a
        real touch; ``noise_source`` says which).
    noise_source : str
    pre_contact_noise_c, residual_rms_c : float
        Both candidates [degC].
    sensor_temp_c, object_temp_c, delta_t_c : (float, float)
        Mean and standard deviation over the touches of the sensor's reading before contact, the
        object's (passive channel before contact; touches without one are left out) and their
        difference [degC].
    sensor_temp_spread_c : float
        Half-width [degC] of the uniform spread of dT with the touches' standard deviation
        (``sqrt(3) sd``): what ``--sensor-temp-spread`` plays.
    onset : str
        How the recorder detected contact (its rule), or that the recording's time 0 was taken.
    onset_offset_s : float
        The model's first heat flow relative to the detected onset [s] (negative: before it).
    noise_correlation_s : float
        Correlation length [s] of the identified model's residual on the calibration touches (the
        Matern-3/2 autocorrelation fitted to it, :func:`residual_correlation_s`; 0: not measured, white).
        A rig's misfit wanders smoothly over a touch, so it does not average away over its samples as
        white noise would.
    contact_ramp : mapping or None
        ``{"rise_s": s, "to_share": 0.9}``: median time from the detected onset until the force
        reaches 90 % of its plateau (touches with a force channel).
    n_touches : int
    """

    noise_c: float
    noise_source: str
    pre_contact_noise_c: float
    residual_rms_c: float
    sensor_temp_c: tuple[float, float]
    object_temp_c: tuple[float, float]
    delta_t_c: tuple[float, float]
    sensor_temp_spread_c: float
    onset: str
    onset_offset_s: float
    contact_ramp: Mapping[str, float] | None = None
    n_touches: int = 0
    noise_correlation_s: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        def pair(v):
            return {"mean": round(float(v[0]), 4), "sd": round(float(v[1]), 4)}

        return {"noise_c": float(self.noise_c), "noise_source": self.noise_source,
                "pre_contact_noise_c": float(self.pre_contact_noise_c), "residual_rms_c": float(self.residual_rms_c),
                "sensor_temp_c": pair(self.sensor_temp_c), "object_temp_c": pair(self.object_temp_c),
                "delta_t_c": pair(self.delta_t_c), "sensor_temp_spread_c": round(float(self.sensor_temp_spread_c), 4),
                "onset": self.onset,
                "onset_offset_s": round(float(self.onset_offset_s), 4) if math.isfinite(self.onset_offset_s) else None,
                "contact_ramp": None if self.contact_ramp is None else dict(self.contact_ramp),
                "n_touches": int(self.n_touches),
                "noise_correlation_s": round(float(self.noise_correlation_s), 4)}


def residual_correlation_s(residuals: Sequence[np.ndarray], sample_rate_hz: float, *, max_lag_s: float = 2.0) -> float:
    """Correlation length [s] of residual series: the Matern-3/2 autocorrelation
    ``(1 + a) exp(-a)``, ``a = sqrt(3) lag / l``, fitted (least squares over lags up to ``max_lag_s``)
    to their pooled autocorrelation about 0 (residuals of a fit: their mean is part of the wander, not
    removed). 0 when there is too little to tell.

    Examples
    --------
    >>> from designkit.simulation import correlate_noise
    >>> z = correlate_noise(np.random.default_rng(0).standard_normal((40, 600)), 200.0, 0.5)
    >>> round(residual_correlation_s(list(z), 200.0), 1)
    0.5
    """
    from scipy.optimize import minimize_scalar

    rows = [np.asarray(r, dtype=np.float64) for r in residuals if np.size(r) >= 8]
    if not rows:
        return 0.0
    n_lag = min(int(max_lag_s * sample_rate_hz), min(r.size for r in rows) // 2)
    acf, weight = np.zeros(n_lag + 1), np.zeros(n_lag + 1)
    for r in rows:
        acf += np.correlate(r, r, "full")[r.size - 1:r.size + n_lag]
        weight += r.size - np.arange(n_lag + 1)
    acf = acf / weight
    if not acf[0] > 0:
        return 0.0
    acf /= acf[0]
    lag = np.arange(n_lag + 1) / float(sample_rate_hz)

    def misfit(log_l):
        a = math.sqrt(3.0) * lag / math.exp(log_l)
        return float(np.sum(((1.0 + a) * np.exp(-a) - acf) ** 2))

    lo, hi = math.log(0.5 / sample_rate_hz), math.log(100.0)
    best = minimize_scalar(misfit, bounds=(lo, hi), method="bounded")
    return float(math.exp(best.x)) if best.x > lo + 1e-3 else 0.0


def rig_conditions(trials: Sequence[Any], *, pre_contact_noise_c: float, residual_rms_c: float,
                   onset_offset_s: float, residuals: Sequence[np.ndarray] = (),
                   sample_rate_hz: float = 200.0) -> RigConditions:
    """The conditions of the touches ``trials`` (:class:`~designkit.calibration.trials.Trial`).

    Examples
    --------
    >>> from designkit.calibration.trials import Trial
    >>> t = np.arange(-200, 400) / 200.0
    >>> trs = [Trial(t, np.full(t.size, 30.0 + d), np.full(t.size, 22.0), np.clip(t, 0, 0.5) * 8, "wood")
    ...        for d in (-0.2, 0.0, 0.2)]
    >>> c = rig_conditions(trs, pre_contact_noise_c=0.001, residual_rms_c=0.03, onset_offset_s=-0.2)
    >>> [round(v, 6) for v in c.delta_t_c], c.noise_c, c.contact_ramp
    ([8.0, 0.2], 0.03, {'rise_s': 0.45, 'to_share': 0.9})
    """
    if not trials:
        raise InputError("no touches to read the rig's conditions from")
    ts0, to, rises, rules = [], [], [], set()
    for tr in trials:
        pre = tr.time_s < 0
        if pre.sum() < 1:
            continue
        s, o = tr.before_contact()
        ts0.append(s)
        to.append(o)
        f = np.asarray(tr.force_n, dtype=np.float64)
        late = tr.time_s >= 1.0
        if np.isfinite(f).all() and late.any():
            plateau = float(np.median(f[late]))
            after = np.flatnonzero((tr.time_s >= 0) & (f >= 0.9 * plateau))
            if plateau > 0 and after.size:
                rises.append(float(tr.time_s[after[0]]))
        rule = (tr.meta or {}).get("contact_rule")
        rules.add(_rule_text(rule) if rule else "the recording's time 0 (its recorder's own onset)")
    ts0_a, to_a = np.array(ts0), np.array(to)
    dt = ts0_a - to_a
    dt = dt[np.isfinite(dt)]

    def mean_sd(v):
        v = v[np.isfinite(v)]
        return (float(np.mean(v)), float(np.std(v, ddof=1)) if v.size > 1 else 0.0) if v.size else (math.nan, 0.0)

    noise = max(pre_contact_noise_c, residual_rms_c) if math.isfinite(residual_rms_c) else pre_contact_noise_c
    source = ("the identified model's residual RMS on the calibration touches (what it does not explain of a real "
              "touch; above the pre-contact noise)" if noise == residual_rms_c else "the pre-contact noise")
    d = mean_sd(dt)
    return RigConditions(float(noise), source, float(pre_contact_noise_c), float(residual_rms_c), mean_sd(ts0_a),
                         mean_sd(to_a), d, math.sqrt(3.0) * d[1], "; ".join(sorted(rules)), float(onset_offset_s),
                         {"rise_s": round(float(np.median(rises)), 4), "to_share": 0.9} if rises else None,
                         len(ts0), residual_correlation_s(residuals, sample_rate_hz) if len(residuals) else 0.0)


def rig_scene(sensor) -> dict[str, float]:
    """The Scene fields (:class:`designkit.scene.Scene`) that make a simulated touch the rig's: the noise's
    correlation length, and the recorder's window from its detected onset (model time, at least 0). Empty
    for a sensor without recorded conditions (presets, older files: the paper's white noise from the first
    heat flow)."""
    cond = getattr(sensor, "conditions", None) or {}
    if not cond:
        return {}
    start = model_start_s(sensor)
    return {"noise_correlation_s": float(cond.get("noise_correlation_s") or 0.0),
            "onset_s": max(-start, 0.0) if start is not None else 0.0}


def question_scene(sensor, **scene):
    """The scene a question about ``sensor`` plays (:meth:`designkit.scene.Scene.from_delta_t` of ``scene``),
    with a calibrated rig's correlated noise and its recorder's window from the detected onset
    (:func:`rig_scene`; nothing added for a sensor without recorded conditions). The SVM and the Monte Carlo
    ideal observer of the exact route both read their touches from it."""
    from .scene import Scene

    return Scene.from_delta_t(**scene).replace(**rig_scene(sensor))


def _rule_text(rule: Mapping[str, Any]) -> str:
    kind = rule.get("rule", "?")
    if kind == "force":
        return f"force above {rule.get('force_threshold_n', '?')} N"
    return f"{kind} rule " + ", ".join(f"{k} {v}" for k, v in rule.items() if k != "rule")


def model_start_s(sensor) -> float | None:
    """The model's time 0 relative to the rig's detected onset [s] (None: the file records no rig conditions).

    The recorded time offset of the heat flow, plus, for a force-driven contact area, the time after the
    onset at which the nominal force ramp puts down its first share. Files without ``conditions`` (presets,
    older files) keep counting from the model's own time 0.
    """
    if not getattr(sensor, "conditions", None):
        return None
    return record_start_s(getattr(sensor, "model", None))


def record_start_s(record: Mapping[str, Any] | None) -> float | None:
    """:func:`model_start_s` of a sensor file's ``model`` record (None without a time offset)."""
    if record is None or record.get("time_offset_s") is None:
        return None
    t0 = float(record["time_offset_s"])
    area = record.get("contact_area")
    if area and area.get("time_s") is not None:
        from .models.ramp import area_share

        share = area_share(np.asarray(area["force_share"], dtype=np.float64), float(area["force_fraction"]))
        on = np.flatnonzero(np.maximum.accumulate(share) > 0)
        if on.size:
            t0 += float(np.asarray(area["time_s"])[on[0]])
    return t0


def to_model_contact(contact_s: float, start_s: float | None) -> float:
    """A contact counted from the detected onset [s] as the model counts it (from its first heat flow)."""
    return contact_s if start_s is None else contact_s - start_s


def from_model_contact(contact_s, start_s: float | None):
    """A model contact time [s] counted from the rig's detected onset (None passes through)."""
    if contact_s is None or start_s is None:
        return contact_s
    return contact_s + start_s


@dataclass(frozen=True)
class RigScene:
    """A question's scene with each value's source.

    Attributes
    ----------
    values : dict
        ``noise_c``, ``delta_t_c``, ``sensor_temp_spread_c`` (and ``contact_s`` when asked: as the
        model counts it).
    sources : dict
        Per key ``"user"``, ``"sensor file"`` or ``"default"``.
    start_s : float or None
        The model's time 0 relative to the detected onset (None: the model's own t = 0 counts).
    notes : tuple of str
    calibrated : bool
        The sensor file records the rig's conditions (else the answer is left as it is: presets and
        older files answer with the defaults, as before).
    """

    values: Mapping[str, float]
    sources: Mapping[str, str]
    start_s: float | None
    notes: tuple[str, ...] = field(default=())
    calibrated: bool = True

    def conditions(self, asked_contact_s: float | None = None) -> dict[str, Any]:
        """``{key: {"value", "source"}}`` for ``--json`` (the contact as asked, from the onset)."""
        out = {k: {"value": v, "source": self.sources[k]} for k, v in self.values.items() if k != "contact_s"}
        if "contact_s" in self.values:
            out["contact_s"] = {"value": asked_contact_s, "source": self.sources["contact_s"],
                                "counted_from": "detected onset" if self.start_s is not None else "first heat flow",
                                "model_contact_s": self.values["contact_s"]}
        out["onset_offset_s"] = {"value": self.start_s, "source": "sensor file" if self.start_s is not None
                                 else "default"}
        return out


def resolve_scene(sensor, given: Mapping[str, float | None]) -> RigScene:
    """A question's scene: each value the user gave, else the sensor file's condition, else the default.

    ``given`` holds the keys the question takes (``noise_c``, ``delta_t_c``,
    ``sensor_temp_spread_c``, ``contact_s``), None where the user gave nothing. A contact time
    counts from the rig's detected onset when the sensor file records one. The rig's spread of dT
    is recorded but not played unless given (a note says how).

    Examples
    --------
    >>> from designkit import SENSORS
    >>> sc = resolve_scene(SENSORS["paper"], {"noise_c": None, "delta_t_c": 7.0})
    >>> sc.values, sc.sources
    ({'noise_c': 0.05, 'delta_t_c': 7.0}, {'noise_c': 'default', 'delta_t_c': 'user'})
    """
    cond = getattr(sensor, "conditions", None) or {}
    # the touch-to-touch spread of dT is recorded, not played by default: varied initial conditions are
    # computed pair by pair, and the Monte Carlo ideal observer of some models (force-ramp) takes fixed ones only
    from_file = {"noise_c": cond.get("noise_c"), "delta_t_c": (cond.get("delta_t_c") or {}).get("mean")}
    values, sources, notes = {}, {}, []
    for key, v in given.items():
        if key == "contact_s":
            continue
        if v is not None:
            values[key], sources[key] = _number(v), "user"
        elif from_file.get(key) is not None and math.isfinite(float(from_file[key])):
            values[key], sources[key] = float(from_file[key]), "sensor file"
        else:
            values[key], sources[key] = float(DEFAULTS[key]), "default"
    start = model_start_s(sensor)
    if "contact_s" in given and given["contact_s"] is not None:
        asked = _number(given["contact_s"])
        values["contact_s"] = to_model_contact(asked, start)
        sources["contact_s"] = "user"
        early = np.ravel((np.asarray(values["contact_s"]) <= 0) & (np.asarray(asked) > 0))
        if start is not None and early.any():
            bad = float(np.ravel(asked)[np.flatnonzero(early)[0]])
            raise InputError(f"contact {bad:g} s after the rig's detected onset ends before the "
                             f"model's first heat flow ({start:+.3g} s from the onset): give a longer contact")
    used = [f"{k} {_words(values[k])} ({sources[k]})" for k in values if k != "contact_s"]
    if cond:
        notes.append(f"the rig as calibrated (sensor file {sensor.name}): " + ", ".join(used))
        spread = cond.get("sensor_temp_spread_c")
        if spread and given.get("sensor_temp_spread_c") is None and "sensor_temp_spread_c" in given:
            notes.append(f"the rig's dT varied from touch to touch (SD {(cond.get('delta_t_c') or {}).get('sd', 0):.2g}"
                         f" °C): not played by default; --sensor-temp-spread {spread:.2g} plays it")
    if start is not None:
        notes.append(f"contact time counts from the rig's detected onset ({cond.get('onset') or 'as recorded'}), "
                     f"as its controller measures it; the model's heat flow starts {start:+.3g} s from it"
                     + ("; simulated touches are read from the onset on, as the rig's recognizer reads them"
                        if start < 0 else ""))
    if cond.get("noise_correlation_s"):
        notes.append(f"the noise is correlated over {float(cond['noise_correlation_s']):.2g} s, as the identified "
                     "model's residual on the calibration touches (sensor file): it wanders over a touch instead of "
                     "averaging away")
    return RigScene(values, sources, start, tuple(notes), bool(cond))


def _number(v):
    """A scene value as given: a float, or a float64 array (array questions)."""
    return float(v) if np.ndim(v) == 0 else np.asarray(v, dtype=np.float64)


def _words(v) -> str:
    return f"{v:g}" if np.ndim(v) == 0 else "as given per element"


def rig_arguments(scene_keys: Sequence[str], arguments: Mapping[str, Any]) -> tuple[dict[str, Any], RigScene | None]:
    """A question's arguments with its scene resolved for the sensor asked about (:func:`resolve_scene`).

    ``scene_keys``: the scene quantities the question takes (:attr:`designkit.query.Question.scene`); with
    ``sensor_temp_spread_c`` they may be None or absent, meaning "the sensor file's recorded conditions, else
    the paper's defaults". For a sensor file with the rig's conditions each is resolved (a contact time, asked
    from the rig's detected onset, becomes the model's), and the :class:`RigScene` comes back for
    :func:`for_rig`; otherwise the values not given are left to the route's defaults (None back). The one
    place a question's scene is resolved: :func:`designkit.query.ask` calls it.

    Examples
    --------
    >>> args, rig = rig_arguments(("noise_c", "delta_t_c"), {"e1": 35000.0, "e2": 20000.0, "noise_c": None})
    >>> args, rig
    ({'e1': 35000.0, 'e2': 20000.0}, None)
    """
    keys = (*scene_keys, "sensor_temp_spread_c")
    sensor = arguments.get("sensor")
    sen = None
    if sensor is not None:
        from .sensor import load_sensor

        sen = load_sensor(sensor)
    if sen is None or not getattr(sen, "conditions", None):
        return {k: v for k, v in arguments.items() if not (k in keys and v is None)}, None
    rig = resolve_scene(sen, {k: arguments.get(k) for k in keys})
    return {**arguments, "sensor": sen, **{k: rig.values[k] for k in keys}}, rig  # (the file read once)


def for_rig(answer, scene: RigScene, asked_contact_s: float | None = None):
    """An answer (:class:`~designkit.query.answer.Answer`) as the rig sees it.

    A min-contact answer (and its interval and ideal bound) is counted from the rig's detected onset
    (the model's time plus :attr:`RigScene.start_s`, at least 0); the scene gets the conditions and
    their sources (``scene["conditions"]``), the notes say so. Unchanged for a sensor without
    recorded conditions.
    """
    import dataclasses

    if not scene.calibrated:
        return answer
    if not hasattr(answer, "scene"):  # an array answer (designkit.query.ArrayAnswer)
        return _arrays_for_rig(answer, scene, asked_contact_s)
    changes: dict[str, Any] = {}
    if answer.question == "min-contact" and scene.start_s is not None:
        def shift(v):
            return None if v is None or not math.isfinite(float(v)) else max(float(v) + scene.start_s, 0.0)

        changes["value"] = shift(answer.value)
        changes["interval"] = tuple(shift(v) for v in answer.interval)
        ib = answer.ideal_bound
        if ib is not None and not isinstance(ib.value, bool):
            iv = None if ib.interval is None else (shift(ib.interval[0]), shift(ib.interval[1]), ib.interval[2])
            changes["ideal_bound"] = dataclasses.replace(ib, value=shift(ib.value), interval=iv)
    sc = dict(answer.scene)
    if "contact_s" in sc and asked_contact_s is not None:
        sc["contact_s"] = asked_contact_s
    sc["conditions"] = scene.conditions(asked_contact_s)
    changes["scene"] = sc
    notes = tuple(answer.notes)
    if scene.start_s is not None:  # the model's own time 0 no longer counts: the onset does
        notes = tuple(n.replace(", from which the contact time counts", "") for n in notes)
    notes += tuple(n for n in scene.notes if n not in notes)
    changes["notes"] = notes
    return dataclasses.replace(answer, **changes)


def _arrays_for_rig(answer, scene: RigScene, asked_contact_s):
    """:func:`for_rig` of an array answer: min-contact's arrays counted from the onset, the conditions stated."""
    import dataclasses

    changes: dict[str, Any] = {"conditions": scene.conditions(asked_contact_s)}
    if answer.question == "min-contact" and scene.start_s is not None:
        for k in ("value", "low", "high", "ideal"):
            changes[k] = np.maximum(np.asarray(getattr(answer, k)) + scene.start_s, 0.0)  # (NaN stays NaN)
    return dataclasses.replace(answer, **changes)
