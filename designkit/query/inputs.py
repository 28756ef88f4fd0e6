"""What a question is about: its objects, the materials rule, and its scene inputs.

The shared helpers of the question layer (both routes use them; nothing here
reads a table or simulates a touch).

The materials rule
------------------
A designer asking "tell copper from steel" wants *every* copper object told
from *every* steel object, so a question about materials is answered for the
hardest pair: the two narrow classes (one class width ``w`` each, the
table's interval width, 80 by default) at the facing edges of the two
effusivity ranges, ``[a_max - w, a_max)`` against ``[b_min, b_min + w)`` for
a material ``a`` below ``b`` (a material narrower than ``w``: its whole
range). For models that need the diffusivity, each class keeps its
material's whole diffusivity range. When the two effusivity ranges overlap,
some objects of the two materials are identical to the sensor and there is no
answer. An object given as a number ``e`` is the class ``[e, e + w)`` itself.

Examples
--------
>>> p = pair_question(m1="paper12:stainless steel", m2="paper12:aluminum")
>>> [c.e_range for c in p.classes]  # the facing edges, 80 wide
[(10104.17, 10184.17), (12767.69, 12847.69)]
>>> pair_question(e1=35000, e2=20000).classes[0].e_range
(20000.0, 20080.0)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .._validation import (InputError, check_effusivity, check_finite, check_positive,
                          check_temperature)
from ..objects import DEFAULT_CLASS_WIDTH, ObjectClass, object_class, ordered_pair

__all__ = [
    "MATERIALS_RULE",
    "NUMBERS_RULE",
    "REFERENCE_RULE",
    "NeedsInput",
    "PairQuestion",
    "TableMismatch",
    "check_contact",
    "check_threshold",
    "pair_question",
    "reference_class",
    "scene_inputs",
    "table_reroute",
]

MATERIALS_RULE = ("materials: the hardest pair, the two classes one class width wide at the facing edges of "
                  "the two effusivity ranges ([a_max - w, a_max) vs [b_min, b_min + w), a below b; a material "
                  "narrower than w: its whole range), each keeping its material's whole diffusivity range; "
                  "overlapping effusivity ranges have no answer")
NUMBERS_RULE = "numbers: an object given as an effusivity e is the class [e, e + w)"
REFERENCE_RULE = ("delta-e: the reference is the class [e, e + w) (a material: at the middle of its effusivity "
                  "range, with its whole diffusivity range); partners differ from it only in effusivity")


class NeedsInput(InputError):
    """A question lacks (or was given a needless) input; ``what`` names it (``"diffusivity"`` ...)."""

    def __init__(self, message: str, what: str):
        super().__init__(message)
        self.what = what


class TableMismatch(InputError):
    """A table cannot answer the question as asked (another model, sensor or threshold)."""


def scene_inputs(noise_c: float, delta_t_c: float) -> tuple[float, float]:
    """Checked noise sigma [degC] (>= 0) and sensor-object temperature difference [degC] (!= 0)."""
    noise = check_temperature("noise sigma [degC]", noise_c, nonnegative=True)
    dt = check_temperature("temperature difference [degC]", delta_t_c)
    if dt == 0:
        raise InputError("temperature difference is 0: an unheated sensor sees no contrast between materials")
    return noise, dt


def check_contact(contact_s: float) -> float:
    """A checked contact time [s] (> 0, finite)."""
    return check_positive("contact time [s]", contact_s)


def check_threshold(threshold: float) -> float:
    """A checked F1 threshold Phi in (2/3, 1) (2/3 is the F1 of guessing)."""
    phi = check_finite("threshold", threshold)
    if not 2 / 3 < phi < 1:
        raise InputError(f"threshold must be in (2/3, 1), got {phi:g}")
    return phi


@dataclass(frozen=True)
class PairQuestion:
    """The two objects of a pair question and the two classes the answer is for.

    Attributes
    ----------
    asked : (ObjectClass, ObjectClass)
        As named (a material's whole ranges), in the order given.
    classes : (ObjectClass, ObjectClass) or None
        The limiting pair, lower effusivity first; None when no answer exists
        (overlapping materials, see ``note``).
    width : float
        Class width w [J s^-1/2 K^-1 m^-2].
    rule : str
        The rule applied (numbers, or materials).
    note : str
        Why there is no answer (empty otherwise).
    """

    asked: tuple[ObjectClass, ObjectClass]
    classes: tuple[ObjectClass, ObjectClass] | None
    width: float
    rule: str
    note: str = ""

    @property
    def points(self) -> tuple[float, float]:
        """Lower edges of the two classes (a table's pair of effusivities)."""
        assert self.classes is not None
        return self.classes[0].e_range[0], self.classes[1].e_range[0]

    def objects_dicts(self) -> tuple[dict[str, Any], ...]:
        return tuple(o.to_dict() for o in self.asked)

    def limiting_dicts(self) -> tuple[dict[str, Any], ...]:
        return () if self.classes is None else tuple(c.to_dict() for c in self.classes)


def _one(e, m, key: str, width: float, diffusivity_m2_s) -> ObjectClass:
    if e is not None and m is not None:
        raise InputError(f"give object {key[-1]} once: as an effusivity or as a material, not both")
    if e is None and m is None:
        raise InputError("give two objects, each as an effusivity or a material name")
    if m is not None:
        return object_class(material=m)
    check_effusivity(key, e)
    return object_class(e, width=width, diffusivity_m2_s=diffusivity_m2_s)


def _edge(obj: ObjectClass, width: float, upper: bool) -> ObjectClass:
    lo, hi = obj.e_range
    if hi - lo <= width:
        return obj
    rng = (hi - width, hi) if upper else (lo, lo + width)
    side = "upper" if upper else "lower"
    return ObjectClass(f"{obj.material} ({side} edge {rng[0]:.0f}–{rng[1]:.0f})", rng, obj.diffusivity_range_m2_s,
                       obj.material)


def _require(objs, properties, model_name: str, diffusivity_given: bool) -> None:
    needs = "diffusivity_m2_s" in properties
    for o in objs:
        if needs and o.diffusivity_range_m2_s is None:
            raise NeedsInput(f"object {o.label} has no diffusivity, which the {model_name} model needs "
                             "(give it a diffusivity [m^2/s] or name a material)", "diffusivity")
    if diffusivity_given and not needs:
        raise NeedsInput(f"a diffusivity was given but the {model_name} model does not use it", "diffusivity-unused")


def pair_question(e1: float | None = None, e2: float | None = None, m1: str | None = None, m2: str | None = None,
                  *, objects=None, width: float = DEFAULT_CLASS_WIDTH, diffusivity_m2_s: float | None = None,
                  model=None) -> PairQuestion:
    """Resolve a pair question's objects and apply the materials rule.

    Parameters
    ----------
    e1, e2 : float, optional
        Effusivities [J s^-1/2 K^-1 m^-2]: the classes ``[e, e + width)``.
    m1, m2 : str, optional
        Material names (instead of ``e1`` / ``e2``).
    objects : (ObjectClass, ObjectClass), optional
        The classes themselves (instead of all of the above); a class with a
        ``material`` follows the materials rule, others are answered as given.
    width : float
        Class width w [J s^-1/2 K^-1 m^-2].
    diffusivity_m2_s : float, optional
        Diffusivity [m^2 s^-1] of the objects given as numbers (models that need it).
    model : ForwardModel or name, optional
        The forward model, to check that the objects give what it needs.
    """
    from ..models import get_model

    fm = get_model(model)
    w = check_positive("class width", width)
    if objects is not None:
        if any(x is not None for x in (e1, e2, m1, m2)):
            raise InputError("give the objects either as classes or as effusivities / material names, not both")
        a, b = objects
        if not isinstance(a, ObjectClass) or not isinstance(b, ObjectClass):
            raise InputError("objects must be two designkit.objects.ObjectClass")
        if diffusivity_m2_s is not None:
            raise InputError("a diffusivity is for objects given as numbers; classes carry their own")
    else:
        if (e1 is None and m1 is None) or (e2 is None and m2 is None):
            raise InputError("give two objects, each as an effusivity or a material name")
        if m1 is not None and m2 is not None and diffusivity_m2_s is not None:
            raise NeedsInput("a diffusivity is for objects given as numbers; both materials take their "
                             "diffusivity ranges from the materials database", "diffusivity-unused")
        if e1 is not None and e2 is not None and m1 is None and m2 is None:
            v1, v2 = check_effusivity("e1", e1), check_effusivity("e2", e2)
            if v1 == v2:
                raise InputError(f"e1 and e2 are equal ({v1:g}): nothing to separate")
        a = _one(e1, m1, "e1", w, diffusivity_m2_s)
        b = _one(e2, m2, "e2", w, diffusivity_m2_s)
    _require((a, b), fm.object_properties, fm.name, diffusivity_m2_s is not None)
    asked = (a, b)
    if a.material is None and b.material is None:
        return PairQuestion(asked, ordered_pair(a, b), w, NUMBERS_RULE)
    low, high = sorted(asked, key=lambda o: o.e_mid)
    if max(low.e_range[0], high.e_range[0]) < min(low.e_range[1], high.e_range[1]):
        note = (f"the effusivity ranges of {low.label} and {high.label} overlap: some objects of the two are "
                "identical to the sensor, so no scene tells every object of one from every object of the other")
        return PairQuestion(asked, None, w, MATERIALS_RULE, note)
    lo_c = _edge(low, w, upper=True) if low.material else low
    hi_c = _edge(high, w, upper=False) if high.material else high
    return PairQuestion(asked, (lo_c, hi_c), w, MATERIALS_RULE)


def reference_class(e: float | None = None, m: str | None = None, *, width: float = DEFAULT_CLASS_WIDTH,
                    diffusivity_m2_s=None, model=None) -> ObjectClass:
    """The reference class of a delta-e question (see :data:`REFERENCE_RULE`).

    ``diffusivity_m2_s`` is one value or a ``(low, high)`` range [m^2 s^-1] for a
    reference given as a number.

    >>> reference_class(1000.0).e_range
    (1000.0, 1080.0)
    """
    from ..models import get_model

    fm = get_model(model)
    w = check_positive("class width", width)
    if (e is None) == (m is None):
        raise InputError("give the reference either as an effusivity or as a material name")
    if m is not None:
        if diffusivity_m2_s is not None:
            raise NeedsInput(f"the diffusivity of {m!r} comes from the materials database; a diffusivity is "
                             "for a reference given as an effusivity", "diffusivity-unused")
        mat = object_class(material=m)
        mid = mat.e_mid
        ref = ObjectClass(f"{mat.material} (middle {mid:.0f})", (mid, mid + w), mat.diffusivity_range_m2_s,
                          mat.material)
    else:
        v = check_effusivity("e", e)
        d = None
        if diffusivity_m2_s is not None:
            vals = [float(x) for x in (diffusivity_m2_s if isinstance(diffusivity_m2_s, (list, tuple))
                                       else [diffusivity_m2_s])]
            if len(vals) not in (1, 2):
                raise InputError("give the reference's diffusivity as one value or a (low, high) range [m^2/s]")
            d = (check_positive("diffusivity [m^2/s]", vals[0]), check_positive("diffusivity [m^2/s]", vals[-1]))
        ref = ObjectClass(f"{v:g}", (v, v + w), d)
    _require((ref,), fm.object_properties, fm.name, m is None and diffusivity_m2_s is not None)
    return ref


def table_reroute(sensor, model, table_sensor=None, table_model=None) -> str | None:
    """Why a question about ``sensor`` under ``model`` cannot be read from a table built for another one.

    The shipped tables (``svm-fine``, ``svm-paper``, ``ideal-paper``) are for the paper's
    sensor and the semi-infinite model; by default ``table_sensor`` /
    ``table_model`` are those. Returns None when the table answers for this
    sensor and model, else one sentence for the answer's notes (the caller
    computes the answer instead: a table never answers silently for another
    sensor).

    Examples
    --------
    >>> from designkit import SENSORS
    >>> table_reroute(SENSORS["paper"], None) is None
    True
    >>> table_reroute(SENSORS["paper"].replace(effusivity=1982.0, name="mine"), None)[:53]
    'the shipped tables are for the paper sensor, not mine'
    """
    from ..models import get_model
    from ..sensor import SENSORS, load_sensor

    sen = load_sensor(sensor)
    if sen is SENSORS["paper"] and model is None and table_sensor is None:  # (the shipped tables' own: at once)
        return None
    fm = get_model(model) if model is not None else None
    ts = table_sensor if table_sensor is not None else SENSORS["paper"]
    tm = get_model(table_model)
    why = []
    if sen != ts:
        why.append(f"the {ts.name} sensor, not {sen.name}")
    if fm is not None and fm != tm:
        why.append(f"the {tm.name} model, not {fm.name}")
    if not why:
        return None
    return ("the shipped tables are for " + " and ".join(why)
            + ": computed for this sensor and model instead (--table names a table built for them)")
