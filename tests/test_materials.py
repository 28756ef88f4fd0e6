"""The materials table: file validity, derived values, the paper's numbers, lookup, CLI."""

from __future__ import annotations

import copy
import functools
import itertools
import json
import math
import os
import re
import shutil
import subprocess
import sys
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from designkit import InputError
from designkit.cli import app
from designkit.materials import (
    FAMILIES,
    FAMILY_LABELS,
    Material,
    get_material,
    list_materials,
    load_material_table,
    material_or_effusivity,
)

REPO = Path(__file__).resolve().parents[1]
PAPER12_NAMES = ["Cardboard", "Wood", "ABS", "Rubber", "MDF", "Acrylic", "Porcelain", "Glass",
                 "Granite", "Stainless Steel", "Aluminum", "Copper"]
# The paper's extremes (section III-B): Rigid Polymer Foam (LD) 3.05e1, Copper Alloy 3.68e4;
# its appendix table prints Copper's maximum as 36761.16.
PAPER_MIN_FOAM = 30.5
PAPER_MAX_COPPER = (36800.0, 36761.16)


@functools.lru_cache(maxsize=1)
def _raw_cached() -> dict:
    text = resources.files("designkit").joinpath("data").joinpath("materials.yaml").read_text("utf-8")
    return yaml.safe_load(text)


def _raw() -> dict:
    """The shipped file as plain data, parsed here independently of designkit.materials."""
    return copy.deepcopy(_raw_cached())


def _header() -> str:
    text = resources.files("designkit").joinpath("data").joinpath("materials.yaml").read_text("utf-8")
    comments = [line.lstrip("#") for line in text.splitlines() if line.startswith("#")]
    return " ".join(" ".join(comments).split())  # one line, single spaces


def _domain_md() -> Path | None:
    for cand in (os.environ.get("DESIGNKIT_DOMAIN_MD"), REPO.parent / "shared" / "reference" / "DOMAIN.md"):
        if cand and Path(cand).is_file():
            return Path(cand)
    return None


# ------------------------------------------------------------------------ the file
def test_shipped_file_loads_with_enough_materials_in_every_family():
    table = load_material_table()
    assert table is load_material_table()  # read once, cached
    assert len(table.database) >= 69
    counts = {f: len(list_materials(f)) for f in FAMILIES}
    assert all(n >= 10 for n in counts.values()), counts
    assert sum(counts.values()) == len(table.database)
    assert [m.name for m in list_materials(set="paper12")] == PAPER12_NAMES
    # the header's statement of the entry count is the real count
    stated = re.search(r"(\d+) entries instead of 69", _header())
    assert stated and int(stated.group(1)) == len(table.database)


def test_every_database_entry_has_ranges_source_and_a_known_family():
    for m in list_materials():
        assert m.family in FAMILIES and m.set == "database"
        assert m.source and "(" in m.source, m.name  # names the kind of reference
        for lo, hi in [(m.conductivity_min_w_mk, m.conductivity_max_w_mk),
                       (m.density_min_kg_m3, m.density_max_kg_m3),
                       (m.specific_heat_min_j_kgk, m.specific_heat_max_j_kgk),
                       (m.e_min, m.e_max), m.diffusivity_range_m2_s]:
            assert 0 < lo <= hi < math.inf, m.name


def test_derived_values_recomputed_independently_from_the_raw_file():
    """e and alpha from the raw YAML with plain Python floats (not numpy, not the loader)."""
    raw = {r["name"]: r for r in _raw()["database"]}
    mats = list_materials()
    assert {m.name for m in mats} == set(raw)
    for m in mats:
        (k0, k1), (r0, r1), (c0, c1) = (raw[m.name][f] for f in
                                        ("conductivity_w_mk", "density_kg_m3", "specific_heat_j_kgk"))
        assert m.e_min == pytest.approx(math.sqrt(k0 * r0 * c0), rel=1e-12)
        assert m.e_max == pytest.approx(math.sqrt(k1 * r1 * c1), rel=1e-12)
        assert m.diffusivity_min_m2_s == pytest.approx(k0 / (r1 * c1), rel=1e-12)
        assert m.diffusivity_max_m2_s == pytest.approx(k1 / (r0 * c0), rel=1e-12)
        # e = k / sqrt(alpha) at a corner (paper eq. 1 in its other form)
        assert m.e_min == pytest.approx(k0 / math.sqrt(k0 / (r0 * c0)), rel=1e-12)


def test_corner_rule_bounds_every_grade_inside_the_property_box():
    """The documented rule gives the exact extremes of e and alpha over the k, rho, c box."""
    rng = np.random.default_rng(5)
    for m in list_materials():
        box = np.array([[m.conductivity_min_w_mk, m.conductivity_max_w_mk],
                        [m.density_min_kg_m3, m.density_max_kg_m3],
                        [m.specific_heat_min_j_kgk, m.specific_heat_max_j_kgk]])
        corners = np.array(list(itertools.product(*box)))
        inside = box[:, 0] + rng.random((200, 3)) * (box[:, 1] - box[:, 0])
        pts = np.vstack([corners, inside])
        e = np.sqrt(pts.prod(axis=1))
        a = pts[:, 0] / (pts[:, 1] * pts[:, 2])
        assert e.min() == pytest.approx(m.e_min, rel=1e-12) and e.max() == pytest.approx(m.e_max, rel=1e-12)
        assert a.min() == pytest.approx(m.diffusivity_min_m2_s, rel=1e-12)
        assert a.max() == pytest.approx(m.diffusivity_max_m2_s, rel=1e-12)


def test_values_are_physically_plausible():
    """Guards against unit slips (kJ for J, g/cm^3 for kg/m^3) in hand-typed ranges."""
    mats = list_materials()
    for m in mats:
        assert 1e-8 < m.diffusivity_min_m2_s and m.diffusivity_max_m2_s < 2e-4, m.name
        assert 0.01 < m.conductivity_min_w_mk and m.conductivity_max_w_mk < 450, m.name
        assert 10 < m.density_min_kg_m3 and m.density_max_kg_m3 < 22000, m.name
        assert 100 < m.specific_heat_min_j_kgk and m.specific_heat_max_j_kgk < 2600, m.name
    foams = [m for m in mats if "foam" in m.name.lower()]
    assert len(foams) == 6 and all(m.density_max_kg_m3 < 500 for m in foams)
    polymers = list_materials("polymers")
    assert max(m.e_max for m in polymers) < 1200
    assert min(m.e_min for m in list_materials("metals")) > 3 * max(m.e_max for m in polymers)


def test_extremes_agree_with_the_paper_within_the_stated_tolerance():
    tol = [float(x) / 100 for x in re.findall(r"agrees within ([\d.]+) %", _header())]
    assert len(tol) == 2
    mats = list_materials()
    lowest = min(mats, key=lambda m: m.e_min)
    highest = max(mats, key=lambda m: m.e_max)
    assert lowest.name == "Rigid polymer foam (LD)"
    assert highest.name == "Copper alloys"
    assert lowest.e_min == pytest.approx(PAPER_MIN_FOAM, rel=tol[0])
    for paper in PAPER_MAX_COPPER:
        assert highest.e_max == pytest.approx(paper, rel=tol[1])
    # the whole table lies inside the paper's sampled range (0, 40000]
    assert highest.e_max <= 40000


# ------------------------------------------------------------------------ paper12
def test_paper12_matches_domain_md_table():
    path = _domain_md()
    if path is None:
        pytest.skip("DOMAIN.md not found (set DESIGNKIT_DOMAIN_MD or keep ../shared/reference)")
    rows = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 4 and all(re.fullmatch(r"\d+\.\d+", c) for c in cells[1:]):
            rows[cells[0]] = tuple(float(c) for c in cells[1:])
    assert list(rows) == PAPER12_NAMES
    for name, (ident, lo, hi) in rows.items():
        m = get_material(name, set="paper12")
        assert (m.identified, m.e_min, m.e_max) == (ident, lo, hi)


def test_paper12_flags_and_diffusivity_come_from_the_database_family():
    for m in list_materials(set="paper12"):
        outside = not (m.e_min <= m.identified <= m.e_max)
        assert outside == ("identified_outside_range" in m.flags)
        ref = get_material(m.diffusivity_from, set="database")
        assert (m.family, m.diffusivity_range_m2_s) == (ref.family, ref.diffusivity_range_m2_s)
        assert m.conductivity_min_w_mk is None and m.density_max_kg_m3 is None
    assert [m.name for m in list_materials(set="paper12") if m.flags] == ["MDF"]
    # uniform representation of the four families (paper section IV-B)
    fams = [m.family for m in list_materials(set="paper12")]
    assert all(fams.count(f) == 3 for f in FAMILIES)


def test_paper12_ranges_overlap_their_database_family_except_mdf():
    """Stated in the file header: only handbook MDF lies off the paper's range."""
    off = [m.name for m in list_materials(set="paper12")
           if max(m.e_min, get_material(m.diffusivity_from).e_min)
           > min(m.e_max, get_material(m.diffusivity_from).e_max)]
    assert off == ["MDF"]


# ------------------------------------------------------------------------ lookup
@pytest.mark.parametrize("query, expected", [
    ("steel, stainless", "database:Stainless steel"),
    ("STAINLESS  steel", "database:Stainless steel"),
    ("aluminum", "database:Aluminium alloys"),
    ("aluminium", "database:Aluminium alloys"),
    ("Aluminum alloy", "database:Aluminium alloys"),
    ("acrylic", "database:Polymethyl methacrylate (Acrylic, PMMA)"),
    ("pmma", "database:Polymethyl methacrylate (Acrylic, PMMA)"),
    ("copper", "database:Copper alloys"),
    ("grey cast iron", "database:Cast iron, gray"),
    ("iron, cast (gray)", "database:Cast iron, gray"),
    ("tungsten carbide", "database:Tungsten carbides"),
    ("teflon", "database:Polytetrafluoroethylene (Teflon, PTFE)"),
    ("glass", "paper12:Glass"),          # no database entry of that name: paper12 next
    ("wood", "paper12:Wood"),
    ("paper12:copper", "paper12:Copper"),
    (" Paper12 : Stainless steel ", "paper12:Stainless Steel"),
    ("database:granite", "database:Granite"),
])
def test_lookup_variants(query, expected):
    assert get_material(query).qualified_name == expected


def test_lookup_in_one_set():
    m = get_material("stainless steel", set="paper12")
    assert (m.set, m.identified, m.e_min) == ("paper12", 10184.17, 6388.35)
    with pytest.raises(InputError, match="in set 'database'"):
        get_material("wood", set="database")
    with pytest.raises(InputError, match="names set 'paper12'"):
        get_material("paper12:copper", set="database")
    with pytest.raises(InputError, match="unknown material set"):
        get_material("copper", set="ces")


@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_any_word_order_and_case_of_a_name_finds_it(data):
    m = data.draw(st.sampled_from(list_materials() + list_materials(set="paper12")))
    words = re.findall(r"[A-Za-z0-9]+", m.name)
    words = data.draw(st.permutations(words))
    words = [w.upper() if data.draw(st.booleans()) else w.lower() for w in words]
    sep = data.draw(st.sampled_from([" ", ", ", " - ", "_", "  "]))
    found = get_material(sep.join(words), set=m.set)
    assert found == m


@pytest.mark.parametrize("query, wanted", [
    ("coper", "Copper alloys"),
    ("steel", "Stainless steel"),
    ("steel", "Low carbon steel"),
    ("foam", "Rigid polymer foam (LD)"),
    ("titanum", "Titanium alloys"),
])
def test_unknown_name_suggests_the_closest(query, wanted):
    with pytest.raises(InputError) as exc:
        get_material(query)
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith(f"unknown material {query!r}")
    assert wanted in msg.split("closest:")[1]


def test_unknown_name_far_from_everything_still_one_line():
    with pytest.raises(InputError, match=r"unknown material 'zzqx' \(see 'designkit materials list'\)"):
        get_material("zzqx")
    for bad in ["", "   ", None, 3]:
        with pytest.raises(InputError, match="non-empty string"):
            get_material(bad)


def test_family_filter_accepts_keys_singulars_and_labels():
    metals = list_materials("metals")
    assert list_materials("Metal") == metals == list_materials("metals and alloys")
    assert all(m.family == "metals" for m in metals)
    assert list_materials("composites, foams and natural materials") == list_materials("composites")
    with pytest.raises(InputError, match="unknown material family 'glass'"):
        list_materials("glass")
    with pytest.raises(InputError, match="unknown material set"):
        list_materials(set="level2")
    assert set(FAMILY_LABELS) == set(FAMILIES)


def test_material_or_effusivity():
    assert material_or_effusivity("1234.5") == 1234.5
    assert material_or_effusivity(892) == 892.0
    m = material_or_effusivity("steel, stainless")
    assert isinstance(m, Material) and m.name == "Stainless steel"
    for bad in ["-5", "nan", "0", "inf", -1.0]:
        with pytest.raises(InputError):
            material_or_effusivity(bad)


def test_import_does_no_work():
    code = ("import sys, designkit.materials as dm; "
            "print('yaml' in sys.modules, dm._shipped_table.cache_info().currsize)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "0"]


# ------------------------------------------------------------------------ validation
def _mutate(fn):
    data = copy.deepcopy(_raw())
    fn(data)
    return data


def _set(path, value):
    def fn(d):
        obj = d
        for key in path[:-1]:
            obj = obj[key]
        obj[path[-1]] = value
    return fn


def _drop(path):
    def fn(d):
        obj = d
        for key in path[:-1]:
            obj = obj[key]
        del obj[path[-1]]
    return fn


@pytest.mark.parametrize("mutation, message", [
    (_set(["database", 0, "conductivity_w_mk"], [235, 76]), "conductivity_w_mk min 235 is above max 76"),
    (_set(["database", 2, "density_kg_m3"], [-1, 11400]), "density_kg_m3 min must be positive"),
    (_set(["database", 2, "density_kg_m3"], [".nan", 11400]), "density_kg_m3 min must be a number"),
    (_set(["database", 2, "specific_heat_j_kgk"], [122]), "must be a [min, max] pair"),
    (_set(["database", 1, "family"], "metal"), "family 'metal' is not one of"),
    (_drop(["database", 3, "source"]), "missing field(s) source"),
    (_set(["database", 3, "colour"], "grey"), "unknown field(s) colour"),
    (_set(["database", 4, "aliases"], ["ALUMINIUM"]), "matches 'aluminium (Aluminium alloys)'"),
    (_set(["database", 4, "aliases"], "nickel"), "aliases must be a list"),
    (_set(["database", 4, "name"], ""), "name must be a non-empty string"),
    (_set(["paper12", 4, "flags"], []), "lies outside [618.47, 733.93] but flag 'identified_outside_range' is missing"),
    (_set(["paper12", 0, "flags"], ["identified_outside_range"]), "lies inside"),
    (_set(["paper12", 0, "flags"], ["dubious"]), "unknown flag(s) dubious"),
    (_set(["paper12", 1, "diffusivity_from"], "Wood"), "diffusivity_from 'Wood' is not a database material"),
    (_set(["families", "metals"], "metals"), "families must be exactly"),
    (_set(["designkit_materials"], 2), "not a designkit materials file of version 1"),
    (_set(["paper12"], []), "'paper12' must be a non-empty list"),
    (_set(["extra"], 1), "unknown top-level field(s) extra"),
])
def test_invalid_files_are_refused_with_one_line(tmp_path, mutation, message):
    path = tmp_path / "materials.yaml"
    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
    path.write_text(yaml.dump(_mutate(mutation), Dumper=dumper, sort_keys=False), encoding="utf-8")
    with pytest.raises(InputError) as exc:
        load_material_table(path)
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith(str(path)) and message in msg, msg


def test_unreadable_and_garbled_files(tmp_path):
    with pytest.raises(OSError):
        load_material_table(tmp_path / "missing.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("database: [\n  - name: x\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"not valid YAML \(line \d+\)"):
        load_material_table(bad)
    bad.write_text("- just\n- a list\n", encoding="utf-8")
    with pytest.raises(InputError, match="must be a mapping"):
        load_material_table(bad)


def test_a_copy_of_the_shipped_file_loads_the_same(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_text(yaml.safe_dump(_raw()), encoding="utf-8")
    table = load_material_table(path)
    assert table.database == load_material_table().database
    assert table.paper12 == load_material_table().paper12


# ------------------------------------------------------------------------ CLI
runner = CliRunner()


def test_cli_list_json_and_filters():
    res = runner.invoke(app, ["materials", "list", "--json"])
    assert res.exit_code == 0, res.output
    payload = json.loads(res.stdout)
    assert payload["count"] == len(list_materials()) == len(payload["materials"])
    first = payload["materials"][0]
    m = get_material(first["name"])
    assert first["effusivity_range"] == [m.e_min, m.e_max]
    assert first["diffusivity_range_m2_s"] == [m.diffusivity_min_m2_s, m.diffusivity_max_m2_s]

    res = runner.invoke(app, ["materials", "list", "--family", "metals", "--sort", "effusivity", "--json"])
    mats = json.loads(res.stdout)["materials"]
    assert {x["family"] for x in mats} == {"metals"}
    assert [x["effusivity_range"][0] for x in mats] == sorted(x["effusivity_range"][0] for x in mats)
    assert mats[-1]["name"] == "Silver"

    res = runner.invoke(app, ["materials", "list", "--set", "paper12", "--json"])
    p12 = json.loads(res.stdout)["materials"]
    assert [x["name"] for x in p12] == PAPER12_NAMES
    assert p12[4]["identified"] == 544.63 and p12[4]["flags"] == ["identified_outside_range"]


def test_cli_list_human_table():
    res = runner.invoke(app, ["materials", "list", "--family", "ceramic"])
    assert res.exit_code == 0, res.output
    assert "Soda-lime glass" in res.stdout and "Copper alloys" not in res.stdout
    assert "ceramics 16" in res.stdout or re.search(r"ceramics \d+", res.stdout)
    res = runner.invoke(app, ["materials", "list", "--set", "paper12"])
    assert "MDF [!]" in res.stdout and "23049.18" in res.stdout


def test_cli_show():
    res = runner.invoke(app, ["materials", "show", "steel, stainless", "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.stdout)
    assert d["name"] == "Stainless steel" and d["set"] == "database"
    assert d["effusivity_range"][0] == pytest.approx(math.sqrt(12 * 7600 * 450))
    res = runner.invoke(app, ["materials", "show", "mdf", "--set", "paper12"])
    assert res.exit_code == 0
    text = " ".join(res.stdout.split())  # rich wraps at the terminal width
    assert "544.63" in text and "outside its printed range" in text
    assert "from database 'Medium-density fibreboard (MDF)'" in text


@pytest.mark.parametrize("args, message", [
    (["materials", "show", "coper"], "Error: unknown material 'coper'; closest: Copper alloys"),
    (["materials", "show", "copper", "--set", "ces"], "Error: unknown material set 'ces'"),
    (["materials", "list", "--family", "foo"], "Error: unknown material family 'foo'"),
    (["materials", "list", "--sort", "size"], "Error: unknown sort 'size'"),
])
def test_cli_bad_input_exit_2_one_line(args, message):
    res = runner.invoke(app, args)
    assert res.exit_code == 2
    assert res.stderr.startswith(message) and res.stderr.count("\n") == 1, res.stderr
    assert "Traceback" not in res.output


def _console_script() -> str:
    cand = Path(sys.executable).with_name("designkit")
    if cand.is_file():
        return str(cand)
    found = shutil.which("designkit")
    if not found:
        pytest.skip("the designkit console script is not installed")
    return found


def test_console_script_subprocess():
    exe = _console_script()
    out = subprocess.run([exe, "materials", "show", "paper12:copper", "--json"],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert (d["name"], d["identified"], d["effusivity_range"]) == ("Copper", 23049.18, [23049.18, 36761.16])
    bad = subprocess.run([exe, "materials", "show", "unobtainium"], capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr.startswith("Error: unknown material 'unobtainium'") and bad.stderr.count("\n") == 1
