"""The C99 header: the example program compiled with the system compiler (-Werror) and
compared with designkit.query on random inputs; sanitizer builds queried at and beyond
every table edge; prefixes; float arithmetic."""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from designkit.query import table as q
from designkit.export import render, slice_table
from designkit.tables.store import load_table

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_export import (CASES, EXAMPLES, ON_ROW, PAYLOADS, _beyond_slice, agree, case, ideal_table,  # noqa: E402
                         injected_table, on_contact_columns, random_queries, random_ratio_table, reference,
                         with_model)

CC = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc") or shutil.which("clang")
pytestmark = pytest.mark.skipif(CC is None, reason="no C compiler (cc, gcc or clang) on PATH: the C header "
                                "cannot be compiled here")
STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]
SENTINELS = {-1.0: None, -2.0: "outside", -3.0: "invalid"}


def to_c(exp, prefix: str = "designkit") -> bytes:
    return render(exp, "c", prefix=prefix)


def build(tmp_path: Path, header: bytes, *, flags=("-O2",), name="lookup", source: Path | None = None) -> Path:
    """Compile the example program (or ``source``) against ``header`` in a fresh folder."""
    folder = tmp_path / name
    folder.mkdir()
    (folder / "designkit_table.h").write_bytes(header)
    src = folder / "main.c"
    shutil.copy(source or EXAMPLES / "c_lookup" / "main.c", src)
    exe = folder / name
    proc = subprocess.run([CC, *STRICT, *flags, "-o", str(exe), str(src), "-lm"], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    return exe


def _arg(x: float) -> str:
    return repr(float(np.float32(x))) if math.isfinite(x) else ("nan" if math.isnan(x) else ("inf" if x > 0 else "-inf"))


def run_batch(exe: Path, queries, env=None) -> list:
    """Answers of ``exe --batch``, mapped like the reference: float, None, bool, 'outside', 'invalid'."""
    # the header's grid rule (PREFIX_grid_*); its own functions (the library's estimator) are
    # tests/test_export_conformance.py's
    text = "".join(f"grid_{op} {' '.join(_arg(a) for a in args)}\n" for op, args in queries)
    proc = subprocess.run([str(exe), "--batch"], input=text, capture_output=True, text=True, timeout=300, env=env)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr[-3000:]
    out = []
    for (op, _), line in zip(queries, proc.stdout.splitlines(), strict=True):
        v = float(line)
        if op == "distinguishable":
            out.append({1.0: True, 0.0: False, -2.0: "outside", -3.0: "invalid"}[v])
        else:
            out.append(SENTINELS[v] if v < 0 else v)
    return out


def compare(tab, kind, exp, queries, got, rtol=2e-6):
    mismatches, seen = [], set()
    for (op, args), g in zip(queries, got):
        want = reference(tab, kind, op, args)
        if g == "outside" and _beyond_slice(exp, op, args):
            continue
        want = on_contact_columns(exp, op, want)
        seen.add(want if isinstance(want, str) else type(want).__name__)
        if not agree(g, want, rtol):
            mismatches.append((op, args, g, want))
    assert not mismatches, mismatches[:5]
    return seen


# ============================================================ the example question
def test_example_program_answers_the_35k_vs_20k_question(tmp_path):
    tab = ideal_table()
    want = q.min_contact(35000, 20000, noise_c=0.05, delta_t_c=10.0, table=tab, ideal_table=None).value
    exe = build(tmp_path, to_c(slice_table(tab, noise_c=0.05, delta_t_c=10.0)))
    check_example_answer(exe, tab, want)


def check_example_answer(exe: Path, tab, want: float) -> None:
    out = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60).stdout
    got = float(re.search(r"touch for at least ([0-9.]+) s", out).group(1))
    assert got == pytest.approx(want, rel=5e-3), out  # printed with 3 significant digits, as designkit does
    assert "separates them: yes" in out and "ideal-paper" in out and tab.header["content_hash"] in out
    # 0.05f / 10.0f is the sigma/dT row 0.005 itself, as 0.05 / 10 is in Python
    c = run_batch(exe, [("min_contact", (35000.0, 20000.0, 0.05, 10.0))])[0]
    assert c == pytest.approx(want, rel=1e-6)


# ============================================================ random inputs
@pytest.mark.slow  # a C compile and thousands of queries per case (5-15 s)
@pytest.mark.parametrize("name", [n for n in CASES if n != "svm-small-full"] + ["svm-small-full"])
def test_c_header_answers_like_the_query(tmp_path, name):
    tab, opts, exp = case(name)
    kind = opts.get("kind", "svm")
    exe = build(tmp_path, to_c(exp))
    queries = [(op, args) for op, args in random_queries(exp, np.random.default_rng(17), 200)
               if not (kind == "ideal" and op == "distinguishable")]
    seen = compare(tab, kind, exp, queries, run_batch(exe, queries))
    assert "float" in seen


@pytest.mark.slow
def test_c_header_of_the_whole_ideal_table(tmp_path):
    tab = ideal_table()
    exp = slice_table(tab)
    exe = build(tmp_path, to_c(exp), flags=("-O1",))
    queries = random_queries(exp, np.random.default_rng(5), 300)
    seen = compare(tab, "svm", exp, queries, run_batch(exe, queries))
    assert {"float", "outside", "NoneType"} <= seen
    want = q.min_contact(35000, 20000, noise_c=0.05, delta_t_c=10.0, table=tab, ideal_table=None).value
    check_example_answer(exe, tab, want)  # the example program on the whole table


@pytest.mark.slow  # a C compile and thousands of queries per case (5-15 s)
def test_c_header_of_the_shipped_svm_paper_table(tmp_path):
    tab = load_table("svm-paper")
    exp = slice_table(tab)
    exe = build(tmp_path, to_c(exp), flags=("-O1",))
    queries = random_queries(exp, np.random.default_rng(9), 200)
    compare(tab, "svm", exp, queries, run_batch(exe, queries))


# ============================================================ edges, sanitizers
def _edge_values(lo: float, hi: float) -> list[float]:
    """At, just inside, just beyond and far beyond both ends, and values that are not numbers."""
    return [lo, hi, lo * (1 + 1e-3), hi * (1 - 1e-3), lo * (1 - 1e-3), hi * (1 + 1e-3), lo * 0.5, hi * 2,
            0.5 * (lo + hi), math.nan, math.inf, -math.inf, 0.0, -1.0, 1e30, 1e-30]


def _edge_queries(exp) -> list[tuple[str, tuple]]:
    scene = exp.scene_axes
    if scene[0].name == "noise_ratio":
        r = scene[0].values
        noise_dt = [(x * 10.0, 10.0) for x in _edge_values(min(r), max(r))] + [(0.01, 0.0), (0.01, -10.0)]
        centre = (0.5 * (min(r) + max(r)) * 10.0, 10.0)
        if len(r) == 1:
            centre = (exp.provenance["slice"]["scene"]["noise_c"], exp.provenance["slice"]["scene"]["delta_t_c"])
    else:
        n, d = scene[0].values, scene[1].values
        noise_dt = [(x, d[0]) for x in _edge_values(min(n), max(n))] + [(n[0], x) for x in _edge_values(min(d), max(d))]
        centre = (n[0], d[0])
    c = exp.contact.values
    contacts = _edge_values(c[0], c[-1])
    es = _edge_values(max(exp.e_lo, 1e-3), exp.e_hi) + [exp.e_lo, float(np.nextafter(np.float32(exp.e_hi),
                                                                                     np.float32(np.inf)))]
    e_mid = 0.5 * (exp.e_lo + exp.e_hi)
    out = []
    for e in es:  # one argument at a time at and beyond its edges, the others in the middle
        out += [("delta_e", (e, *centre, c[0])), ("min_contact", (e, e_mid, *centre)),
                ("distinguishable", (e_mid, e, *centre, c[-1])), ("delta_e_upper", (e, *centre, c[-1])),
                ("delta_e_lower", (e, *centre, c[0]))]
    for nd in noise_dt:
        out += [("delta_e", (e_mid, *nd, c[0])), ("min_contact", (exp.e_lo + 1, exp.e_hi, *nd)),
                ("distinguishable", (exp.e_hi, e_mid, *nd, c[-1]))]
    for t in contacts:
        out += [("delta_e", (exp.e_hi, *centre, t)), ("distinguishable", (exp.e_hi, max(exp.e_lo, 1e-3), *centre, t))]
    rng = np.random.default_rng(0)  # and every combination of edges, a random sample of them
    for _ in range(600):
        e1, e2 = es[rng.integers(len(es))], es[rng.integers(len(es))]
        nd, t = noise_dt[rng.integers(len(noise_dt))], contacts[rng.integers(len(contacts))]
        out.append([("delta_e", (e1, *nd, t)), ("min_contact", (e1, e2, *nd)),
                    ("distinguishable", (e1, e2, *nd, t))][rng.integers(3)])
    return [(op, tuple(_f32(a) for a in args)) for op, args in out]  # what the C program receives


def _f32(x: float) -> float:
    return float(np.float32(x)) if math.isfinite(x) and abs(x) < 3e38 else x


def _invalid(op: str, args) -> bool:
    """What designkit.query refuses with InputError."""
    pair = op in ("min_contact", "distinguishable")
    es = args[:2] if pair else args[:1]
    noise, dt = (args[2], args[3]) if pair else (args[1], args[2])
    contact = None if op == "min_contact" else args[-1]
    return (any(not math.isfinite(a) for a in args) or any(e <= 0 for e in es) or (pair and es[0] == es[1])
            or noise < 0 or dt == 0 or (contact is not None and contact <= 0))


@pytest.mark.slow  # a C compile and thousands of queries per case (5-15 s)
@pytest.mark.parametrize("name", ["svm-small-full", "rand-varied-full", "ideal-row", "rand-ratio-e"])
def test_sanitizer_build_at_and_beyond_every_edge(tmp_path, name):
    tab, opts, exp = case(name)
    probe = subprocess.run([CC, "-fsanitize=address,undefined", "-x", "c", "-", "-o", str(tmp_path / "probe")],
                           input="int main(void){return 0;}", capture_output=True, text=True)
    if probe.returncode != 0 or subprocess.run([str(tmp_path / "probe")]).returncode != 0:
        pytest.skip(f"{CC} cannot build or run AddressSanitizer/UBSan programs here")
    exe = build(tmp_path, to_c(exp), flags=("-O1", "-g", "-fsanitize=address,undefined", "-fno-sanitize-recover=all",
                                            "-fno-omit-frame-pointer"))
    queries = _edge_queries(exp)
    env = {**os.environ, "ASAN_OPTIONS": "detect_leaks=0:halt_on_error=1", "UBSAN_OPTIONS": "halt_on_error=1"}
    got = run_batch(exe, queries, env=env)  # a sanitizer report would fail it (stderr must stay empty)
    kind = opts.get("kind", "svm")
    for (op, args), g in zip(queries, got):
        bad = _invalid(op, args)
        if bad:
            assert g == "invalid", (op, args, g)
            continue
        beyond_e = any(not (exp.e_lo < e <= exp.e_hi) and not (exp.e_lo_inclusive and e == exp.e_lo)
                       for e in (args[:2] if op in ("min_contact", "distinguishable") else args[:1]))
        if beyond_e:
            assert g == "outside", (op, args, g)
            continue
        if _snapped(tab, op, args):
            continue  # C takes 0.05f / 10.0f as the grid row 0.005 (the test of the example shows it)
        want = reference(tab, kind, op, args)
        if isinstance(want, str) or isinstance(g, str):
            # contact and scene edges: C matches grid edges to float precision (1e-6), query.py to 1e-12;
            # beyond that band both refuse
            if _far_beyond(exp, op, args):
                assert g == "outside" and (want == "outside" or _beyond_slice(exp, op, args)), (op, args, g, want)
            continue
        assert agree(g, on_contact_columns(exp, op, want), 2e-6), (op, args, g, want)


def _snapped(tab, op, args) -> bool:
    """A scene or contact coordinate within C's float tolerance (1e-6) of a source grid value,
    but not on it: C answers at the grid value, query.py a hair off it."""
    noise, dt = (args[2], args[3]) if op in ("min_contact", "distinguishable") else (args[1], args[2])
    contact = args[4] if op == "distinguishable" else (None if op == "min_contact" else args[3])
    ax = tab.axes
    coords = [("contact_s", contact)] if contact is not None else []
    coords += [("noise_ratio", noise / abs(dt))] if "noise_ratio" in ax else [("noise_c", noise), ("delta_t_c", dt)]
    return any(x != v and abs(x - v) <= 1e-6 * abs(v) for name, x in coords for v in ax[name])


def _far_beyond(exp, op, args) -> bool:
    """Scene or contact outside the export's grid by more than float precision."""
    noise, dt = (args[2], args[3]) if op in ("min_contact", "distinguishable") else (args[1], args[2])
    contact = args[4] if op == "distinguishable" else (None if op == "min_contact" else args[3])
    scene = exp.scene_axes
    tol = 1e-5

    def out(x, vals):
        return x < min(vals) * (1 - tol) or x > max(vals) * (1 + tol)

    if scene[0].name == "noise_ratio":
        if out(noise / abs(dt), scene[0].values):
            return True
    elif out(noise, scene[0].values) or out(dt, scene[1].values):
        return True
    return contact is not None and out(contact, exp.contact.values)


# ============================================================ prefixes, float arithmetic
TWO_TABLES = r'''
#include <stdio.h>
#include "left.h"
#include "right.h"
int main(void)
{
    printf("%.9g\n", left_min_contact_s(35000.0f, 20000.0f, 0.0625f, 12.5f));
    printf("%.9g\n", right_min_contact_s(2000.0f, 5000.0f, 0.0625f, 10.0f));
    printf("%.9g %s %s %d\n", LEFT_THRESHOLD, LEFT_SOURCE_TABLE, RIGHT_SOURCE_TABLE, RIGHT_N_E);
    printf("%d\n", left_distinguishable(35000.0f, 20000.0f, 0.0625f, 12.5f, 3.0f) == LEFT_YES);
    return 0;
}
'''


def test_two_prefixed_tables_live_in_one_program(tmp_path):
    left = slice_table(ideal_table(), noise_c=ON_ROW[0], delta_t_c=ON_ROW[1])
    right_tab = random_ratio_table()
    right = slice_table(right_tab)
    (tmp_path / "left.h").write_bytes(to_c(left, "left"))
    (tmp_path / "right.h").write_bytes(to_c(right, "right"))
    (tmp_path / "two.c").write_text(TWO_TABLES)
    exe = tmp_path / "two"
    proc = subprocess.run([CC, *STRICT, "-O2", "-o", str(exe), str(tmp_path / "two.c"), "-lm"], capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    lines = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60).stdout.splitlines()
    want_left = q.min_contact(35000, 20000, noise_c=ON_ROW[0], delta_t_c=ON_ROW[1], table=ideal_table(),
                              ideal_table=None).value
    right_ans = q.min_contact(2000, 5000, noise_c=0.0625, delta_t_c=10.0, table=right_tab, ideal_table=None)
    # the export carries the library's estimator: its answer, not the grid's raw crossing
    want_right = right_ans.value
    assert float(lines[0]) == pytest.approx(want_left, rel=1e-6)
    assert float(lines[1]) == (pytest.approx(want_right, rel=1e-6) if want_right is not None else -1.0)
    assert lines[2] == f"0.9 ideal-paper rand-ratio {len(right.e_ref.values)}"
    assert lines[3] == "1"


def test_float_arithmetic_variant_agrees_to_float_precision(tmp_path):
    tab = ideal_table()
    exp = slice_table(tab, noise_c=ON_ROW[0], delta_t_c=ON_ROW[1])
    exe = build(tmp_path, to_c(exp), flags=("-O2", "-DDESIGNKIT_FLOAT_MATH"))
    rng = np.random.default_rng(21)
    queries = [("delta_e", (float(np.float32(rng.uniform(100, 39000))), *ON_ROW,
                            float(np.float32(rng.uniform(0.5, 10))))) for _ in range(300)]
    queries.append(("min_contact", (35000.0, 20000.0, *ON_ROW)))
    got = run_batch(exe, queries)
    close = 0
    for (op, args), g in zip(queries, got):
        want = reference(tab, "svm", op, args)
        close += agree(g, want, 1e-4)
    assert close >= 0.99 * len(queries)  # float rounding may flip a value that sits on a NaN boundary
    assert got[-1] == pytest.approx(reference(tab, "svm", "min_contact", (35000.0, 20000.0, *ON_ROW)), rel=1e-4)


# ============================================================ injection (issue 15)
PRINT_STRINGS = r'''
#include <stdio.h>
#include "designkit_table.h"
static void hex(const char *s)
{
    for (; *s; s++) printf("%02x", (unsigned char)*s);
    printf("\n");
}
int main(void)
{
    hex(DESIGNKIT_SOURCE_CREATED);
    hex(DESIGNKIT_SOURCE_HASH);
    hex(DESIGNKIT_FIDELITY);
    hex(DESIGNKIT_MODEL);
    hex(DESIGNKIT_MODEL_PARAMETERS);
    printf("%.9g\n", designkit_min_contact_s(2000.0f, 5000.0f, 0.05f, 10.0f));
    return 0;
}
'''


def _code_outside_strings(cc: str, header: Path) -> str:
    """The header's tokens after the preprocessor (comments gone), string literals removed."""
    pre = subprocess.run([cc, "-std=c99", "-E", "-P", "-dD", str(header)], capture_output=True, text=True)
    assert pre.returncode == 0, pre.stderr
    return re.sub(r'"(\\.|[^"\\])*"', '""', pre.stdout)


@pytest.mark.parametrize("i", range(len(PAYLOADS)))
def test_c_header_carries_any_text_compiles_and_injects_nothing(tmp_path, i):
    payload = PAYLOADS[i]
    exp = with_model(slice_table(injected_table(payload)), payload)
    header = to_c(exp)
    assert header.isascii()
    folder = tmp_path / "inj"
    folder.mkdir()
    (folder / "designkit_table.h").write_bytes(header)
    assert "injected" not in _code_outside_strings(CC, folder / "designkit_table.h")
    (folder / "main.c").write_text(PRINT_STRINGS)
    proc = subprocess.run([CC, *STRICT, "-O0", "-o", str(folder / "p"), str(folder / "main.c"), "-lm"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr  # valid C, no warning, whatever the table's text
    lines = subprocess.run([str(folder / "p")], capture_output=True, text=True, timeout=60).stdout.splitlines()
    # C strings end at the first NUL byte: the payload up to it, in UTF-8
    want = payload.encode().split(b"\0")[0].hex()
    params = json.dumps({"n": 1.5, "param": payload}, sort_keys=True).encode().hex()
    assert lines[:5] == [want, want, want, want, params]
    want = reference(random_ratio_table(), "svm", "min_contact", (2000.0, 5000.0, 0.05, 10.0))
    assert float(lines[5]) == (-1.0 if want is None else pytest.approx(want, rel=1e-6))


@pytest.mark.parametrize("prefix", ["designkit\n", "x;int y", "9lives", "a b", "", "x" * 41, "é"])
def test_prefixes_that_are_not_c_identifiers_are_refused(prefix):
    with pytest.raises(ValueError, match="prefix must be a C identifier") as err:
        to_c(slice_table(random_ratio_table()), prefix)
    assert "\n" not in str(err.value)


def test_header_is_the_package_template_filled():
    from designkit.export._common import read_template
    from designkit.export.formats.c import TEMPLATE

    template = read_template(TEMPLATE)
    assert "@DELTA_UP@" in template and "static inline int @p@_axis_(" in template
    header = to_c(slice_table(random_ratio_table())).decode()
    assert not re.search(r"@[A-Za-z0-9_]+@", header)
