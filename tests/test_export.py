"""Exports: slices interpolated like the query, the data formats, and the stdlib-only Python
module compared with designkit.query on random inputs in a Python where numpy cannot be
imported; the CLI; the robot-loop example. (The C header: tests/test_export_c.py.)"""

from __future__ import annotations

import ast
import functools
import json
import math
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

from designkit import InputError
from designkit.query import table as q
from designkit.sweep import SweepConfig, run_sweep
from designkit.export import FORMATS, export_table, parse_contact, read_export, render, slice_table
from designkit.export.formats.python import LOOKUP_BEGIN, LOOKUP_END, estimator_source, lookup_source
from designkit.tables.store import Table, content_hash, load_table, table_header, write_table

REPO = Path(__file__).resolve().parent.parent


def to_python(exp) -> bytes:
    return render(exp, "python")
EXAMPLES = REPO / "examples"

# Slice scenes are exactly representable in float32 (so that C's float arguments and the
# Python reference see the same numbers): 0.0625 / 12.5 is the sigma/dT grid row 0.005 itself.
ON_ROW = (0.0625, 12.5)
OFF_ROW = (0.0625, 10.0)  # sigma/dT 0.00625, between rows


# ============================================================ tables used by the tests
@functools.lru_cache(maxsize=None)
def ideal_table():
    return load_table("ideal-paper")


@functools.lru_cache(maxsize=None)
def svm_small_table():
    """A real (tiny) SVM table from the sweep engine: Monte Carlo noise, NaNs, lo/hi/ideal arrays."""
    folder = Path(tempfile.mkdtemp(prefix="dk-export-svm-"))
    cfg = SweepConfig(name="svm-small", fidelity="svm", e_min=0.0, e_max=8000.0, intervals=10, trials=12,
                      folds=3, noise_ratio=(0.002, 0.005, 0.01), contact_s=(0.5, 1.0, 2.0), max_repeats=1)
    path = run_sweep(cfg, folder / "work", out=folder / "svm-small.npz", jobs=1, backend="sequential")
    return load_table(path)


def _random_arrays(shape, width, rng, nan_fraction=0.2):
    out = {}
    for name in ("delta_up", "delta_down", "delta_up_lo", "delta_down_lo", "delta_up_hi", "delta_down_hi",
                 "delta_up_ideal", "delta_down_ideal"):
        a = width * rng.integers(1, 25, size=shape).astype(float)  # distances between centres
        a[rng.random(shape) < nan_fraction] = np.nan
        out[name] = a
    out["fits"] = np.zeros(shape[:-1], dtype=np.int64)
    out["chunk_wall_s"] = np.zeros(shape[:-1])
    return out


@functools.lru_cache(maxsize=None)
def random_ratio_table():
    """Synthetic sigma/dT table with NaNs everywhere: stresses the NaN rules."""
    cfg = SweepConfig(name="rand-ratio", e_min=0.0, e_max=6000.0, intervals=30, noise_ratio=(0.001, 0.003, 0.01),
                      contact_s=(0.5, 1.0, 2.0, 3.5))
    arrays = _random_arrays((3, 4, 30), cfg.width, np.random.default_rng(1))
    folder = Path(tempfile.mkdtemp(prefix="dk-export-rr-"))
    return load_table(write_table(folder / "rand-ratio.npz", table_header(cfg, arrays), arrays))


@functools.lru_cache(maxsize=None)
def random_varied_table():
    """Synthetic varied-initial-conditions table: separate noise (log) and dT (linear) axes."""
    cfg = SweepConfig(name="rand-varied", e_min=0.0, e_max=5000.0, intervals=25, noise_ratio=None,
                      noise_c=(0.02, 0.05, 0.1), delta_t_c=(5.0, 10.0, 15.0), sensor_temp_spread_c=2.5,
                      contact_s=(1.0, 2.0, 4.0))
    arrays = _random_arrays((3, 3, 3, 25), cfg.width, np.random.default_rng(2), nan_fraction=0.15)
    folder = Path(tempfile.mkdtemp(prefix="dk-export-rv-"))
    return load_table(write_table(folder / "rand-varied.npz", table_header(cfg, arrays), arrays))


TABLES = {"ideal": ideal_table, "svm-small": svm_small_table, "rand-ratio": random_ratio_table,
          "rand-varied": random_varied_table}

# (table, slice options) covering: full tables of both scene layouts, one-scene slices on and
# between grid rows, effusivity and contact slices, and the Monte Carlo / ideal kinds.
CASES = {
    "ideal-row": ("ideal", dict(noise_c=ON_ROW[0], delta_t_c=ON_ROW[1])),
    "ideal-between-rows-e-contact": ("ideal", dict(noise_c=OFF_ROW[0], delta_t_c=OFF_ROW[1], e_min=15000.0,
                                                   e_max=36000.0, contact="1.1:4.1")),
    "svm-small-full": ("svm-small", {}),
    "svm-small-hi": ("svm-small", dict(kind="hi")),
    "svm-small-lo-slice": ("svm-small", dict(kind="lo", noise_c=0.0625, delta_t_c=20.0)),
    "svm-small-ideal": ("svm-small", dict(kind="ideal", e_min=1000.0, e_max=6500.0)),
    "rand-ratio-full": ("rand-ratio", {}),
    "rand-ratio-e": ("rand-ratio", dict(e_min=1234.0, e_max=4321.0, contact=(0.75, 3.0))),
    "rand-varied-full": ("rand-varied", {}),
    "rand-varied-slice": ("rand-varied", dict(noise_c=0.0625, delta_t_c=7.5)),
}


def case(name):
    table, opts = CASES[name]
    tab = TABLES[table]()
    return tab, opts, slice_table(tab, **opts)


# ============================================================ reference and random queries
OPS = ("min_contact", "delta_e", "delta_e_lower", "delta_e_upper", "distinguishable")


def reference(tab, kind: str, op: str, args):
    """designkit.query.table's grid-interpolation answer (:func:`designkit.query.table.grid_answer`): float,
    None (nothing suffices), bool, or 'outside' / 'invalid'.

    Asked with the table's own sensor temperature spread (an exported table answers for the conditions it
    was built with; the query route refuses a table built for another spread)."""
    kw = dict(table=tab, ideal_table=None, sensor_temp_spread_c=q.table_spread(tab))
    # the grid read needs no Monte Carlo ideal bound (varied tables): the table route's own floor
    from designkit.query import table as table_route
    try:
        if op == "min_contact":
            e1, e2, noise, dt = args
            a = table_route.min_contact(e1, e2, noise_c=noise, delta_t_c=dt, ideal_bound=False, **kw)
        elif op == "distinguishable":
            e1, e2, noise, dt, c = args
            a = q.distinguishable(e1, e2, contact_s=c, noise_c=noise, delta_t_c=dt, **kw)
        else:
            e, noise, dt, c = args
            a = table_route.delta_e(e, contact_s=c, noise_c=noise, delta_t_c=dt, ideal_bound=False, **kw)
    except InputError as exc:
        # the library refuses temperatures and noise beyond 1e4 degC as bad input; a grid-bound export
        # (which never had them in its grid) calls the same question "outside"
        return "outside" if "at most 10000 degC" in str(exc) else "invalid"
    if not all(a.in_grid.values()):
        return "outside"
    # what an export answers is the table's grid interpolation alone (the CLI refines it between grid points
    # with the exact ideal observer, which an export cannot run): designkit.query.table.grid_answer reads it
    if op == "distinguishable":
        assert kind != "ideal", "the table route answers the ideal observer's F1 in closed form, not by delta"
        return bool(q.grid_answer(a, kind))
    if op == "min_contact":
        return q.grid_answer(a, kind)
    part = {"delta_e_lower": "lower", "delta_e_upper": "upper"}.get(op)
    return q.grid_answer(a, kind, part)


def _f32(x: float) -> float:
    return float(np.float32(x))


def random_queries(exp, rng, n: int) -> list[tuple[str, tuple]]:
    """Random float32 inputs, mostly inside what ``exp`` answers, some beyond it, a few invalid."""
    scene = exp.scene_axes
    c0, c1 = exp.contact.values[0], exp.contact.values[-1]
    lo, hi = max(exp.e_lo, 1.0), exp.e_hi

    def e_value():
        u = rng.random()
        if u < 0.05:
            return _f32(hi * (1 + rng.random()))  # beyond the top
        if u < 0.08:
            return _f32(lo * rng.random()) if lo > 1.0 else _f32(exp.e_lo + 1e-3)
        return _f32(rng.uniform(lo, hi))

    def scene_value():
        if len(scene[0].values) == 1 and rng.random() < 0.85:  # a slice: its own scene
            p = exp.provenance["slice"]["scene"]
            return _f32(p["noise_c"]), _f32(p["delta_t_c"])
        if scene[0].name == "noise_ratio":
            r0, r1 = min(scene[0].values), max(scene[0].values)
            r = math.exp(rng.uniform(math.log(r0 / 1.3), math.log(r1 * 1.3)))
            dt = rng.uniform(2.0, 20.0) * (1 if rng.random() < 0.9 else -1)
            return _f32(r * abs(dt)), _f32(dt)
        n0, n1 = min(scene[0].values), max(scene[0].values)
        d0, d1 = min(scene[1].values), max(scene[1].values)
        return _f32(math.exp(rng.uniform(math.log(n0 / 1.2), math.log(n1 * 1.2)))), _f32(rng.uniform(d0 - 1, d1 + 1))

    def contact_value():
        return _f32(rng.uniform(c0 * 0.9, c1 * 1.05)) if c1 > c0 else _f32(c0 if rng.random() < 0.9 else c0 * 1.5)

    out = []
    for i in range(n):
        op = OPS[i % len(OPS)]
        noise, dt = scene_value()
        if op in ("min_contact", "distinguishable"):
            e1, e2 = e_value(), e_value()
            args = (e1, e2, noise, dt) if op == "min_contact" else (e1, e2, noise, dt, contact_value())
        else:
            args = (e_value(), noise, dt, contact_value())
        if rng.random() < 0.03:  # invalid input
            args = list(args)
            args[rng.integers(len(args))] = [math.nan, 0.0, -1.0, math.inf][rng.integers(4)]
            args = tuple(args)
        out.append((op, args))
    return out


def agree(got, want, rtol: float) -> bool:
    if isinstance(want, float) and isinstance(got, float):
        return math.isclose(got, want, rel_tol=rtol, abs_tol=1e-9)
    return got == want and type(got) is type(want)


# ============================================================ slicing
def test_one_scene_on_a_grid_row_is_that_row():
    tab = ideal_table()
    exp = slice_table(tab, noise_c=ON_ROW[0], delta_t_c=ON_ROW[1])
    row = list(tab.axes["noise_ratio"]).index(0.005)
    assert exp.shape == (1,) + tab.arrays["delta_up"].shape[1:]
    np.testing.assert_array_equal(exp.delta_up[0], tab.arrays["delta_up"][row])
    np.testing.assert_array_equal(exp.delta_down[0], tab.arrays["delta_down"][row])
    assert exp.scene_axes[0].values == (0.005,)


def test_one_scene_between_rows_is_log_linear_with_nan_propagating():
    tab = ideal_table()
    r = OFF_ROW[0] / OFF_ROW[1]
    ratios = tab.axes["noise_ratio"]
    j = int(np.flatnonzero(ratios < r)[-1])
    w = (math.log(r) - math.log(ratios[j])) / (math.log(ratios[j + 1]) - math.log(ratios[j]))
    assert 0 < w < 1
    exp = slice_table(tab, noise_c=OFF_ROW[0], delta_t_c=OFF_ROW[1])
    for name, got in (("delta_up", exp.delta_up[0]), ("delta_down", exp.delta_down[0])):
        a, b = tab.arrays[name][j], tab.arrays[name][j + 1]
        np.testing.assert_allclose(got, (1 - w) * a + w * b, rtol=1e-13)
        np.testing.assert_array_equal(np.isnan(got), np.isnan(a) | np.isnan(b))
    # varied tables: bilinear in (log sigma, dT)
    tv = random_varied_table()
    ev = slice_table(tv, noise_c=0.0625, delta_t_c=7.5)
    wn = (math.log(0.0625) - math.log(0.05)) / (math.log(0.1) - math.log(0.05))
    wd = 0.5
    d = tv.arrays["delta_up"]
    expect = ((1 - wn) * (1 - wd) * d[1, 0] + (1 - wn) * wd * d[1, 1] + wn * (1 - wd) * d[2, 0] + wn * wd * d[2, 1])
    np.testing.assert_allclose(ev.delta_up[0, 0], expect, rtol=1e-13)
    np.testing.assert_array_equal(np.isnan(ev.delta_up[0, 0]), np.isnan(expect))


@pytest.mark.parametrize("e_min,e_max", [(15000.0, 36000.0), (15040.0, 35960.0), (10.0, 60.0), (39990.0, 40000.0)])
def test_effusivity_slice_keeps_one_interval_of_margin(e_min, e_max):
    tab = ideal_table()
    centres = tab.axes["e_ref"]
    exp = slice_table(tab, e_min=e_min, e_max=e_max)
    kept = np.asarray(exp.e_ref.values)
    # every centre the query's interpolation reads for e in [e_min, e_max] is kept ...
    # (an effusivity on a centre reads that centre only)
    below, above = centres[centres <= e_min], centres[centres >= e_max]
    assert kept[0] == (below[-1] if below.size else centres[0])
    assert kept[-1] == (above[0] if above.size else centres[-1])
    # ... and nothing else
    inner = centres[(centres >= e_min) & (centres < e_max)]
    assert kept.size <= inner.size + 3
    assert exp.e_lo == e_min and exp.e_lo_inclusive and exp.e_hi == e_max


def test_contact_slices_keep_the_columns_that_interpolate_them():
    tab = ideal_table()  # contact 0.5, 0.75, ..., 10 s
    assert slice_table(tab, contact="2").contact.values == (2.0,)
    assert slice_table(tab, contact="2.1").contact.values == (2.0, 2.25)
    rng = slice_table(tab, contact="1.1:2.6")
    assert rng.contact.values == (1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5, 2.75)
    assert all(rng.contact_adjacent)
    gaps = slice_table(tab, contact=["1", "4"])
    assert gaps.contact.values == (1.0, 4.0) and gaps.contact_adjacent == (False,)
    assert parse_contact("1,2:3") == (1.0, (2.0, 3.0))


@pytest.mark.parametrize("kwargs,match", [
    (dict(noise_c=0.05), "together"),
    (dict(noise_c=1.0, delta_t_c=10.0), "outside table ideal-paper's grid along noise_ratio"),
    (dict(noise_c=-0.1, delta_t_c=10.0), ">= 0"),
    (dict(noise_c=0.05, delta_t_c=0.0), "temperature difference is 0"),
    (dict(e_min=30000.0, e_max=20000.0), "below"),
    (dict(e_max=50000.0), "outside"),
    (dict(contact="20"), "outside the table's contact grid"),
    (dict(contact="4:1"), "shorter to longer"),
    (dict(contact="fast"), "number or a range"),
    (dict(kind="best"), "kind must be one of"),
])
def test_bad_slice_requests_are_refused_in_one_line(kwargs, match):
    with pytest.raises(InputError, match=match) as err:
        slice_table(ideal_table(), **kwargs)
    assert "\n" not in str(err.value)


# ============================================================ data formats
@pytest.mark.parametrize("fmt", ["json", "csv", "npz"])
def test_data_formats_round_trip_with_provenance(tmp_path, fmt):
    tab, _, exp = case("ideal-between-rows-e-contact")
    res = export_table(tab, tmp_path / f"t.{fmt}", fmt, noise_c=OFF_ROW[0], delta_t_c=OFF_ROW[1], e_min=15000.0,
                       e_max=36000.0, contact="1.1:4.1")
    assert res.size_bytes == res.path.stat().st_size
    back = read_export(res.path)
    np.testing.assert_array_equal(back.delta_up, exp.delta_up)  # NaN positions included
    np.testing.assert_array_equal(back.delta_down, exp.delta_down)
    assert [a.values for a in back.axes] == [a.values for a in exp.axes]
    assert back.contact_adjacent == exp.contact_adjacent
    p = back.provenance
    assert p["source_table"] == "ideal-paper" and p["source_content_hash"] == tab.header["content_hash"]
    assert p["sensor"]["name"] == "paper" and p["fidelity"] == "ideal" and p["threshold"] == 0.9
    assert p["slice"]["scene"]["noise_ratio"] == OFF_ROW[0] / OFF_ROW[1]
    assert {a["name"]: a["units"] for a in p["axes"]}["contact_s"] == "s"
    assert p["export_hash"] == content_hash({"delta_up": back.delta_up, "delta_down": back.delta_down,
                                             **{f"axis_{a.name}": np.asarray(a.values) for a in back.axes}})


def test_data_formats_read_with_plain_tools(tmp_path):
    exp = slice_table(ideal_table(), noise_c=ON_ROW[0], delta_t_c=ON_ROW[1])
    doc = json.loads(render(exp, "json"))  # strict JSON: NaN written as null
    assert doc["delta_up"][0][0][0] is None or isinstance(doc["delta_up"][0][0][0], float)
    nulls = sum(v is None for row in doc["delta_up"][0] for v in row)
    assert nulls == int(np.isnan(exp.delta_up).sum()) > 0
    (tmp_path / "t.csv").write_bytes(render(exp, "csv"))
    data = np.genfromtxt(tmp_path / "t.csv", delimiter=",", names=True, comments="#")
    assert data.dtype.names == ("noise_ratio", "contact_s", "e_ref", "delta_up", "delta_down")
    assert data.size == exp.delta_up.size
    sel = (data["contact_s"] == 2.0) & (data["e_ref"] == 20040.0)
    k, i = exp.contact.values.index(2.0), exp.e_ref.values.index(20040.0)
    assert data["delta_up"][sel][0] == exp.delta_up[0, k, i]
    (tmp_path / "t.npz").write_bytes(render(exp, "npz"))
    with np.load(tmp_path / "t.npz", allow_pickle=False) as z:
        np.testing.assert_array_equal(z["delta_down"], exp.delta_down)
        assert json.loads(str(z["provenance"]))["source_table"] == "ideal-paper"


def test_a_slice_is_much_smaller_than_the_full_table():
    tab = ideal_table()
    full, one = slice_table(tab), slice_table(tab, noise_c=ON_ROW[0], delta_t_c=ON_ROW[1])
    fixed = {"python": len(lookup_source().encode()) + len(estimator_source().encode())}  # the code it carries
    for fmt in FORMATS:
        size = {label: len(render(exp, fmt)) - fixed.get(fmt, 0) for label, exp in (("one", one), ("full", full))}
        assert size["one"] * 5 < size["full"], fmt


# ============================================================ stdlib-only Python module
DRIVER = r'''
import importlib.util, json, sys
spec = importlib.util.spec_from_file_location("table_module", sys.argv[1])
m = importlib.util.module_from_spec(spec)
spec.loader.exec_module(m)
try:
    import numpy  # noqa: F401
    numpy_importable = True
except ImportError:
    numpy_importable = False
names = {"min_contact": "min_contact_s"}
out = []
for op, args in json.load(sys.stdin):
    try:
        out.append({"v": getattr(m.TABLE, names.get(op, op))(*args)})  # the grid rule (TABLE)
    except m.OutsideTable:
        out.append({"v": "outside"})
    except ValueError:
        out.append({"v": "invalid"})
foreign = sorted(k for k in sys.modules if k.split(".")[0] not in sys.stdlib_module_names
                 and k not in ("__main__", "table_module"))
json.dump({"numpy_importable": numpy_importable, "foreign_modules": foreign, "answers": out}, sys.stdout)
'''


def run_module(path: Path, queries, tmp_path: Path) -> list:
    """Answer queries with the generated module's grid rule (its ``TABLE``) in `python -I -S` (no site-packages:
    no numpy). What its own functions answer (the library's estimator) is tests/test_export_conformance.py's."""
    driver = tmp_path / "driver.py"
    driver.write_text(DRIVER)
    proc = subprocess.run([sys.executable, "-I", "-S", str(driver), str(path)], input=json.dumps(queries),
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    res = json.loads(proc.stdout)
    assert res["numpy_importable"] is False and res["foreign_modules"] == []
    return [a["v"] for a in res["answers"]]


def imports_of(source: str) -> set[str]:
    mods = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            mods |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            mods.add((node.module or "").split(".")[0])
    return mods


@pytest.mark.parametrize("name", list(CASES))
def test_stdlib_module_answers_like_the_query(tmp_path, name):
    tab, opts, exp = case(name)
    src = to_python(exp)
    assert imports_of(src.decode()) <= set(sys.stdlib_module_names)
    path = tmp_path / "table_module.py"
    path.write_bytes(src)
    kind = opts.get("kind", "svm")
    queries = [(op, args) for op, args in random_queries(exp, np.random.default_rng(7), 150)
               if not (kind == "ideal" and op == "distinguishable")]
    got = run_module(path, queries, tmp_path)
    # a slice answers only its own scene / contact columns / effusivities: elsewhere it must
    # say "outside", and wherever it answers, the full table's query must agree
    mismatches = []
    categories = set()
    for (op, args), g in zip(queries, got):
        want = reference(tab, kind, op, args)
        if g == "outside" and exp is not None and _beyond_slice(exp, op, args):
            categories.add("outside-slice")
            continue
        want = on_contact_columns(exp, op, want)
        categories.add(type(want).__name__ if not isinstance(want, str) else want)
        if not agree(g, want, 1e-9):
            mismatches.append((op, args, g, want))
    assert not mismatches, mismatches[:5]
    # the random grid reached answers and refusals
    assert "float" in categories and categories & {"outside", "outside-slice"}


def on_contact_columns(exp, op: str, want):
    """The full table's min_contact restricted to a contact slice's columns c[0]..c[-1]:
    none beyond c[-1], at least c[0] (the need shrinks with contact time in these tables)."""
    if op != "min_contact" or not exp.provenance["slice"]["contact_s"] or not isinstance(want, float):
        return want
    c = exp.contact.values
    return None if want > c[-1] else max(want, c[0])


def _beyond_slice(exp, op: str, args) -> bool:
    """Whether a query lies outside what a slice keeps (but maybe inside the source table)."""
    s = exp.provenance["slice"]
    if op in ("min_contact", "distinguishable"):
        es, (noise, dt), contact = args[:2], args[2:4], (args[4] if op == "distinguishable" else None)
    else:
        es, (noise, dt), contact = args[:1], args[1:3], args[3]
    if any(isinstance(x, float) and not math.isfinite(x) for x in args):
        return False
    if s["scene"]:
        if "noise_ratio" in s["scene"]:
            same = dt != 0 and math.isclose(noise / abs(dt), s["scene"]["noise_ratio"], rel_tol=1e-6)
        else:
            same = math.isclose(noise, s["scene"]["noise_c"]) and math.isclose(dt, s["scene"]["delta_t_c"])
        if not same:
            return True
    if s["effusivity"] and any(not (exp.e_lo <= e <= exp.e_hi) for e in es):
        return True
    if s["contact_s"] and contact is not None:
        c = exp.contact.values
        return not (c[0] <= contact <= c[-1])
    return False


def test_stdlib_module_refuses_contacts_between_non_neighbour_columns(tmp_path):
    tab = ideal_table()
    exp = slice_table(tab, noise_c=ON_ROW[0], delta_t_c=ON_ROW[1], contact=["1", "4"])
    path = tmp_path / "table_module.py"
    path.write_bytes(to_python(exp))
    rng = np.random.default_rng(3)
    pairs = [(_f32(rng.uniform(500, 39000)), _f32(rng.uniform(500, 39000))) for _ in range(30)]
    queries = [("min_contact", (a, b, *ON_ROW)) for a, b in pairs]
    queries += [("delta_e", (20000.0, *ON_ROW, 2.5)), ("distinguishable", (1000.0, 30000.0, *ON_ROW, 3.0))]
    got = run_module(path, queries, tmp_path)
    assert got[-2:] == ["outside", "outside"]
    for (a, b), g in zip(pairs, got):
        # the robot can touch for 1 s or 4 s: the shortest of these that separates the pair
        at1 = q.distinguishable(a, b, contact_s=1.0, noise_c=ON_ROW[0], delta_t_c=ON_ROW[1], table=tab,
                                ideal_table=None).value
        at4 = q.distinguishable(a, b, contact_s=4.0, noise_c=ON_ROW[0], delta_t_c=ON_ROW[1], table=tab,
                                ideal_table=None).value
        assert g == (1.0 if at1 else 4.0 if at4 else None), (a, b)


def test_contact_range_slice_equals_the_full_table_above_its_first_column(tmp_path):
    tab = ideal_table()
    exp = slice_table(tab, noise_c=ON_ROW[0], delta_t_c=ON_ROW[1], contact="2:6")
    path = tmp_path / "table_module.py"
    path.write_bytes(to_python(exp))
    rng = np.random.default_rng(4)
    pairs = [(_f32(rng.uniform(500, 39000)), _f32(rng.uniform(500, 39000))) for _ in range(80)]
    got = run_module(path, [("min_contact", (a, b, *ON_ROW)) for a, b in pairs], tmp_path)
    seen = set()
    for (a, b), g in zip(pairs, got):
        full = q.min_contact(a, b, noise_c=ON_ROW[0], delta_t_c=ON_ROW[1], table=tab, ideal_table=None).value
        if full is None or full > 6.0:
            assert g is None
            seen.add("none")
        elif full > 2.0:
            assert g == pytest.approx(full, rel=1e-12)
            seen.add("equal")
        else:  # the ideal table's need shrinks with contact time: the first kept column suffices
            assert g == 2.0
            seen.add("first")
    assert seen == {"none", "equal", "first"}


def test_stdlib_module_checks_its_data(tmp_path):
    path = tmp_path / "table_module.py"
    src = to_python(slice_table(random_ratio_table(), noise_c=0.02, delta_t_c=10.0)).decode()
    i = src.index('_DATA = (\n    "') + len('_DATA = (\n    "') + 20
    bad = src[:i] + ("0" if src[i] != "0" else "1") + src[i + 1:]
    path.write_text(bad)
    proc = subprocess.run([sys.executable, "-I", "-S", "-c",
                           f"import importlib.util as u; s = u.spec_from_file_location('m', {str(path)!r}); "
                           "s.loader.exec_module(u.module_from_spec(s))"], capture_output=True, text=True)
    assert proc.returncode != 0
    assert "corrupted" in proc.stderr or "Error" in proc.stderr


def test_shipped_svm_paper_exports_like_its_query(tmp_path):
    tab = load_table("svm-paper")
    for label, exp in (("whole", slice_table(tab)), ("row", slice_table(tab, noise_c=ON_ROW[0], delta_t_c=ON_ROW[1]))):
        path = tmp_path / f"table_module_{label}.py"
        path.write_bytes(to_python(exp))
        queries = random_queries(exp, np.random.default_rng(11), 100)
        queries.append(("min_contact", (35000.0, 20000.0, 0.05, 10.0)))  # 0.05 / 10 is the row 0.005
        got = run_module(path, queries, tmp_path)
        for (op, args), g in zip(queries, got):
            if g == "outside" and _beyond_slice(exp, op, args):
                continue
            want = reference(tab, "svm", op, args)
            assert agree(g, want, 1e-9), (label, op, args, g, want)


# ============================================================ CLI
@pytest.mark.parametrize("fmt,suffix", [("json", ".json"), ("csv", ".csv"), ("npz", ".npz"), ("mat", ".mat"), ("c", ".h"),
                                        ("python", ".py")])
def test_cli_export_every_format(cli, tmp_path, fmt, suffix):
    out = tmp_path / f"table{suffix}"
    r = cli("export", "--table", "ideal-paper", "--format", fmt, "--noise", "0.05", "--delta-t", "10",
            "--e-min", "15000", "--e-max", "36000", "--contact", "1:4", "--out", out, "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["format"] == fmt and d["size_bytes"] == out.stat().st_size > 0
    assert d["provenance"]["slice"]["contact_s"]["source_columns"] == list(range(2, 15))
    human = cli("export", "--table", "ideal-paper", "--noise", "0.05", "--delta-t", "10", "--out",
                tmp_path / f"again{suffix}")  # format from the suffix
    assert human.exit_code == 0 and "wrote" in human.stdout and "ideal-paper" in human.stdout


@pytest.mark.parametrize("args,message", [
    (["--out", "x.txt"], "cannot tell the format"),
    (["--out", "x.h", "--noise", "1", "--delta-t", "10"], "outside table ideal-paper's grid"),
    (["--out", "x.h", "--prefix", "9lives"], "prefix must be a C identifier"),
    (["--out", "x.json", "--format", "xml"], "format must be one of"),
    (["--out", "x.json", "--e-min", "nan"], "must be finite"),
])
def test_cli_bad_input_is_one_line_and_status_2(cli, tmp_path, args, message):
    args = [str(tmp_path / a) if a.startswith("x.") else a for a in args]
    r = cli("export", "--table", "ideal-paper", *args)
    assert r.exit_code == 2
    assert message in r.stderr and r.stderr.count("\n") == 1
    assert not list(tmp_path.iterdir())  # nothing half-written


def test_console_script_exports_a_module_a_bare_python_can_use(tmp_path):
    exe = shutil.which("designkit") or str(Path(sys.executable).with_name("designkit"))
    out = tmp_path / "thermal_table.py"
    proc = subprocess.run([exe, "export", "--table", "ideal-paper", "--format", "python", "--noise", "0.05",
                           "--delta-t", "10", "--out", str(out)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    got = run_module(out, [("min_contact", (35000.0, 20000.0, 0.05, 10.0))], tmp_path)
    want = q.min_contact(35000, 20000, noise_c=0.05, delta_t_c=10.0, table="ideal-paper", ideal_table=None).value
    assert got == [pytest.approx(want, rel=1e-12)]


# ============================================================ robot-loop example
def test_robot_loop_example_decides_from_the_table(tmp_path):
    tab = ideal_table()
    module = tmp_path / "thermal_table.py"
    export_table(tab, module, "python", e_min=200.0, e_max=30000.0)
    proc = subprocess.run([sys.executable, "-I", "-S", str(EXAMPLES / "robot_loop" / "robot_loop.py"),
                           "--table", str(module), "--json"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    decisions = [json.loads(line) for line in proc.stdout.splitlines()]
    assert len(decisions) >= 4
    actions = set()
    for d in decisions:
        actions.add(d["action"])
        for p in d["pairs"] or []:
            want = q.min_contact(p["e_a"], p["e_b"], noise_c=d["noise_c"], delta_t_c=d["delta_t_c"], table=tab,
                                 ideal_table=None).value
            assert p["min_contact_s"] == (pytest.approx(want, rel=1e-12) if want is not None else None)
        if d["action"] == "touch":
            assert all(d["contact_s"] >= p["min_contact_s"] for p in d["pairs"])
            assert all(q.distinguishable(p["e_a"], p["e_b"], contact_s=d["contact_s"], noise_c=d["noise_c"],
                                         delta_t_c=d["delta_t_c"], table=tab, ideal_table=None).value
                       for p in d["pairs"])
        if d["action"] == "heat":
            for p in d["pairs_hot"]:
                want = q.min_contact(p["e_a"], p["e_b"], noise_c=d["noise_c"], delta_t_c=d["heat_to_delta_t_c"],
                                     table=tab, ideal_table=None).value
                assert want is not None and d["contact_s"] >= want
    assert {"touch", "heat"} <= actions
    human = subprocess.run([sys.executable, "-I", "-S", str(EXAMPLES / "robot_loop" / "robot_loop.py"),
                            "--table", str(module)], capture_output=True, text=True, timeout=120)
    assert human.returncode == 0 and "touch for" in human.stdout


# ============================================================ one lookup implementation
def test_lookup_module_is_stdlib_only_and_the_python_export_carries_it_verbatim():
    from designkit.tables import lookup

    text = Path(lookup.__file__).read_text(encoding="utf-8")
    assert imports_of(text) <= set(sys.stdlib_module_names)
    assert "from __future__" not in text  # it is pasted into the middle of a module
    src = render(slice_table(random_ratio_table()), "python").decode()
    begin, end = src.index(LOOKUP_BEGIN + "\n") + len(LOOKUP_BEGIN) + 1, src.index(LOOKUP_END)
    assert src[begin:end] == text
    assert lookup.GRID_RTOL == q.GRID_RTOL


@pytest.mark.parametrize("name", ["rand-ratio-e", "rand-varied-full", "svm-small-lo-slice"])
def test_lookup_on_numpy_arrays_answers_like_the_query(name):
    """The same Lookup in-process on numpy rows (what the query will use) and on array.array rows."""
    import array

    from designkit.export._common import log_grid
    from designkit.tables.lookup import Lookup, OutsideTable

    tab, opts, exp = case(name)
    scene = [(a.name, a.scale, np.asarray(a.values), np.asarray(log_grid(a))) for a in exp.scene_axes]
    common = dict(e_min=exp.e_lo, e_max=exp.e_hi, e_min_inclusive=exp.e_lo_inclusive,
                  contact_adjacent=exp.contact_adjacent, name=tab.name)
    on_numpy = Lookup(scene, np.asarray(exp.contact.values), np.asarray(exp.e_ref.values), exp.delta_up.ravel(),
                      exp.delta_down.ravel(), **common)
    on_array = Lookup([(n, s, v.tolist(), g.tolist()) for n, s, v, g in scene], list(exp.contact.values),
                      list(exp.e_ref.values), array.array("d", exp.delta_up.ravel().tolist()),
                      array.array("d", exp.delta_down.ravel().tolist()), **common)
    kind = opts.get("kind", "svm")
    names = {"min_contact": "min_contact_s"}
    seen = set()
    for op, args in random_queries(exp, np.random.default_rng(23), 150):
        if kind == "ideal" and op == "distinguishable":
            continue
        answers = []
        for lk in (on_numpy, on_array):
            try:
                answers.append(getattr(lk, names.get(op, op))(*args))
            except OutsideTable:
                answers.append("outside")
            except ValueError:
                answers.append("invalid")
        assert answers[0] == answers[1], (op, args, answers)
        got = answers[0]
        if got == "outside" and _beyond_slice(exp, op, args):
            continue
        want = on_contact_columns(exp, op, reference(tab, kind, op, args))
        seen.add(type(want).__name__)
        assert agree(float(got) if isinstance(got, np.floating) else got, want, 1e-9), (op, args, got, want)
    assert "float" in seen


# ============================================================ registry, formats
def test_registry_names_every_format_and_refuses_others_in_one_line():
    from designkit.export import SUFFIXES, WRITERS, format_for, get_writer

    assert FORMATS == ("json", "csv", "npz", "mat", "c", "python") == tuple(WRITERS)
    assert {SUFFIXES[s] for s in (".json", ".csv", ".npz", ".mat", ".h", ".py")} == set(FORMATS)
    exp = slice_table(random_ratio_table(), noise_c=0.02, delta_t_c=10.0)
    for fmt in FORMATS:
        assert render(exp, fmt)  # every writer is a function of the slice returning bytes
        assert format_for(f"x{WRITERS[fmt].suffixes[0]}", None) == fmt
    with pytest.raises(InputError) as err:
        get_writer("xlsx")
    assert str(err.value) == "format must be one of json, csv, npz, mat, c, python, got 'xlsx'"


def test_mat_file_holds_the_arrays_axes_and_provenance(tmp_path):
    from scipy.io import loadmat

    tab, _, exp = case("rand-varied-slice")
    (tmp_path / "t.mat").write_bytes(render(exp, "mat"))
    z = loadmat(str(tmp_path / "t.mat"))
    np.testing.assert_array_equal(z["delta_up"].reshape(exp.shape), exp.delta_up)
    assert z["axis_contact_s"].shape == (len(exp.contact.values), 1)
    assert json.loads(str(z["provenance"][0]))["source_content_hash"] == tab.header["content_hash"]


def test_csv_reads_with_default_readers_and_its_provenance_is_beside_it(tmp_path):
    """issue 16: pandas.read_csv(path) with its defaults; the csv module where pandas is not installed."""
    tab, _, exp = case("ideal-between-rows-e-contact")
    res = export_table(tab, tmp_path / "t.csv", noise_c=OFF_ROW[0], delta_t_c=OFF_ROW[1], e_min=15000.0,
                       e_max=36000.0, contact="1.1:4.1")
    text = res.path.read_text()
    assert "#" not in text
    columns = ["noise_ratio", "contact_s", "e_ref", "delta_up", "delta_down"]
    try:
        import pandas
    except ImportError:
        import csv

        with res.path.open(newline="") as fh:
            rows = list(csv.reader(fh))
        assert rows[0] == columns
        assert all(len(r) == len(columns) for r in rows[1:]) and len(rows) - 1 == exp.delta_up.size
        values = np.array([[float(x) for x in r] for r in rows[1:]])  # every field a number ("nan" included)
    else:
        frame = pandas.read_csv(res.path)
        assert list(frame.columns) == columns and len(frame) == exp.delta_up.size
        values = frame.to_numpy(dtype=float)
    assert np.isnan(values[:, 3]).sum() == np.isnan(exp.delta_up).sum()
    side = json.loads(res.sidecar.read_text())
    assert res.sidecar == tmp_path / "t.csv.json" and side["sidecar_of"] == "t.csv"
    assert side["provenance"]["source_table"] == "ideal-paper" and [c["name"] for c in side["columns"]] == columns
    with pytest.raises(InputError, match="sidecar of the CSV export"):
        read_export(res.sidecar)
    res.sidecar.unlink()
    with pytest.raises(InputError, match="sidecar t.csv.json is missing"):
        read_export(res.path)


@pytest.mark.parametrize("fmt", ["json", "npz", "mat", "csv", "c", "python"])
def test_every_export_records_the_forward_model(tmp_path, fmt):
    old = random_ratio_table()
    header = {k: v for k, v in old.header.items() if k != "model"}  # a table from before the header said
    tables = {"semi-infinite": Table(name="old", path=old.path, header=header, arrays=old.arrays),
              "contact": Table(name="hc", path=old.path, arrays=old.arrays,
                               header={**header, "model": {"name": "contact", "conductance_w_m2k": 1500.0}})}
    for model, tab in tables.items():
        res = export_table(tab, tmp_path / f"{model}{WRITER_SUFFIX[fmt]}", fmt)
        assert res.provenance["model"]["name"] == model
        data = res.path.read_bytes()
        if fmt in ("json", "npz", "mat", "csv"):
            assert read_export(res.path).provenance["model"] == tab.model.to_dict()
        elif fmt == "c":
            assert f'#define DESIGNKIT_MODEL "{model}"'.encode() in data
            assert (b"conductance_w_m2k" in data) == (model == "contact")
        else:
            assert imported(res.path, tmp_path, "MODEL") == tab.model.to_dict()


WRITER_SUFFIX = {"json": ".json", "csv": ".csv", "npz": ".npz", "mat": ".mat", "c": ".h", "python": ".py"}


def imported(path: Path, cwd: Path, *names: str):
    """Values of ``names`` (JSON) from importing the generated module ``path`` in `python -I -S`, run in ``cwd``."""
    code = ("import importlib.util, json, sys; s = importlib.util.spec_from_file_location('m', sys.argv[1]); "
            "m = importlib.util.module_from_spec(s); s.loader.exec_module(m); "
            "json.dump([getattr(m, n) for n in sys.argv[2:]] + [m.__doc__], sys.stdout)")
    proc = subprocess.run([sys.executable, "-I", "-S", "-c", code, str(path), *names], cwd=cwd, capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    return out[0] if len(names) == 1 else out


# ============================================================ injection (issue 15)
PAYLOADS = [
    'x */ int designkit_injected_c = 42; /*',
    'x"; int designkit_injected_c = 42; //',
    'x??/" int designkit_injected_c = 42; //',  # a C99 trigraph would turn ??/ into a backslash
    'x\n#define designkit_injected_c 42\n',
    'x\\\nint designkit_injected_c = 42;',
    'x"""; import os; os.system("touch PWNED"); """',
    "x'''; import os; os.system('touch PWNED'); '''",
    'x\\\n__import__("os").system("touch PWNED")',
    'x\r\n__import__("os").system("touch PWNED")',
    '\u2028__import__("os").system("touch PWNED") # \u00b0C \u4e2d',
    'x @P@ @DELTA_UP@ @LOOKUP_SOURCE@',
    'x\x00\x1b[31m,"\n1,2,3',
]


def injected_table(payload: str, name: str = "inj") -> Table:
    """A table whose every free-text header field holds ``payload`` (its names stay valid)."""
    base = random_ratio_table()
    header = json.loads(json.dumps(base.header))
    header.update(created=payload, fidelity=payload, content_hash=payload, designkit_version=payload)
    for a in header["axes"]:
        a["units"] = payload
    return Table(name=name, path=base.path, header=header, arrays=base.arrays)


def with_model(exp, payload: str):
    """``exp`` with a forward-model record holding ``payload`` in its name and a parameter (past the model
    registry, which refuses unknown names and non-numbers: this checks the writers' own escaping)."""
    import dataclasses

    return dataclasses.replace(exp, provenance={**exp.provenance, "model": {"name": payload, "param": payload,
                                                                            "n": 1.5}})


@pytest.mark.parametrize("i", range(len(PAYLOADS)))
def test_python_export_carries_any_text_and_runs_none(tmp_path, i):
    payload = PAYLOADS[i]
    exp = with_model(slice_table(injected_table(payload)), payload)
    path = tmp_path / "table_module.py"
    path.write_bytes(render(exp, "python"))
    src = path.read_text()
    assert src.isascii()  # every string from the table escaped
    prov, fidelity, model, doc = imported(path, tmp_path, "PROVENANCE", "FIDELITY", "MODEL")
    assert prov["source_created"] == payload and prov["source_content_hash"] == payload
    assert [a["units"] for a in prov["axes"]][:2] == [payload, payload]
    assert doc.startswith("designkit lookup table inj (")
    assert fidelity == payload and model == {"name": payload, "param": payload, "n": 1.5}
    assert not list(tmp_path.glob("PWNED*")) and not Path("PWNED").exists()
    got = run_module(path, [("min_contact", (2000.0, 5000.0, 0.02, 10.0))], tmp_path)
    assert got == [reference(random_ratio_table(), "svm", "min_contact", (2000.0, 5000.0, 0.02, 10.0))]


@pytest.mark.parametrize("i", range(len(PAYLOADS)))
def test_data_exports_carry_any_text_as_data(tmp_path, i):
    payload = PAYLOADS[i]
    exp = with_model(slice_table(injected_table(payload)), payload)
    rows = exp.delta_up.size
    csv_text = render(exp, "csv").decode()
    assert csv_text.count("\n") == rows + 1 and len({line.count(",") for line in csv_text.splitlines()}) == 1
    doc = json.loads(render(exp, "json"))
    assert doc["provenance"]["source_created"] == payload and doc["provenance"]["model"]["param"] == payload
    from designkit.export.formats.csv import sidecar

    assert json.loads(sidecar(exp, "t.csv"))["provenance"]["fidelity"] == payload
    (tmp_path / "t.npz").write_bytes(render(exp, "npz"))
    assert read_export(tmp_path / "t.npz").provenance["axes"][0]["units"] == payload
    (tmp_path / "t.mat").write_bytes(render(exp, "mat"))
    assert read_export(tmp_path / "t.mat").provenance["model"]["name"] == payload


@pytest.mark.parametrize("i", range(len(PAYLOADS)))
def test_unsafe_table_and_sensor_names_are_refused_in_one_line(tmp_path, i):
    payload = PAYLOADS[i]
    sensor_tab = injected_table("x", name="ok")
    sensor_tab.header["sensor"] = {**sensor_tab.header["sensor"], "name": payload}
    for tab, what in ((injected_table("x", name=payload), "table name"), (sensor_tab, "sensor name")):
        for fmt, suffix in (("c", ".h"), ("python", ".py"), ("csv", ".csv")):
            with pytest.raises(InputError, match="cannot be exported safely") as err:
                export_table(tab, tmp_path / f"t{suffix}", fmt)
            assert "\n" not in str(err.value) and what in str(err.value)
    assert not list(tmp_path.iterdir())


def test_safe_names_with_every_allowed_character_export(tmp_path):
    tab = injected_table("x", name="Lab table_v2.1+b-c 7")
    tab.header["sensor"] = {**tab.header["sensor"], "name": "rig 3.b_x+y-z"}
    path = tmp_path / "m.py"
    export_table(tab, path, "python")
    assert imported(path, tmp_path, "SOURCE_TABLE") == "Lab table_v2.1+b-c 7"


def test_cli_refuses_an_injected_table_name_and_a_prefix_with_a_newline(cli, tmp_path):
    base = random_ratio_table()
    header = {**base.header, "name": 'x */ int designkit_injected_c = 42; /*'}
    folder = tmp_path / "tables"
    path = write_table(folder / "inj.npz", header, {k: v for k, v in base.arrays.items()})
    out = tmp_path / "out"
    out.mkdir()
    r = cli("export", "--table", path, "--out", out / "t.h")
    assert r.exit_code == 2 and "cannot be exported safely" in r.stderr and r.stderr.count("\n") == 1
    r = cli("export", "--table", "ideal-paper", "--prefix", "designkit\n", "--out", out / "t.h")
    assert r.exit_code == 2 and "prefix must be a C identifier" in r.stderr
    assert not list(out.iterdir())


def test_an_export_never_writes_over_the_table_it_reads(cli, tmp_path):
    """--out (or a CSV's provenance sidecar) naming the source table's .npz or .json, also through a hard link,
    is refused in one line before anything is written; the table still loads, with its content hash."""
    base = random_ratio_table()
    src = write_table(tmp_path / "own.npz", base.header, dict(base.arrays))
    before = {p.name: p.read_bytes() for p in (src, src.with_suffix(".json"))}
    (tmp_path / "link.npz").hardlink_to(src)
    for out, fmt in (("own.npz", "npz"), ("own.json", "json"), ("own", "csv"), ("link.npz", "npz")):
        r = cli("export", "--table", src, "--format", fmt, "--out", tmp_path / out)
        assert r.exit_code == 2 and "is the table being exported" in r.stderr and r.stderr.count("\n") == 1, (out, r.output)
        with pytest.raises(InputError, match="is the table being exported"):
            export_table(load_table(src), tmp_path / out, fmt)
    assert {p.name: p.read_bytes() for p in (src, src.with_suffix(".json"))} == before
    assert load_table(src).header["content_hash"] == base.header["content_hash"]
    assert cli("export", "--table", src, "--format", "npz", "--out", tmp_path / "other.npz").exit_code == 0


@pytest.mark.parametrize("fmt,suffix", [("c", ".h"), ("python", ".py")])
def test_the_regenerate_line_writes_the_same_export_again(cli, tmp_path, fmt, suffix):
    """The "Regenerate:" command of an export, run as printed, writes the same file: for a shipped table it
    names the table; for a user's table (here one whose header says svm-paper, in a folder with a space) its
    path, where the name would have exported the shipped svm-paper instead."""
    import shlex

    base = load_table("ideal-paper")
    folder = tmp_path / "my tables"
    mine = write_table(folder / "mine.npz", {**base.header, "name": "svm-paper"}, dict(base.arrays))
    for table, named in (("ideal-paper", "--table ideal-paper "), (str(mine), f"--table {shlex.quote(str(mine))} ")):
        first = tmp_path / f"first{suffix}"
        r = cli("export", "--table", table, "--format", fmt, "--noise", "0.05", "--delta-t", "10", "--out", first)
        assert r.exit_code == 0, r.output
        line = next(x for x in first.read_text().splitlines() if "Regenerate:" in x)
        command = line.split("Regenerate:", 1)[1].strip()
        assert named in command, command
        args = shlex.split(command)
        assert args[:2] == ["designkit", "export"] and args[-2:] == ["--out", "FILE"]
        again = tmp_path / f"again{suffix}"
        r = cli(*args[1:-1], again)
        assert r.exit_code == 0, r.output
        assert again.read_text() == first.read_text()


def test_cli_writes_to_standard_output(cli, tmp_path):
    r = cli("export", "--table", "ideal-paper", "--noise", "0.05", "--delta-t", "10", "--contact", "2",
            "--format", "csv", "--out", "-")
    assert r.exit_code == 0, r.output
    lines = r.stdout.splitlines()
    assert lines[0] == "noise_ratio,contact_s,e_ref,delta_up,delta_down" and len(lines) == 501
    assert not Path("-").exists()
    r = cli("export", "--table", "ideal-paper", "--out", "-")
    assert r.exit_code == 2 and "needs --format" in r.stderr
