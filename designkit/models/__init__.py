"""Forward models of a touch: the catalogue, by name.

Every model answers one question, the normalized reading ``u(t)`` of a touch
for an object and a sensor (:class:`~designkit.models.base.ForwardModel`);
simulation, recognition, sweeps, tables, questions and exports are written
once against that seam.

==================  =======================================  ==============
name                model                                    shared shape
==================  =======================================  ==============
``semi-infinite``   the paper's (eqs. 1-2), perfect contact  yes
``slab``            an object of finite thickness on a       no
                    backing (image series / finite volumes)
``contact``         finite interface conductance h_c         no
``layered``         heater film on a backing, h_c, the       no
                    thermistor lag and the host smoothing
``force-ramp``      any of these with a contact area that    no
                    grows while the finger presses in
==================  =======================================  ==============

Adding a model is one module defining a :class:`ForwardModel` subclass plus
one line in :data:`MODELS`. Modules load on first use, so naming a model costs
nothing until it is used.

Examples
--------
>>> from designkit.models import get_model
>>> get_model("contact", conductance_w_m2k=1500).describe()
'contact (conductance_w_m2k = 1500 W m^-2 K^-1)'
>>> get_model().name
'semi-infinite'
>>> get_model("contact:conductance_w_m2k=800").conductance_w_m2k
800.0
"""

from __future__ import annotations

import difflib
import importlib
from typing import Any, Mapping

from .._validation import InputError
from .base import ForwardModel, ModelCheck

__all__ = ["MODELS", "ForwardModel", "ModelCheck", "get_model", "load_sensor_model", "model_class", "model_names",
           "parse_model_spec", "sensor_model", "sensor_model_notes"]

#: name -> (module, class): the registry of forward models (pvlib-style catalogue).
MODELS: dict[str, tuple[str, str]] = {
    "semi-infinite": ("designkit.models.semi_infinite", "SemiInfinite"),
    "slab": ("designkit.models.slab", "Slab"),
    "contact": ("designkit.models.contact", "Contact"),
    "layered": ("designkit.models.layered", "Layered"),
    "force-ramp": ("designkit.models.ramp", "ForceRamp"),
}

_CLASSES = {cls: name for name, (_, cls) in MODELS.items()}


def model_names() -> tuple[str, ...]:
    """Names of the registered models."""
    return tuple(MODELS)


def model_class(name: str) -> type[ForwardModel]:
    """The class registered as ``name`` (unknown names: an error listing the valid ones)."""
    key = str(name).strip().lower()
    if key not in MODELS:
        close = difflib.get_close_matches(key, MODELS, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise InputError(f"unknown forward model {name!r}{hint}; known: {', '.join(MODELS)}")
    module, cls = MODELS[key]
    return getattr(importlib.import_module(module), cls)


def parse_model_spec(text: str) -> tuple[str, dict[str, Any]]:
    """``"NAME"`` or ``"NAME:KEY=VALUE,KEY=VALUE"`` as (name, parameters); numbers become floats.

    The one textual form of a model with its parameters, so that a command line
    can name any registered model without options of its own, e.g.
    ``--model contact:conductance_w_m2k=2000``.
    """
    name, _, rest = str(text).partition(":")
    params: dict[str, Any] = {}
    for item in filter(None, (p.strip() for p in rest.split(","))):
        key, eq, value = item.partition("=")
        if not eq or not key.strip():
            raise InputError(f"model parameter {item!r} in {text!r} is not KEY=VALUE")
        try:
            params[key.strip()] = float(value)
        except ValueError:
            params[key.strip()] = value.strip()
    return name.strip(), params


def get_model(spec: "str | Mapping[str, Any] | ForwardModel | None" = None, **parameters: Any) -> ForwardModel:
    """A forward model from a name (and parameters), a dict like a table header's, or a model.

    Parameters
    ----------
    spec : str, dict, ForwardModel or None
        ``None`` is the paper's semi-infinite model; a string is a name, or
        ``"NAME:KEY=VALUE,..."`` (:func:`parse_model_spec`); a dict is
        ``{"name": ..., **parameters}`` (what :meth:`ForwardModel.to_dict` writes).
    **parameters
        The model's parameters (with a name), e.g. ``conductance_w_m2k=2000``.
    """
    if isinstance(spec, ForwardModel):
        if parameters:
            raise InputError(f"parameters {sorted(parameters)} given with a model object; "
                             "use dataclasses.replace on the model instead")
        return spec
    if spec is None:
        spec = "semi-infinite"
    if isinstance(spec, Mapping):
        params = {k: v for k, v in spec.items() if k != "name"}
        if "name" not in spec:
            raise InputError(f"a model needs a name (one of {', '.join(MODELS)}), got keys {sorted(spec)}")
        return get_model(str(spec["name"]), **params, **parameters)
    name, inline = parse_model_spec(str(spec))
    clash = sorted(set(inline) & set(parameters))
    if clash:
        raise InputError(f"model parameter {', '.join(clash)} given twice")
    parameters = {**inline, **parameters}
    cls = model_class(name)
    fields = {f for f in getattr(cls, "__dataclass_fields__", {})}
    unknown = sorted(set(parameters) - fields)
    if unknown:
        raise InputError(f"model {cls.name!r} has no parameter {', '.join(unknown)}; "
                         f"its parameters: {', '.join(sorted(fields)) or 'none'}")
    try:
        return cls(**parameters)
    except TypeError as exc:  # pragma: no cover - a missing required parameter
        raise InputError(f"model {cls.name!r}: {exc}") from None


def sensor_model(sensor) -> ForwardModel:
    """The forward model a sensor was identified with (its file's ``model:``; none: the semi-infinite model).

    A record with a ``contact_area`` (calibrated with the force-driven contact area) gives the model
    with the nominal force ramp it records (:class:`~designkit.models.ramp.ForceRamp`: the calibration
    touches' median force over its plateau, through the fitted threshold ``c``): a question has no
    force trace of its own. A record's ``drift`` is a per-touch nuisance (each touch's heater still
    warming) and plays no part: a new touch has no drift.

    Parameters
    ----------
    sensor : designkit.Sensor
        A sensor whose ``model`` record is None or ``{"name": ..., "params": {...}, ...}``.

    Examples
    --------
    >>> from designkit import SENSORS
    >>> sensor_model(SENSORS["paper"]).name
    'semi-infinite'
    >>> s = SENSORS["paper"].replace(model={"name": "contact", "params": {"conductance_w_m2k": 2500.0}})
    >>> sensor_model(s).describe()
    'contact (conductance_w_m2k = 2500 W m^-2 K^-1)'
    """
    record = getattr(sensor, "model", None)
    if record is None:
        return get_model("semi-infinite")
    try:
        base = get_model(str(record["name"]), **dict(record.get("params") or {}))
        area = record.get("contact_area")
        if not area:
            return base
        from .ramp import ForceRamp

        missing = [k for k in ("force_fraction", "time_s", "force_share") if area.get(k) is None]
        if missing:
            raise InputError(f"contact_area needs {', '.join(missing)}")
        return ForceRamp.from_force_profile(
            base, area["time_s"], area["force_share"], float(area["force_fraction"]),
            source=f"the median force ramp of {area.get('n_touches', 'the')} calibration touches",
            touch_force_rel=area.get("touch_force_share") or ())
    except InputError as exc:
        raise InputError(f"sensor {sensor.name!r}: its recorded model: {exc}") from None


def sensor_model_notes(sensor, model: "ForwardModel | None" = None) -> list[str]:
    """What an answer says about the model a sensor file recorded: which, and what it plays for a touch.

    One line naming the model (and the calibration candidate), one on the
    contact area when the model has a force ramp (a question has no force
    trace: the calibration touches' median ramp), one on the heater drift when
    calibration fitted one per touch (a nuisance, not a property of the
    sensor: a question's touch has none). Empty for the semi-infinite model
    without extras.

    Parameters
    ----------
    sensor : designkit.Sensor
    model : ForwardModel, optional
        The model that answered (default: :func:`sensor_model` of ``sensor``).

    Examples
    --------
    >>> from designkit import SENSORS
    >>> s = SENSORS["paper"].replace(name="rig", model={"name": "contact", "params": {"conductance_w_m2k": 2500.0},
    ...                                                 "drift": "per-touch"})
    >>> for line in sensor_model_notes(s):
    ...     print(line[:60])
    model contact: recorded in sensor file rig
    heater drift: fitted per touch in calibration (a nuisance li
    """
    record = getattr(sensor, "model", None)
    if record is None:
        return []
    fm = sensor_model(sensor) if model is None else model
    ramp = getattr(fm, "name", "") == "force-ramp"
    name = fm.base.name if ramp else fm.name
    cand = record.get("candidate")
    out = []
    if name != "semi-infinite" or ramp or record.get("drift"):
        out.append(f"model {name}{' with a force-driven contact area' if ramp else ''}: recorded in sensor file "
                   f"{sensor.name}" + (f" (calibrated as {cand})" if cand and cand != name else ""))
    if ramp:
        n = (record.get("contact_area") or {}).get("n_touches", "?")
        d = [v for v, _, _ in fm.touch_ramps]
        how = (f"each simulated touch presses as one of them (its own ramp, first contact {min(d):+.2f} to "
               f"{max(d):+.2f} s from the median's)" if d else "a question has no force trace")
        out.append(f"contact area: the median force ramp of the {n} calibration touches ({how}), area share "
                   f"clip((F/F_p - c)/(1 - c), 0, 1) with c = {fm.force_fraction:.3g}; the whole area is in contact "
                   f"{fm.ramp_duration_s:.2f} s after the first contact, from which the contact time counts")
    if record.get("drift"):
        out.append("heater drift: fitted per touch in calibration (a nuisance like the touch's initial "
                   "temperature, not a property of the sensor); not played here: a new touch has none")
    return out


def load_sensor_model(spec="paper", model: "str | Mapping[str, Any] | ForwardModel | None" = None):
    """A sensor (preset name, YAML path or Sensor) and the forward model that answers for it.

    ``model`` None takes the model the sensor file records (the semi-infinite
    model for presets and files without ``model:``); a model given explicitly
    overrides it.

    Returns
    -------
    (Sensor, ForwardModel)

    Examples
    --------
    >>> s, m = load_sensor_model("paper")
    >>> s.name, m.name
    ('paper', 'semi-infinite')
    """
    from ..sensor import load_sensor

    sensor = load_sensor(spec if spec is not None else "paper")
    return sensor, (sensor_model(sensor) if model is None else get_model(model))


def __getattr__(name: str):
    # ``from designkit.models import Contact`` loads its module on first use.
    if name in _CLASSES:
        return model_class(_CLASSES[name])
    raise AttributeError(f"module 'designkit.models' has no attribute {name!r}")
