"""Exports against the library: 1,000 random questions asked of designkit, the C header, the Python module and the
data exports' reading rule (designkit.export.estimator_data.estimator_of), value by value, with per-call timings.

Questions (seed 38): min-contact, delta-e, distinguishable; e uniform in [100, 40000], noise in [0.01, 0.1] degC,
dT in [5, 15] degC, contact in [0.5, 10] s; table svm-fine (the library's default), exported whole.

    python benchmarks/bench_export.py                 # conformance and timings
    python benchmarks/bench_export.py --reference     # also (re)write tests/data/export_conformance.json
    python benchmarks/bench_export.py --baseline REV  # also REV's exports, timed in the same run
    DESIGNKIT_DATA_DIR=/tmp/rigfinal2/data python benchmarks/bench_export.py --rig-only  # the rig section alone

The rig section (issues 33, 34): the table registered for tests/data/rig_sensor.yaml (``designkit tables build
--sensor``, found in $DESIGNKIT_DATA_DIR) exported to Python and C; 50 random pairs (seed 34) of the paper's 12
materials' effusivity span asked of both and of the library (``designkit min-contact --sensor FILE``'s answer, at
the rig's recorded conditions, contact from its detected onset): max |difference| of value and ends in s, and how
many intervals agree (both ends within 1e-9 of the library's, relative, or both open); the same for delta-e at random
contacts from the onset within the table's contact axis. Skipped, saying so, where no table is registered.

Per-call times are CPU times (the machines are shared): C's clock(), Python's time.process_time(). With
``--baseline REV`` the module and header that commit's ``designkit/export`` writes (over this tree's
library, so the same tables) answer the same questions in the same run: their times are the baseline,
and the answers are compared with this tree's value by value.

An answer conforms when it is within 1 % of the library's value or inside its 90 % interval (None == None);
distinguishable's verdicts are compared where the contact lies outside min-contact's interval.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REFERENCE = HERE.parent / "tests" / "data" / "export_conformance.json"
N = 1000
SEED = 38


def questions(n: int = N, seed: int = SEED) -> dict[str, list[float]]:
    rng = np.random.default_rng(seed)
    q = {k: rng.uniform(a, b, n) for k, (a, b) in {"e1": (100, 40000), "e2": (100, 40000), "noise": (0.01, 0.1),
                                                     "dt": (5, 15), "contact": (0.5, 10)}.items()}
    return {k: [round(float(x), 6) for x in v] for k, v in q.items()}


def library(q: dict) -> dict:
    from designkit.query import delta_e, distinguishable, min_contact

    e1, e2, noise, dt, c = (np.asarray(q[k]) for k in ("e1", "e2", "noise", "dt", "contact"))
    out = {}
    t = time.perf_counter()
    a = min_contact(e1, e2, noise_c=noise, delta_t_c=dt)
    out["min_contact"] = [a.value.tolist(), a.low.tolist(), a.high.tolist()]
    b = delta_e(e1, contact_s=c, noise_c=noise, delta_t_c=dt)
    out["delta_e"] = [b.value.tolist(), b.low.tolist(), b.high.tolist()]
    d = distinguishable(e1, e2, contact_s=c, noise_c=noise, delta_t_c=dt)
    out["distinguishable"] = [d.value.tolist()]
    out["seconds"] = time.perf_counter() - t
    return out


def conforms(got, value, low, high) -> bool:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return got is None
    if got is None:
        return False
    return abs(got - value) <= 0.01 * abs(value) or (low is not None and not math.isnan(low) and low <= got
                                                     and (high is None or math.isnan(high) or got <= high))


C_MAIN = r'''
#include <stdio.h>
#include <time.h>
#include "dk_table.h"
int main(void) {
    double e1, e2, n, dt, c, iv[3], de[3], sink = 0;
    int k = 0, i, sure;
    clock_t t0;
    static double qs[4000][5];
    while (scanf("%lf %lf %lf %lf %lf", &e1, &e2, &n, &dt, &c) == 5) {
        int s1 = designkit_min_contact_interval(e1, e2, n, dt, iv);
        int s2 = designkit_delta_e_interval(e1, n, dt, c, de);
        int v = designkit_distinguishable_verdict(e1, e2, n, dt, c, &sure);
        printf("%d %.17g %.17g %.17g %d %.17g %.17g %.17g %d %d\n", s1, iv[0], iv[1], iv[2], s2, de[0], de[1], de[2],
               v, sure);
        qs[k][0] = e1; qs[k][1] = e2; qs[k][2] = n; qs[k][3] = dt; qs[k][4] = c;
        k++;
    }
    t0 = clock();
    for (i = 0; i < k; i++) designkit_min_contact_interval(qs[i][0], qs[i][1], qs[i][2], qs[i][3], iv);
    fprintf(stderr, "%.9g\n", (double)(clock() - t0) / CLOCKS_PER_SEC / k);
    t0 = clock();
    for (i = 0; i < k; i++) designkit_delta_e_interval(qs[i][0], qs[i][2], qs[i][3], qs[i][4], de);
    fprintf(stderr, "%.9g\n", (double)(clock() - t0) / CLOCKS_PER_SEC / k);
    t0 = clock();  /* the baseline in the same run: the grid rule (what the header answered before) */
    for (i = 0; i < k; i++) sink += designkit_grid_min_contact_s((float)qs[i][0], (float)qs[i][1], (float)qs[i][2],
                                                               (float)qs[i][3]);
    fprintf(stderr, "%.9g\n", (double)(clock() - t0) / CLOCKS_PER_SEC / k);
    t0 = clock();
    for (i = 0; i < k; i++) sink += designkit_grid_delta_e((float)qs[i][0], (float)qs[i][2], (float)qs[i][3],
                                                         (float)qs[i][4]);
    fprintf(stderr, "%.9g %g\n", (double)(clock() - t0) / CLOCKS_PER_SEC / k, sink > 0 ? 0.0 : 1.0);
    return 0;
}
'''


def c_answers(header: bytes, q: dict, workdir: Path):
    """Compile the header once; one process answers every question. Returns answers and seconds per call."""
    (workdir / "dk_table.h").write_bytes(header)
    (workdir / "main.c").write_text(C_MAIN)
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2", "main.c", "-lm", "-o",
                    "main"], cwd=workdir, check=True)
    lines = "".join(f"{q['e1'][i]!r} {q['e2'][i]!r} {q['noise'][i]!r} {q['dt'][i]!r} {q['contact'][i]!r}\n"
                    for i in range(len(q["e1"])))
    r = subprocess.run(["./main"], cwd=workdir, input=lines, capture_output=True, text=True, check=True)
    out = {"min_contact": [], "delta_e": [], "distinguishable": []}
    for line in r.stdout.splitlines():
        f = line.split()
        s1, s2 = int(f[0]), int(f[4])
        out["min_contact"].append(float(f[1]) if s1 == 0 else None)
        out["delta_e"].append(float(f[5]) if s2 == 0 else None)
        out["distinguishable"].append(int(f[8]) == 1)
    mc_t, de_t, gmc_t, gde_t = (float(x) for x in r.stderr.split()[:4])
    return out, {"min_contact": mc_t, "delta_e": de_t, "grid_min_contact": gmc_t, "grid_delta_e": gde_t}


def estimator_answers(est, q: dict, grid=None):
    """Every question asked of ``est``; with ``grid`` (a Lookup) also the grid rule's per-call times (baseline)."""
    out = {"min_contact": [], "delta_e": [], "distinguishable": []}
    times = {"min_contact": 0.0, "delta_e": 0.0}
    for i in range(len(q["e1"])):
        a = (q["e1"][i], q["e2"][i], q["noise"][i], q["dt"][i])
        t = time.process_time()
        out["min_contact"].append(est.min_contact_s(*a))
        times["min_contact"] += time.process_time() - t
        t = time.process_time()
        out["delta_e"].append(est.delta_e(a[0], a[2], a[3], q["contact"][i]))
        times["delta_e"] += time.process_time() - t
        out["distinguishable"].append(est.distinguishable(*a, q["contact"][i]))
        if grid is not None:
            t = time.process_time()
            grid.min_contact_s(*a)
            times["grid_min_contact"] = times.get("grid_min_contact", 0.0) + time.process_time() - t
            t = time.process_time()
            grid.delta_e(a[0], a[2], a[3], q["contact"][i])
            times["grid_delta_e"] = times.get("grid_delta_e", 0.0) + time.process_time() - t
    return out, {k: v / len(q["e1"]) for k, v in times.items()}


def score(ans: dict, ref: dict, q: dict) -> dict:
    res = {}
    for name in ("min_contact", "delta_e"):
        v, lo, hi = ref[name]
        ok = [conforms(g, a, b, c) for g, a, b, c in zip(ans[name], v, lo, hi)]
        res[name] = (sum(ok), len(ok))
    v, lo, hi = ref["min_contact"]
    outside = [i for i in range(len(q["e1"])) if not (lo[i] is not None and not math.isnan(lo[i])
                                                       and lo[i] <= q["contact"][i] <= (hi[i] if hi[i] is not None
                                                                                        and not math.isnan(hi[i])
                                                                                        else math.inf))]
    same = sum(bool(ans["distinguishable"][i]) == (ref["distinguishable"][0][i] == 1.0) for i in outside)
    res["distinguishable_outside_interval"] = (same, len(outside))
    return res


def baseline_exports(rev: str, workdir: Path) -> tuple[bytes, bytes]:
    """The Python module and C header of svm-fine that commit ``rev``'s designkit/export writes (over this tree's
    library and tables, in a subprocess)."""
    repo = HERE.parent
    base = workdir / "base"
    shutil.copytree(repo / "designkit", base / "designkit", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.rmtree(base / "designkit" / "export")
    archive = subprocess.run(["git", "-C", str(repo), "archive", rev, "designkit/export"], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(base)], input=archive, check=True)
    os.symlink(repo / "tables", base / "tables")
    code = ("import sys; from designkit.export import render, slice_table; e = slice_table('svm-fine'); "
            "open(sys.argv[1], 'wb').write(render(e, 'python')); open(sys.argv[2], 'wb').write(render(e, 'c'))")
    subprocess.run([sys.executable, "-c", code, str(workdir / "dk_base.py"), str(workdir / "base.h")], check=True,
                   env={**os.environ, "PYTHONPATH": str(base)}, cwd=workdir)
    return (workdir / "dk_base.py").read_bytes(), (workdir / "base.h").read_bytes()


def same_answers(a: dict, b: dict) -> str:
    """How many answers of two runs are equal, per question."""
    return ", ".join(f"{k} {sum(x == y for x, y in zip(a[k], b[k]))}/{len(a[k])}" for k in a)


RIG_SENSOR = HERE.parent / "tests" / "data" / "rig_sensor.yaml"


def rig_section(n: int = 50, seed: int = 34) -> None:
    """The rig's own table exported to Python and C against the library for that sensor (see the docstring)."""
    import importlib.util

    from designkit.export import render, slice_table
    from designkit.materials import list_materials
    from designkit.query import ask
    from designkit.sensor import load_sensor
    from designkit.tables.registry import table_for_sensor

    tab = table_for_sensor(load_sensor(str(RIG_SENSOR)))
    if tab is None:
        print(f"rig: no table registered for {RIG_SENSOR.name} in DESIGNKIT_DATA_DIR="
              f"{os.environ.get('DESIGNKIT_DATA_DIR')!r} ('designkit tables build --sensor'): section skipped")
        return
    mats = list_materials(set="paper12")
    span = (min(m.e_min for m in mats), max(m.e_max for m in mats))
    rng = np.random.default_rng(seed)
    e1, e2 = rng.uniform(*span, n), rng.uniform(*span, n)
    t = time.perf_counter()
    lib = ask("min-contact", e1=e1, e2=e2, sensor=str(RIG_SENSOR))
    lib_s = time.perf_counter() - t
    cond = lib.conditions
    noise, dt = cond["noise_c"]["value"], cond["delta_t_c"]["value"]
    ref = np.stack([lib.value, lib.low, lib.high], axis=1)
    exp = slice_table(tab)
    # delta-e at contacts from the rig's detected onset within the table's (model-time) contact axis
    grid = tab.axes["contact_s"] + exp.estimator["onset_offset_s"]
    contact = rng.uniform(grid[0], grid[-1], n)
    de = ask("delta-e", e=e1, contact_s=contact, sensor=str(RIG_SENSOR))
    de_ref = np.stack([de.value, de.low, de.high], axis=1)
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        (d / "rig_table.py").write_bytes(render(exp, "python"))
        spec = importlib.util.spec_from_file_location("rig_table", d / "rig_table.py")
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        py = np.array([[np.nan if x is None else x for x in mod.min_contact_interval(e1[i], e2[i], noise, dt)]
                       for i in range(n)])
        py_de = np.array([[np.nan if x is None else x for x in mod.delta_e_interval(e1[i], noise, dt, contact[i])]
                          for i in range(n)])
        (d / "dk_table.h").write_bytes(render(exp, "c"))
        (d / "main.c").write_text(r'''#include <stdio.h>
#include "dk_table.h"
int main(void) {
    double e1, e2, n, dt, c, iv[3], de[3];
    while (scanf("%lf %lf %lf %lf %lf", &e1, &e2, &n, &dt, &c) == 5) {
        int s = designkit_min_contact_interval(e1, e2, n, dt, iv), s2 = designkit_delta_e_interval(e1, n, dt, c, de);
        printf("%d %.17g %.17g %.17g %d %.17g %.17g %.17g\n", s, iv[0], iv[1], iv[2], s2, de[0], de[1], de[2]);
    }
    return 0;
}
''')
        subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2", "main.c", "-lm", "-o",
                        "main"], cwd=d, check=True)
        lines = "".join(f"{float(e1[i])!r} {float(e2[i])!r} {noise!r} {dt!r} {float(contact[i])!r}\n" for i in range(n))
        out = subprocess.run(["./main"], cwd=d, input=lines, capture_output=True, text=True, check=True).stdout
        rows = [line.split() for line in out.splitlines()]
        c, c_de = (np.array([[np.nan if int(f[j]) != 0 or float(x) < 0 else float(x) for x in f[j + 1:j + 4]]
                             for f in rows]) for j in (0, 4))
    print(f"rig: table {tab.name} ({tab.header['content_hash'][:19]}), sensor {RIG_SENSOR.name}, {n} random pairs "
          f"in the paper's 12 materials' span {span[0]:.0f}-{span[1]:.0f} J s^-1/2 K^-1 m^-2 (seed {seed}), noise "
          f"{noise:.4g} degC, dT {dt:.4g} degC (the sensor file's), contact from the rig's detected onset "
          f"({exp.estimator['onset_offset_s']:+.4f} s); library {lib_s:.2f} s for the array")
    print(f"rig: library answers {int(np.isfinite(ref[:, 0]).sum())}/{n} (none within the table: "
          f"{int(np.isnan(ref[:, 0]).sum())}); intervals with both ends {int(np.isfinite(ref[:, 1:]).all(1).sum())}")
    e_unit = "J s^-1/2 K^-1 m^-2"
    for name, got, want, unit in (("python", py, ref, "s"), ("C", c, ref, "s"), ("python", py_de, de_ref, e_unit),
                                  ("C", c_de, de_ref, e_unit)):
        same_none = (np.isnan(got) == np.isnan(want)).all(axis=1)
        diff = np.where(np.isnan(got) & np.isnan(want), 0.0, np.abs(got - want))
        ends = same_none & (diff[:, 1:] <= 1e-9 * np.fmax(np.abs(want[:, :1]), 1.0)).all(axis=1)
        print(f"rig: {name:6s} {'min-contact' if unit == 's' else 'delta-e'} max |difference| value "
              f"{np.nanmax(diff[:, 0]):.2e} {unit}, low {np.nanmax(diff[:, 1]):.2e} {unit}, "
              f"high {np.nanmax(diff[:, 2]):.2e} {unit}; none where the library's none {int(same_none.sum())}/{n}; "
              f"intervals agreeing {int(ends.sum())}/{n}")
    print(f"rig: delta-e at contacts {contact.min():.2f}-{contact.max():.2f} s from the onset: library answers "
          f"{int(np.isfinite(de_ref[:, 0]).sum())}/{n}")


def main(argv: list[str]) -> None:
    from designkit.export import export_bytes, read_export, render, slice_table
    from designkit.export.estimator_data import estimator_of

    rig_section()
    if "--rig-only" in argv:
        return
    q = questions()
    baseline = argv[argv.index("--baseline") + 1] if "--baseline" in argv else None
    if "--reference" in argv or not REFERENCE.is_file():
        print("asking the library (array route) ...", flush=True)
        ref = library(q)
        REFERENCE.write_text(json.dumps({"seed": SEED, "table": "svm-fine", "questions": q, "library": ref}))
    ref = json.loads(REFERENCE.read_text())["library"]
    print(f"library: {ref['seconds']:.1f} s for the 3 x {N} questions (array route)")
    t = time.perf_counter()
    exp = slice_table("svm-fine")
    print(f"slice with estimator constants: {time.perf_counter() - t:.1f} s")
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        header = render(exp, "c")
        print(f"C header of the whole table: {len(header) / 1e6:.1f} MB")
        one = export_bytes("svm-fine", "c", noise_c=0.05, delta_t_c=10.0).data
        print(f"C header of the one-scene slice (0.05 degC, 10 degC): {len(one) / 1e6:.2f} MB (target <= 2 MB)")
        c_ans, c_t = c_answers(header, q, d)
        (d / "dk.py").write_bytes(render(exp, "python"))
        sys.path.insert(0, str(d))
        import dk  # noqa: E402
        rows = {}
        if baseline:
            base_py, base_h = baseline_exports(baseline, d)
            (d / "cbase").mkdir()
            rows[f"C {baseline}"] = c_answers(base_h, q, d / "cbase")
            import dk_base  # noqa: E402
            rows[f"python {baseline}"] = estimator_answers(dk_base._EST, q)
        py_ans, py_t = estimator_answers(dk._EST, q, dk.TABLE)
        rows.update({"C": (c_ans, c_t), "python": (py_ans, py_t)})
        for fmt in ("json", "csv", "npz"):
            f = d / f"t.{fmt}"
            f.write_bytes(render(exp, fmt))
            if fmt == "csv":
                from designkit.export.formats.csv import sidecar, sidecar_path
                sidecar_path(f).write_bytes(sidecar(exp, f.name))
            rows[fmt] = estimator_answers(estimator_of(read_export(f)), q)
    for fmt, (ans, times) in rows.items():
        s = score(ans, ref, q)
        print(f"{fmt:14s} " + "  ".join(f"{k} {a}/{b} ({100 * a / max(b, 1):.1f} %)" for k, (a, b) in s.items())
              + f"  per call: min-contact {times['min_contact'] * 1e6:.1f} us, delta-e {times['delta_e'] * 1e6:.1f} us"
              + (f" (grid rule in the same run: {times['grid_min_contact'] * 1e6:.2f} us, "
                 f"{times['grid_delta_e'] * 1e6:.2f} us)" if "grid_min_contact" in times else ""))
    if baseline:
        for fmt in ("C", "python"):
            new, old = rows[fmt], rows[f"{fmt} {baseline}"]
            print(f"{fmt}: answers equal to {baseline}'s: {same_answers(new[0], old[0])}; per call "
                  f"{baseline} -> now: min-contact {old[1]['min_contact'] * 1e6:.1f} -> "
                  f"{new[1]['min_contact'] * 1e6:.1f} us ({old[1]['min_contact'] / new[1]['min_contact']:.1f}x), "
                  f"delta-e {old[1]['delta_e'] * 1e6:.1f} -> {new[1]['delta_e'] * 1e6:.1f} us "
                  f"({old[1]['delta_e'] / new[1]['delta_e']:.1f}x)")


if __name__ == "__main__":
    main(sys.argv[1:])
