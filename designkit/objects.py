"""Object classes: what a robot must tell apart.

An :class:`ObjectClass` is a population of objects: effusivity uniform in a
range (the paper's 80-wide "material category", or a material's whole
database range) and, for forward models that need it (a slab), diffusivity
uniform in a range. Simulation draws touches from it; recognition tells two
of them apart.

Units: effusivity [J s^-1/2 K^-1 m^-2], diffusivity [m^2 s^-1].
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ._validation import InputError, check_effusivity, check_effusivity_range, check_positive

__all__ = ["DEFAULT_CLASS_WIDTH", "ObjectClass", "object_class", "ordered_pair"]

#: The paper's class width: (0, 40000] cut into 500 intervals [J s^-1/2 K^-1 m^-2].
DEFAULT_CLASS_WIDTH = 80.0


@dataclass(frozen=True)
class ObjectClass:
    """A class of objects: effusivity (and diffusivity) uniform in ranges.

    Attributes
    ----------
    label : str
        Name shown in answers and reports.
    e_range : (float, float)
        Effusivity ``[low, high)`` [J s^-1/2 K^-1 m^-2]; ``low == high`` is one value.
    diffusivity_range_m2_s : (float, float) or None
        Diffusivity ``[low, high]`` [m^2 s^-1]; None where no model asks for it.
    material : str or None
        Database name, when the class is a material.

    Examples
    --------
    >>> ObjectClass("wood", (331.0, 506.46)).e_mid
    418.73
    """

    label: str
    e_range: tuple[float, float]
    diffusivity_range_m2_s: tuple[float, float] | None = None
    material: str | None = None

    def __post_init__(self) -> None:
        lo, hi = check_effusivity_range(self.label, *self.e_range)
        object.__setattr__(self, "e_range", (lo, hi))
        if self.diffusivity_range_m2_s is not None:
            a_lo = check_positive(f"diffusivity of {self.label} [m^2/s]", self.diffusivity_range_m2_s[0])
            a_hi = check_positive(f"diffusivity of {self.label} [m^2/s]", self.diffusivity_range_m2_s[1])
            if a_hi < a_lo:
                raise InputError(f"diffusivity range of {self.label} must have low <= high, "
                                 f"got [{a_lo:g}, {a_hi:g}]")
            object.__setattr__(self, "diffusivity_range_m2_s", (a_lo, a_hi))

    @property
    def e_mid(self) -> float:
        """Middle of the effusivity range."""
        return 0.5 * (self.e_range[0] + self.e_range[1])

    @property
    def key(self) -> tuple[float, ...]:
        """Ordering key: effusivity midpoint first (the higher class is the positive one)."""
        d = self.diffusivity_range_m2_s or (0.0, 0.0)
        return (self.e_mid, 0.5 * (d[0] + d[1]), *self.e_range)

    def require(self, properties) -> "ObjectClass":
        """This class, checked to give every property in ``properties`` (a model's needs)."""
        if "diffusivity_m2_s" in properties and self.diffusivity_range_m2_s is None:
            raise InputError(f"object {self.label} has no diffusivity, which this model needs "
                             "(give it as a number or name a material)")
        return self

    def to_dict(self) -> dict[str, Any]:
        return {"label": self.label, "material": self.material, "effusivity_range": list(self.e_range),
                "diffusivity_range_m2_s": None if self.diffusivity_range_m2_s is None
                else list(self.diffusivity_range_m2_s)}


def object_class(e: float | None = None, material: str | None = None, *, width: float = DEFAULT_CLASS_WIDTH,
                 diffusivity_m2_s: float | None = None) -> ObjectClass:
    """An object class from an effusivity (a class ``[e, e + width)``) or a material name.

    Parameters
    ----------
    e : float, optional
        Effusivity [J s^-1/2 K^-1 m^-2].
    material : str, optional
        A material of :mod:`designkit.materials`: its effusivity and
        diffusivity ranges are the class.
    width : float
        Class width for ``e`` [J s^-1/2 K^-1 m^-2] (the paper's 80).
    diffusivity_m2_s : float, optional
        Diffusivity of an object given by ``e`` [m^2 s^-1].
    """
    if (e is None) == (material is None):
        raise InputError("give an object either as an effusivity or as a material name")
    if material is not None:
        if diffusivity_m2_s is not None:
            raise InputError(f"the diffusivity of {material!r} comes from the materials database")
        from .materials import get_material

        mat = get_material(material)
        d = (mat.diffusivity_min_m2_s, mat.diffusivity_max_m2_s)
        return ObjectClass(f"{mat.name} ({mat.e_min:.0f}–{mat.e_max:.0f})", (mat.e_min, mat.e_max),
                           d if all(x > 0 for x in d) else None, mat.name)
    v = check_effusivity("e", e)
    w = check_positive("class width", width)
    d = None if diffusivity_m2_s is None else (check_positive("diffusivity [m^2/s]", diffusivity_m2_s),) * 2
    return ObjectClass(f"{v:.10g}", (v, v + w), d)  # the value as typed (9999999, not 1e+07)


def ordered_pair(a: ObjectClass, b: ObjectClass) -> tuple[ObjectClass, ObjectClass]:
    """The two classes, lower effusivity first; identical classes are refused.

    Examples
    --------
    >>> [c.e_range for c in ordered_pair(object_class(35000), object_class(20000))]
    [(20000.0, 20080.0), (35000.0, 35080.0)]
    """
    if a.e_range == b.e_range and a.diffusivity_range_m2_s == b.diffusivity_range_m2_s:
        raise InputError(f"the two objects are identical ({a.label}): nothing to separate")
    return (a, b) if a.key <= b.key else (b, a)
