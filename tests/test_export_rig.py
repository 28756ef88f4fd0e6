"""Exports of a table without a closed-form ideal observer answer as designkit does for that sensor (issues 33, 34).

A calibrated rig's table is answered by the library from both directions' needs averaged, the rounding-corrected
need crossed in its own cell, the Monte Carlo ends by the same rule, contact counted from the rig's detected onset
(:func:`designkit.query.estimates.varied_estimate`, :func:`designkit.rig.for_rig`). The Python module, the data
exports' reading rule and the compiled C header carry that rule: asked the same random pairs, they give the
library's value and 90 % interval, as ``designkit min-contact --sensor FILE`` does from the sensor's registered
table. No table is built: the synthetic staircases of tests/test_table_crossing_bias.py, registered for
tests/data/rig_sensor.yaml in a data folder of the test's own.

Tolerances: the module and the reading rule run the library's steps in Python floats (``math`` for numpy's log,
exp, hypot), the header the same steps in C doubles (libm) over the same arrays in float32, which hold the table's
deltas exactly (multiples of half a width): both agree with the library to float rounding, 1e-12 relative
(measured on the rig's own table, benchmarks/bench_export.py: min-contact bit for bit, the C's delta-e ends within
about 1e-15 relative).
"""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from designkit.export import export_bytes, render, slice_table
from designkit.export.estimator_data import estimator_of
from designkit.query import ask
from designkit.sensor import load_sensor
from designkit.sweep import SweepConfig
from designkit.tables.store import load_table, table_header, write_table

HERE = Path(__file__).resolve().parent
RIG = str(HERE / "data" / "rig_sensor.yaml")
CC = shutil.which("cc") or shutil.which("gcc")
STRICT = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic")
RTOL = 1e-12
#: The synthetic table's one sigma/dT row, asked as noise 0.004 degC over dT 1 degC.
SCENE = (0.004, 1.0)
#: A C program answering one question per input line: min-contact's, delta-e's interval and distinguishable.
C_MAIN = r"""#include <stdio.h>
#include "t.h"
int main(void)
{
    double e1, e2, n, d, c, o[3];
    int s, sure;
    while (scanf("%lf %lf %lf %lf %lf", &e1, &e2, &n, &d, &c) == 5) {
        s = designkit_min_contact_interval(e1, e2, n, d, o);
        printf("%d %.17g %.17g %.17g", s, o[0], o[1], o[2]);
        s = designkit_delta_e_interval(e1, n, d, c, o);
        printf(" %d %.17g %.17g %.17g", s, o[0], o[1], o[2]);
        s = designkit_distinguishable_verdict(e1, e2, n, d, c, &sure);
        printf(" %d %d\n", s, sure);
    }
    return 0;
}
"""


def rig_table(folder: Path, sensor: str):
    """A tiny fixed-condition SVM table for ``sensor`` under its file's model (the rig's force ramp over a layered
    skin: no closed-form ideal observer): the synthetic staircases of tests/test_table_crossing_bias.py."""
    sys.path.insert(0, str(HERE))
    from test_table_crossing_bias import _table

    src = _table(0)
    arrays = {k: np.asarray(v) for k, v in src.arrays.items()}
    cfg = SweepConfig(name="rig-bias", e_min=0.0, e_max=src.header["effusivity"]["max"],
                      intervals=int(src.arrays["delta_up"].shape[-1]), noise_ratio=(SCENE[0] / SCENE[1],),
                      contact_s=tuple(src.header["config"]["contact_s"]), sensor=sensor)  # (the file's model)
    return load_table(write_table(folder / "rig-bias.npz", table_header(cfg, arrays), arrays))


@pytest.fixture
def registered(tmp_path, monkeypatch):
    """The rig's table as ``designkit tables build --sensor`` leaves it: registered for the sensor file."""
    from designkit.tables.registry import register_table

    monkeypatch.setenv("DESIGNKIT_DATA_DIR", str(tmp_path / "data"))
    tab = rig_table(tmp_path, RIG)
    register_table(load_sensor(RIG), tab.path, sensor_file=RIG)
    return tab


def _pairs(n: int, seed: int):
    """Random pairs whose crossings mostly lie inside the table's contact grid (need 1200 t^-1.5), and contacts."""
    rng = np.random.default_rng(seed)
    gap = np.exp(rng.uniform(np.log(100.0), np.log(1900.0), n))
    lo = rng.uniform(300.0, 9000.0 - gap)
    return lo, lo + gap, rng.uniform(0.3, 5.0, n)  # from the onset: the model's 0.75-6 s less 0.64


def _same(got, want) -> bool:
    """One answer's value or end (None / -1 for none) against the library's (NaN: none), to float rounding."""
    if got is None or got == -1.0:
        return bool(np.isnan(want))
    return not np.isnan(want) and math.isclose(got, want, rel_tol=RTOL, abs_tol=RTOL)


def test_the_module_and_the_reading_rule_answer_as_the_library_for_the_rig(registered, load_python_export):
    from designkit.rig import model_start_s

    start = model_start_s(load_sensor(RIG))
    assert start is not None and start < -0.5  # the rig counts from its detected onset
    lo, hi, contact = _pairs(24, 33)
    lib = ask("min-contact", e1=lo, e2=hi, noise_c=SCENE[0], delta_t_c=SCENE[1], sensor=RIG)
    assert lib.route == "table" and "built for sensor rig" in lib.route_reason
    assert np.isfinite(lib.value).sum() >= 20 and np.isfinite(lib.low).sum() >= 20
    exp = slice_table(registered)
    assert exp.provenance["estimator"]["answers"] == "library" and exp.estimator["onset_offset_s"] == start
    assert exp.provenance["contact_frame"]["onset_offset_s"] == start
    assert f"{start:.6g}" in render(exp, "python").decode().split('"""')[1]  # the module's opening text says so
    mod = load_python_export(exp, "rig_mod")
    reader = estimator_of(exp)
    grid_late = 0
    for i in range(lo.size):
        want = (lib.value[i], lib.low[i], lib.high[i])
        for got in (mod.min_contact_interval(lo[i], hi[i], *SCENE), reader.min_contact_interval(lo[i], hi[i], *SCENE)):
            assert all(_same(g, w) for g, w in zip(got, want)), (i, got, want)
        grid = mod.TABLE.min_contact_s(lo[i], hi[i], *SCENE)  # the grid rule: model time, both directions' max
        grid_late += grid is not None and grid + start > lib.value[i] + 1e-9
    assert grid_late >= 12  # what the export answered before it carried the library's rule
    # delta-e and distinguishable take contact from the onset too
    de = ask("delta-e", e=lo, contact_s=contact, noise_c=SCENE[0], delta_t_c=SCENE[1], sensor=RIG)
    dist = ask("distinguishable", e1=lo, e2=hi, contact_s=contact, noise_c=SCENE[0], delta_t_c=SCENE[1], sensor=RIG,
               ideal_bound=False)  # (the ideal F1 of a model without closed form: simulated, not compared)
    assert np.isfinite(de.value).sum() >= 20
    sure = 0
    for i in range(lo.size):
        got = mod.delta_e_interval(lo[i], *SCENE, contact[i])
        assert all(_same(g, w) for g, w in zip(got, (de.value[i], de.low[i], de.high[i]))), i
        yes, confident = mod.distinguishable_verdict(lo[i], hi[i], *SCENE, contact[i])
        if confident:  # outside min-contact's interval: the library's verdict
            sure += 1
            assert float(yes) == dist.value[i], i
    assert sure >= 12


@pytest.mark.skipif(CC is None, reason="no C compiler")
def test_the_c_header_answers_as_the_library_for_the_rig(registered, tmp_path):
    lo, hi, contact = _pairs(24, 34)
    lib = ask("min-contact", e1=lo, e2=hi, noise_c=SCENE[0], delta_t_c=SCENE[1], sensor=RIG)
    de = ask("delta-e", e=lo, contact_s=contact, noise_c=SCENE[0], delta_t_c=SCENE[1], sensor=RIG)
    header = export_bytes(registered, "c").data.decode()
    assert "#define DESIGNKIT_HAS_ESTIMATOR 1" in header and "#define DESIGNKIT_EFFICIENCY_ 0" in header
    assert "detected onset" in header.split("*/", 1)[0] and "#define DESIGNKIT_ONSET_OFFSET_S -0.64" in header
    (tmp_path / "t.h").write_text(header)
    (tmp_path / "main.c").write_text(C_MAIN)
    proc = subprocess.run([CC, *STRICT, "-O1", "main.c", "-lm", "-o", "main"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = "".join(f"{float(lo[i])!r} {float(hi[i])!r} {SCENE[0]!r} {SCENE[1]!r} {float(contact[i])!r}\n"
                    for i in range(lo.size))
    out = subprocess.run(["./main"], cwd=tmp_path, input=lines, capture_output=True, text=True, timeout=60,
                         check=True).stdout.splitlines()
    assert len(out) == lo.size
    for i, line in enumerate(out):
        f = line.split()
        if int(f[0]) == -1:  # none within the table
            assert np.isnan(lib.value[i]), (i, line)
        else:
            assert int(f[0]) == 0 and all(_same(float(g), w) for g, w in
                                          zip(f[1:4], (lib.value[i], lib.low[i], lib.high[i]))), (i, line)
        assert int(f[4]) == 0 and all(_same(float(g), w) for g, w in
                                      zip(f[5:8], (de.value[i], de.low[i], de.high[i]))), (i, line)


def test_a_paper_table_s_export_still_answers_as_the_library(load_python_export):
    """svm-fine's one-scene slice (the efficiency route): the module's min-contact at 24 random pairs within one
    sample of the library's and its interval's ends within 1 % (the critical noise is read off a grid: within
    2e-4 of the library's, docs/exports.md); the full 1,000-question comparison is tests/test_export_conformance.py."""
    from designkit.query import min_contact

    rng = np.random.default_rng(38)
    lo = rng.uniform(500.0, 30000.0, 24)
    hi = lo + np.exp(rng.uniform(np.log(2000.0), np.log(9000.0), lo.size))
    lib = min_contact(lo, hi, noise_c=0.05, delta_t_c=10.0)
    exp = slice_table("svm-fine", noise_c=0.05, delta_t_c=10.0)
    assert exp.estimator["onset_offset_s"] == 0.0  # the paper's sensor: the model's time 0
    mod = load_python_export(exp, "paper_mod")
    answered = 0
    for i in range(lo.size):
        v, low, high = mod.min_contact_interval(lo[i], hi[i], 0.05, 10.0)
        if v is None:
            assert np.isnan(lib.value[i])
            continue
        answered += 1
        assert abs(v - lib.value[i]) <= 1.0 / 200 + 1e-9, (i, v, lib.value[i])
        assert low == pytest.approx(lib.low[i], rel=0.01) and high == pytest.approx(lib.high[i], rel=0.01)
    assert answered >= 20


def test_export_with_a_sensor_file_writes_the_table_its_questions_read(registered, cli, tmp_path, load_python_export):
    """``designkit export --sensor FILE`` without ``--table``: the table registered for the sensor (was: svm-fine,
    refused as another sensor's)."""
    out = tmp_path / "rig_table.py"
    r = cli("export", "--sensor", RIG, "--out", out)
    assert r.exit_code == 0, r.output
    assert "from table rig-bias" in r.output and "answers as designkit does" in r.output
    assert "contact counted from the rig's detected onset (the model's time 0 at -0.643 s)" in r.output
    # its one sigma/dT row, which an export reads to 1e-6 (this table's is not the sensor file's noise / dT)
    assert "one sigma/dT row, 0.004: ask at that ratio (to 1e-6)" in r.output, r.output
    mod = load_python_export(out.read_bytes(), "rig_cli")
    lib = ask("min-contact", e1=2000.0, e2=2600.0, noise_c=SCENE[0], delta_t_c=SCENE[1], sensor=RIG)
    assert lib.value is not None and mod.min_contact_s(2000.0, 2600.0, *SCENE) == pytest.approx(lib.value, rel=RTOL)


def test_between_two_sigma_dt_rows_each_row_answers_and_log_t_is_interpolated(tmp_path):
    """Two sigma/dT rows of a table without closed form (the paper's sensor: no onset offset): at noises between
    them the reading rule answers as the library's array route without a simulated bound (what a sensor's own
    table answers), value and interval."""
    from designkit.query import min_contact

    sys.path.insert(0, str(HERE))
    from test_table_crossing_bias import _table

    a, b = _table(0), _table(1)
    arrays = {k: np.concatenate([np.asarray(a.arrays[k]), np.asarray(b.arrays[k])]) for k in a.arrays}
    cfg = SweepConfig(name="two-rows", e_min=0.0, e_max=a.header["effusivity"]["max"],
                      intervals=int(a.arrays["delta_up"].shape[-1]), noise_ratio=(0.004, 0.008),
                      contact_s=tuple(a.header["config"]["contact_s"]), model={"name": "contact",
                                                                               "conductance_w_m2k": 1500.0})
    tab = load_table(write_table(tmp_path / "two.npz", table_header(cfg, arrays), arrays))
    reader = estimator_of(slice_table(tab))
    lo, hi, _ = _pairs(24, 35)
    noise = np.random.default_rng(35).uniform(0.004, 0.008, lo.size)
    lib = min_contact(lo, hi, noise_c=noise, delta_t_c=1.0, table=tab, ideal_bound=False, ideal_table=None)
    assert np.isfinite(lib.value).sum() >= 20
    for i in range(lo.size):
        got = reader.min_contact_interval(lo[i], hi[i], noise[i], 1.0)
        assert all(_same(g, w) for g, w in zip(got, (lib.value[i], lib.low[i], lib.high[i]))), i
