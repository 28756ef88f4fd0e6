"""Materials: effusivity and diffusivity ranges of engineering material families.

Two named sets are shipped in ``designkit/data/materials.yaml`` (described in
``docs/materials.md``):

``database``
    A public stand-in for the CES EduPack 2016 Level-1 database used by the
    reference paper (Bai et al., section V): engineering material families in
    the paper's four families, each with handbook ranges of thermal
    conductivity k, density rho and specific heat c. Effusivity and
    diffusivity ranges are derived here at load time, never typed:

    - ``e = sqrt(k rho c)`` [J s^-1/2 K^-1 m^-2] (paper eq. 1,
      :func:`designkit.properties.effusivity`); ``e_min`` from the three minima,
      ``e_max`` from the three maxima. e grows with each property, so this
      "corner rule" gives the widest interval the ranges allow (properties
      correlate in real grades, so the true spread is narrower).
    - ``alpha = k / (rho c)`` [m^2 s^-1]; ``alpha_min = k_min / (rho_max c_max)``,
      ``alpha_max = k_max / (rho_min c_min)`` (same rule; alpha falls with rho
      and c).

``paper12``
    The paper's 12 robot-experiment materials with the identified effusivity
    and the range printed in its appendix table (docs/physics.md section 3), k, rho
    and c unknown. Each names the ``database`` entry that supplies its
    diffusivity range and family (``diffusivity_from``).

Names are matched case-insensitively, ignoring punctuation, word order, a
plural ``s`` and British/American spelling (``"steel, stainless"`` is
``"Stainless steel"``, ``"aluminum alloy"`` is ``"Aluminium alloys"``), and
through each entry's aliases (``"acrylic"`` is PMMA). A name is looked up in
``database`` first, then in ``paper12``; a ``paper12:`` or ``database:``
prefix picks a set (``"paper12:copper"``).

The file is read and validated on first use (nothing happens at import) and
kept with :func:`functools.lru_cache`.
"""

from __future__ import annotations

import difflib
import functools
import math
import re
import types
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Mapping

import numpy as np

from ._validation import InputError, check_effusivity

__all__ = [
    "FAMILIES",
    "FAMILY_LABELS",
    "MATERIALS_FILE_VERSION",
    "SETS",
    "Material",
    "MaterialTable",
    "get_material",
    "list_materials",
    "load_material_table",
    "material_or_effusivity",
    "remember_shipped_table",
]

MATERIALS_FILE_VERSION = 1

#: The paper's four material families (CES EduPack categories), as keys.
FAMILIES: tuple[str, ...] = ("metals", "ceramics", "polymers", "composites")

#: Human labels of :data:`FAMILIES`.
FAMILY_LABELS: Mapping[str, str] = types.MappingProxyType({
    "metals": "metals and alloys",
    "ceramics": "ceramics and glasses",
    "polymers": "polymers and elastomers",
    "composites": "composites, foams and natural materials",
})

#: The named sets, in lookup precedence order.
SETS: tuple[str, ...] = ("database", "paper12")

#: Flag a paper12 entry must carry when its identified value lies outside its range.
FLAG_IDENTIFIED_OUTSIDE = "identified_outside_range"
_KNOWN_FLAGS = frozenset({FLAG_IDENTIFIED_OUTSIDE})

# Token spellings treated as equal in names (British -> American, variants).
_SYNONYMS = {
    "aluminium": "aluminum",
    "grey": "gray",
    "fibre": "fiber",
    "fibreboard": "fiberboard",
    "fibreglass": "fiberglass",
    "sulphur": "sulfur",
    "colour": "color",
}
_TOKEN = re.compile(r"[0-9a-z]+")


def _name_key(name: str) -> str:
    """Matching key of a name: lower case, alphanumeric words, synonyms, no plural s, sorted.

    ``"Steel, stainless"`` and ``"stainless STEEL"`` give the same key; so do
    ``"Aluminium alloys"`` and ``"aluminum alloy"``.
    """
    words = []
    for w in _TOKEN.findall(str(name).lower()):
        w = _SYNONYMS.get(w, w)
        if len(w) > 3 and w.endswith("s") and not w.endswith("ss"):
            w = w[:-1]
        words.append(w)
    return " ".join(sorted(words))


@dataclass(frozen=True)
class Material:
    """One material (family) with its thermal property ranges.

    Parameters
    ----------
    name : str
        Display name.
    family : str
        One of :data:`FAMILIES`.
    set : str
        The named set it belongs to (``"database"`` or ``"paper12"``).
    e_min, e_max : float
        Effusivity range [J s^-1/2 K^-1 m^-2].
    identified : float or None
        Effusivity identified by the paper's sensor calibration (paper12 only).
    conductivity_min_w_mk, conductivity_max_w_mk : float or None
        Thermal conductivity range k [W m^-1 K^-1] (None when unknown).
    density_min_kg_m3, density_max_kg_m3 : float or None
        Density range rho [kg m^-3].
    specific_heat_min_j_kgk, specific_heat_max_j_kgk : float or None
        Specific heat range c [J kg^-1 K^-1].
    diffusivity_min_m2_s, diffusivity_max_m2_s : float
        Thermal diffusivity range alpha [m^2 s^-1] (for paper12: that of
        ``diffusivity_from``), used to judge the semi-infinite assumption
        (Fourier number ``alpha t / L^2``).
    aliases : tuple of str
        Other names it is found by.
    source : str
        Where the numbers come from.
    diffusivity_from : str or None
        paper12 only: the database entry supplying diffusivity and family.
    flags : tuple of str
        Caveats, e.g. ``"identified_outside_range"`` (MDF in the paper).
    """

    name: str
    family: str
    set: str
    e_min: float
    e_max: float
    identified: float | None = None
    conductivity_min_w_mk: float | None = None
    conductivity_max_w_mk: float | None = None
    density_min_kg_m3: float | None = None
    density_max_kg_m3: float | None = None
    specific_heat_min_j_kgk: float | None = None
    specific_heat_max_j_kgk: float | None = None
    diffusivity_min_m2_s: float = math.nan
    diffusivity_max_m2_s: float = math.nan
    aliases: tuple[str, ...] = ()
    source: str = ""
    diffusivity_from: str | None = None
    flags: tuple[str, ...] = field(default=())

    @property
    def family_label(self) -> str:
        """Human label of the family (``"metals and alloys"``...)."""
        return FAMILY_LABELS[self.family]

    @property
    def effusivity_range(self) -> tuple[float, float]:
        """``(e_min, e_max)`` [J s^-1/2 K^-1 m^-2]."""
        return (self.e_min, self.e_max)

    @property
    def diffusivity_range_m2_s(self) -> tuple[float, float]:
        """``(alpha_min, alpha_max)`` [m^2 s^-1]."""
        return (self.diffusivity_min_m2_s, self.diffusivity_max_m2_s)

    @property
    def qualified_name(self) -> str:
        """``"set:name"``, which :func:`get_material` resolves to this entry only."""
        return f"{self.set}:{self.name}"

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (JSON output; docs/schema.md): ranges as ``[min, max]`` lists under ``*_range*`` keys."""

        def rng(lo, hi):
            return None if lo is None else [lo, hi]

        return {
            "name": self.name,
            "family": self.family,
            "family_label": self.family_label,
            "set": self.set,
            "effusivity_range": [self.e_min, self.e_max],
            "identified": self.identified,
            "conductivity_range_w_mk": rng(self.conductivity_min_w_mk, self.conductivity_max_w_mk),
            "density_range_kg_m3": rng(self.density_min_kg_m3, self.density_max_kg_m3),
            "specific_heat_range_j_kgk": rng(self.specific_heat_min_j_kgk, self.specific_heat_max_j_kgk),
            "diffusivity_range_m2_s": [self.diffusivity_min_m2_s, self.diffusivity_max_m2_s],
            "aliases": list(self.aliases),
            "source": self.source,
            "diffusivity_from": self.diffusivity_from,
            "flags": list(self.flags),
        }


@dataclass(frozen=True)
class MaterialTable:
    """A validated materials file: the ``database`` and ``paper12`` sets.

    Build with :func:`load_material_table`. Lookups go through :meth:`get`.
    """

    database: tuple[Material, ...]
    paper12: tuple[Material, ...]
    path: str = ""
    _index: Mapping[str, Mapping[str, Material]] = field(default=None, repr=False, compare=False)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        index = {}
        for set_name in SETS:
            keys: dict[str, Material] = {}
            for m in self.materials(set_name):
                for label in (m.name, *m.aliases):
                    keys.setdefault(_name_key(label), m)
            index[set_name] = types.MappingProxyType(keys)
        object.__setattr__(self, "_index", types.MappingProxyType(index))

    def materials(self, set: str = "database") -> tuple[Material, ...]:  # noqa: A002 - the set's name
        """All materials of one named set, in file order."""
        set_name = _check_set(set)
        return self.database if set_name == "database" else self.paper12

    def get(self, name: str, set: str | None = None) -> Material:  # noqa: A002
        """The material called ``name`` (see :func:`get_material`)."""
        if not isinstance(name, str) or not name.strip():
            raise InputError(f"material name must be a non-empty string, got {name!r}")
        text = name.strip()
        prefix, sep, rest = text.partition(":")
        if sep and prefix.strip().lower() in SETS and rest.strip():
            if set is not None and _check_set(set) != prefix.strip().lower():
                raise InputError(f"material {text!r} names set {prefix.strip().lower()!r} "
                                 f"but set {set!r} was asked for")
            set, text = prefix.strip().lower(), rest.strip()
        order = SETS if set is None else (_check_set(set),)
        key = _name_key(text)
        for set_name in order:
            hit = self._index[set_name].get(key)
            if hit is not None:
                return hit
        where = "" if set is None else f" in set {order[0]!r}"
        close = self.suggest(text, order)
        hint = f"; closest: {', '.join(close)}" if close else ""
        raise InputError(f"unknown material {name!r}{where}{hint} (see 'designkit materials list')")

    def suggest(self, name: str, sets: Iterable[str] = SETS, n: int = 5) -> list[str]:
        """Up to ``n`` names close to ``name``: entries containing all its words, then difflib."""
        sets = tuple(sets)
        key = _name_key(name)
        words = set(key.split())
        out: list[str] = []

        def label(m: Material) -> str:
            return m.name if m.set == "database" or len(sets) == 1 else f"{m.name} ({m.set})"

        for set_name in sets:  # every word of the query appears in the entry's name or alias
            for m in self.materials(set_name):
                if words and any(words <= set(_name_key(lbl).split()) for lbl in (m.name, *m.aliases)):
                    if label(m) not in out:
                        out.append(label(m))
        keys = {}
        for set_name in sets:
            for k, m in self._index[set_name].items():
                keys.setdefault(k, m)
        for k in difflib.get_close_matches(key, list(keys), n=2 * n, cutoff=0.6):
            if label(keys[k]) not in out:
                out.append(label(keys[k]))
        return out[:n]


def _check_set(set_name: Any) -> str:
    s = str(set_name).strip().lower()
    if s not in SETS:
        raise InputError(f"unknown material set {set_name!r}; choose one of: {', '.join(SETS)}")
    return s


def _check_family(family: Any) -> str:
    f = str(family).strip().lower()
    if f in FAMILIES:
        return f
    for key, lab in FAMILY_LABELS.items():  # "metal", "Metals and alloys"
        if _name_key(f) in (_name_key(key), _name_key(lab)):
            return key
    raise InputError(f"unknown material family {family!r}; choose one of: {', '.join(FAMILIES)}")


# ----------------------------------------------------------------------------- loading
_DB_FIELDS = ("name", "family", "aliases", "conductivity_w_mk", "density_kg_m3",
              "specific_heat_j_kgk", "source")
_P12_FIELDS = ("name", "aliases", "identified", "effusivity", "diffusivity_from", "source", "flags")
_TOP_FIELDS = ("designkit_materials", "families", "database", "paper12")


def _number(where: str, what: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{where}: {what} must be a number, got {value!r}")
    v = float(value)
    if not math.isfinite(v) or v <= 0:
        raise InputError(f"{where}: {what} must be positive and finite, got {value!r}")
    return v


def _range(where: str, what: str, value: Any) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise InputError(f"{where}: {what} must be a [min, max] pair, got {value!r}")
    lo = _number(where, f"{what} min", value[0])
    hi = _number(where, f"{what} max", value[1])
    if lo > hi:
        raise InputError(f"{where}: {what} min {lo:g} is above max {hi:g}")
    return lo, hi


def _text(where: str, what: str, value: Any) -> str:
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"{where}: {what} must be a non-empty string, got {value!r}")
    return value.strip()


def _strings(where: str, what: str, value: Any) -> tuple[str, ...]:
    if not isinstance(value, list):
        raise InputError(f"{where}: {what} must be a list (possibly empty), got {value!r}")
    return tuple(_text(where, f"{what} entry", v) for v in value)


def _entries(source: str, data: Mapping[str, Any], set_name: str, fields: tuple[str, ...]):
    rows = data.get(set_name)
    if not isinstance(rows, list) or not rows:
        raise InputError(f"{source}: {set_name!r} must be a non-empty list of materials")
    for i, row in enumerate(rows, start=1):
        label = row.get("name") if isinstance(row, Mapping) else None
        where = f"{source}: {set_name} entry {i}" + (f" ({label!r})" if label else "")
        if not isinstance(row, Mapping):
            raise InputError(f"{where}: must be a mapping of fields, got {type(row).__name__}")
        missing = [f for f in fields if f not in row]
        if missing:
            raise InputError(f"{where}: missing field(s) {', '.join(missing)}")
        unknown = sorted(str(k) for k in set(row) - set(fields))
        if unknown:
            raise InputError(f"{where}: unknown field(s) {', '.join(unknown)}")
        yield where, row


def _check_names(source: str, set_name: str, materials: Iterable[Material]) -> None:
    seen: dict[str, str] = {}
    for m in materials:
        for label in (m.name, *m.aliases):
            key = _name_key(label)
            if not key:
                raise InputError(f"{source}: {set_name} name or alias {label!r} of {m.name!r} has no letters or digits")
            if key in seen:
                raise InputError(f"{source}: {set_name} name or alias {label!r} of {m.name!r} "
                                 f"matches {seen[key]!r} (names must be distinct after normalization)")
            seen[key] = f"{label}" if label == m.name else f"{label} ({m.name})"


def _parse_table(data: Any, source: str) -> MaterialTable:
    from .properties import effusivity

    if not isinstance(data, Mapping):
        raise InputError(f"{source}: a materials file must be a mapping, got {type(data).__name__}")
    version = data.get("designkit_materials")
    if version != MATERIALS_FILE_VERSION:
        raise InputError(f"{source}: not a designkit materials file of version {MATERIALS_FILE_VERSION} "
                         f"(designkit_materials: {version!r})")
    unknown = sorted(str(k) for k in set(data) - set(_TOP_FIELDS))
    if unknown:
        raise InputError(f"{source}: unknown top-level field(s) {', '.join(unknown)}")
    fams = data.get("families")
    if not isinstance(fams, Mapping) or dict(fams) != dict(FAMILY_LABELS):
        raise InputError(f"{source}: families must be exactly {dict(FAMILY_LABELS)}, got {fams!r}")

    # database: stored k, rho, c ranges; effusivity and diffusivity derived (corner rule).
    names, fam, aliases, sources, props = [], [], [], [], []
    for where, row in _entries(source, data, "database", _DB_FIELDS):
        names.append(_text(where, "name", row["name"]))
        family = row["family"]
        if family not in FAMILIES:
            raise InputError(f"{where}: family {family!r} is not one of {', '.join(FAMILIES)}")
        fam.append(family)
        aliases.append(_strings(where, "aliases", row["aliases"]))
        sources.append(_text(where, "source", row["source"]))
        props.append([_range(where, f, row[f])
                      for f in ("conductivity_w_mk", "density_kg_m3", "specific_heat_j_kgk")])
    p = np.asarray(props, dtype=np.float64)  # (n, 3 properties, [min, max])
    k, rho, c = p[:, 0, :], p[:, 1, :], p[:, 2, :]
    e_lo = effusivity(k[:, 0], rho[:, 0], c[:, 0])
    e_hi = effusivity(k[:, 1], rho[:, 1], c[:, 1])
    a_lo = k[:, 0] / (rho[:, 1] * c[:, 1])
    a_hi = k[:, 1] / (rho[:, 0] * c[:, 0])
    database = tuple(
        Material(name=names[i], family=fam[i], set="database",
                 e_min=float(e_lo[i]), e_max=float(e_hi[i]),
                 conductivity_min_w_mk=float(k[i, 0]), conductivity_max_w_mk=float(k[i, 1]),
                 density_min_kg_m3=float(rho[i, 0]), density_max_kg_m3=float(rho[i, 1]),
                 specific_heat_min_j_kgk=float(c[i, 0]), specific_heat_max_j_kgk=float(c[i, 1]),
                 diffusivity_min_m2_s=float(a_lo[i]), diffusivity_max_m2_s=float(a_hi[i]),
                 aliases=aliases[i], source=sources[i])
        for i in range(len(names)))
    _check_names(source, "database", database)
    by_name = {m.name: m for m in database}

    # paper12: effusivity as printed; diffusivity and family from the named database entry.
    paper12 = []
    for where, row in _entries(source, data, "paper12", _P12_FIELDS):
        name = _text(where, "name", row["name"])
        e_min, e_max = _range(where, "effusivity", row["effusivity"])
        ident = row["identified"]
        ident = None if ident is None else _number(where, "identified", ident)
        flags = _strings(where, "flags", row["flags"])
        bad = sorted(set(flags) - _KNOWN_FLAGS)
        if bad:
            raise InputError(f"{where}: unknown flag(s) {', '.join(bad)}; known: {', '.join(sorted(_KNOWN_FLAGS))}")
        outside = ident is not None and not (e_min <= ident <= e_max)
        if outside != (FLAG_IDENTIFIED_OUTSIDE in flags):
            state = "lies outside" if outside else "lies inside"
            raise InputError(f"{where}: identified {ident:g} {state} [{e_min:g}, {e_max:g}] "
                             f"but flag {FLAG_IDENTIFIED_OUTSIDE!r} is {'missing' if outside else 'set'}")
        ref_name = _text(where, "diffusivity_from", row["diffusivity_from"])
        ref = by_name.get(ref_name)
        if ref is None:
            raise InputError(f"{where}: diffusivity_from {ref_name!r} is not a database material name")
        paper12.append(Material(
            name=name, family=ref.family, set="paper12", e_min=e_min, e_max=e_max, identified=ident,
            diffusivity_min_m2_s=ref.diffusivity_min_m2_s, diffusivity_max_m2_s=ref.diffusivity_max_m2_s,
            aliases=_strings(where, "aliases", row["aliases"]), source=_text(where, "source", row["source"]),
            diffusivity_from=ref.name, flags=flags))
    _check_names(source, "paper12", paper12)
    return MaterialTable(database=database, paper12=tuple(paper12), path=source)


def _read_table(text: str, source: str) -> MaterialTable:
    return _parse_table(_yaml_data(text, source), source)


def _yaml_data(text: str, source: str) -> Any:
    import yaml

    from ._schemas import _DuplicateKey, _unique_key_loader

    try:
        return yaml.load(text, Loader=_unique_key_loader())  # noqa: S506 - a safe loader (libyaml's when present)
    except _DuplicateKey as exc:
        raise InputError(f"{source}: the key {exc.key!r} is given twice (line {exc.line}): the last would win "
                         f"unnoticed; keep one") from None
    except yaml.YAMLError as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        mark = getattr(exc, "problem_mark", None)
        at = f" (line {mark.line + 1})" if mark is not None else ""
        raise InputError(f"{source}: not valid YAML{at}: {first}") from None


_SHIPPED = Path(__file__).resolve().parent / "data" / "materials.yaml"
_SHIPPED_SOURCE = "designkit/data/materials.yaml"


@functools.lru_cache(maxsize=1)
def _shipped_table() -> MaterialTable:
    from ._schemas import recorded

    content = _SHIPPED.read_bytes()
    data = recorded("materials", content)  # parsed once by designkit tables build: no YAML (its import and parse)
    if data is not None:
        try:
            return _parse_table(data, _SHIPPED_SOURCE)  # every rule checked either way
        except Exception:  # (not what designkit recorded): the file itself, the long way
            pass
    return _parse_table(_yaml_data(content.decode("utf-8"), _SHIPPED_SOURCE), _SHIPPED_SOURCE)


def remember_shipped_table() -> None:
    """Record the shipped materials file's parsed content (:func:`designkit._schemas.record_checked`), so that a
    later process reads it without YAML (``designkit tables build --sensor FILE`` does, for the questions about
    the sensor that follow)."""
    from ._schemas import record_checked

    content = _SHIPPED.read_bytes()
    data = _yaml_data(content.decode("utf-8"), _SHIPPED_SOURCE)
    _parse_table(data, _SHIPPED_SOURCE)
    record_checked("materials", content, data)


def load_material_table(path: str | Path | None = None) -> MaterialTable:
    """Read and validate a materials file.

    Parameters
    ----------
    path : str or Path, optional
        A materials YAML file in the shipped format. ``None`` (default) gives
        the shipped table, read once and cached.

    Returns
    -------
    MaterialTable

    Raises
    ------
    InputError
        The file is not valid YAML or breaks a rule (missing or unknown field,
        family not one of :data:`FAMILIES`, a non-positive number, min above
        max, two names equal after normalization, ...); one line naming the
        file and the entry.
    OSError
        The file cannot be read.
    """
    if path is None:
        return _shipped_table()
    p = Path(path)
    return _read_table(p.read_text(encoding="utf-8"), str(p))


def list_materials(family: str | None = None, set: str = "database") -> tuple[Material, ...]:  # noqa: A002
    """Materials of one named set, optionally of one family, in file order.

    Parameters
    ----------
    family : str, optional
        A key of :data:`FAMILIES` (``"metals"``...); singular forms and labels
        (``"metal"``, ``"ceramics and glasses"``) are accepted.
    set : {"database", "paper12"}
        Which named set.

    Examples
    --------
    >>> len(list_materials(set="paper12"))
    12
    """
    mats = load_material_table().materials(set)
    if family is None:
        return mats
    fam = _check_family(family)
    return tuple(m for m in mats if m.family == fam)


def get_material(name: str, set: str | None = None) -> Material:  # noqa: A002
    """Find a material by name or alias.

    Matching ignores case, punctuation, word order, a plural ``s`` and
    British/American spelling, and follows aliases: ``"steel, stainless"``,
    ``"aluminum"``, ``"acrylic"`` (-> PMMA) all resolve.

    Parameters
    ----------
    name : str
        Material name; a ``"paper12:"`` or ``"database:"`` prefix picks the set.
    set : {"database", "paper12"}, optional
        Look only in this set. By default ``database`` is searched first and
        ``paper12`` second, so ``"copper"`` is the database family "Copper
        alloys" and ``"glass"`` (no database entry of that name) is the paper's
        Glass; use ``set="paper12"`` or ``"paper12:copper"`` for the paper's.

    Raises
    ------
    InputError
        Unknown name; the message lists the closest names.

    Examples
    --------
    >>> get_material("steel, stainless").name
    'Stainless steel'
    >>> get_material("copper", set="paper12").identified
    23049.18
    """
    return load_material_table().get(name, set)


def material_or_effusivity(spec: str | float, set: str | None = None) -> "Material | float":  # noqa: A002
    """Read a query argument that is either an effusivity or a material name.

    A number (or a string that parses as one) is checked as an effusivity
    [J s^-1/2 K^-1 m^-2] and returned as float; anything else is looked up
    with :func:`get_material`. The query layer decides what a material's
    range means for its answer (worst case or mean over the range).

    Examples
    --------
    >>> material_or_effusivity("glass").name, material_or_effusivity("1500")
    ('Glass', 1500.0)
    """
    if isinstance(spec, (int, float)) and not isinstance(spec, bool):
        return check_effusivity("value", spec)
    text = str(spec).strip()
    try:
        value = float(text)
    except ValueError:
        return get_material(text, set)
    return check_effusivity("value", value)
