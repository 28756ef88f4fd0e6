"""A calibrated sensor's own table (issues 34 and 35): coverage of its 90 % intervals against the exact route,
and the time of a question answered from it.

Usage::

    # once: a sensor file of the real rig, and its table for the paper's 12 materials
    designkit calibrate fit ../shared/data/robot-thermal-recordings/index.csv --range metal=aluminium \
        --only metal,wood --out /tmp/rig.yaml
    designkit tables build --sensor /tmp/rig.yaml --materials paper12 -j 2   # or tests/data/rig_sensor.yaml
    # the exact route on random pairs (minutes each on a loaded machine; resumable, appends as it goes)
    nice -n 10 python benchmarks/bench_sensor_table.py --sensor /tmp/rig.yaml --out /tmp/bst --phase exact
    # the table's answers against them, and the time of a question from a fresh shell
    python benchmarks/bench_sensor_table.py --sensor /tmp/rig.yaml --out /tmp/bst --phase table
    # the truth for a few pairs: fresh-seed F1 at fixed contacts around both answers, a smooth fit's crossing
    nice -n 10 python benchmarks/bench_sensor_table.py --sensor /tmp/rig.yaml --out /tmp/bst --phase truth --indices 0,1,2
    # --exact against that truth, the straight-line fit (before issue 34) and the curvature fit (now) on the same
    # evaluations of the route (the route runs once per pair with this tree; its evaluations are replayed)
    nice -n 5 python benchmarks/bench_sensor_table.py --sensor tests/data/rig_sensor.yaml --out /tmp/bst --phase bias \
        --indices 0,1,2,9,15,17 --truth benchmarks/results/sensor_table_truth.jsonl
    # where a build's CPU goes (one block of 20 references at each contact; no table needed)
    python benchmarks/bench_sensor_table.py --sensor tests/data/rig_sensor.yaml --out /tmp/bst --phase profile

Pairs: effusivities log-uniform in the table's span (the lower one in [200, 30000]), the ratio of the two
log-uniform in [1.05, 3]; min-contact at the rig's conditions as calibrated (its noise and dT, its correlated
noise, read from the detected onset). The exact route is the one ``--exact`` takes (``--repeats`` seeds of 100
trials per class, default 4 as ``--exact``; the Monte Carlo ideal bound), with seeds ``1000 + i`` (the table's
are 0), stored as the model counts contact; the table's answers are the library's whole question
(``designkit.query.min_contact(e1, e2, sensor=FILE)``: the route policy finds the table), counted from the
rig's detected onset, and the exact values are moved by the same offset.

Coverage: the fraction of the table's stated 90 % intervals holding the exact route's value. The exact value
has its own Monte Carlo error, which dilutes that fraction below the intervals' own coverage; the z-scores
``(table - exact) / sqrt(sd_table^2 + sd_exact^2)`` (each sd from its stated interval) are given beside it:
their spread is 1 for calibrated intervals.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np

E_LO = (200.0, 30000.0)
RATIO = (1.05, 3.0)
Z90 = 1.6448536269514722


def draw_pairs(n: int, seed: int, e_max: float) -> list[dict]:
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        lo = float(np.exp(rng.uniform(*np.log(E_LO))))
        hi = lo * float(np.exp(rng.uniform(*np.log(RATIO))))
        if hi <= e_max - 80.0:
            out.append({"index": len(out), "e1": round(lo, 1), "e2": round(hi, 1)})
    return out


def _scene(sensor):
    from designkit.rig import resolve_scene

    return resolve_scene(sensor, {"noise_c": None, "delta_t_c": None}).values


def exact_case(sensor_file: str, case: dict, repeats: int = 4, solver: str = "batched", evaluations: bool = False) -> dict:
    from designkit.models import sensor_model
    from designkit.query.exact import exact_min_contact
    from designkit.sensor import load_sensor

    sen = load_sensor(sensor_file)
    sc = _scene(sen)
    t0, c0 = time.perf_counter(), time.process_time()
    a = exact_min_contact(case["e1"], case["e2"], noise_c=sc["noise_c"], delta_t_c=sc["delta_t_c"], sensor=sen,
                          model=sensor_model(sen), seed=1000 + case["index"], repeats=repeats, jobs=1,
                          solver=solver)
    d = a.to_dict()
    extra = {"evaluations": d["computation"]["evaluations"], "ideal_interval": d["ideal"].get("interval")} \
        if evaluations else {}
    return {**case, "exact": {"value": d["value"], "low": d["interval"]["low"], "high": d["interval"]["high"],
                              "coverage": d["interval"]["coverage"], "ideal": d["ideal"]["value"], **extra},
            "repeats": repeats, "solver": solver, "load": os.getloadavg()[0], "wall_s": time.perf_counter() - t0,
            "cpu_s": time.process_time() - c0}


def phase_exact(args) -> None:
    from designkit.sensor import load_sensor
    from designkit.sweep.for_sensor import effusivity_span

    span = effusivity_span(material_set=args.materials)
    load_sensor(args.sensor)
    cases = draw_pairs(args.pairs, args.seed, span.e_max)
    path = Path(args.out) / "exact.jsonl"
    done = {json.loads(line)["index"] for line in path.read_text().splitlines()} if path.exists() else set()
    todo = [c for c in cases if c["index"] not in done]
    if args.first_within:  # the pairs a table over this effusivity range answers first
        lo, hi = args.first_within
        todo.sort(key=lambda c: (not (lo <= c["e1"] and c["e2"] <= hi), c["index"]))
    print(f"{len(todo)} of {len(cases)} pairs to compute by the exact route, {args.jobs} processes", flush=True)
    with ProcessPoolExecutor(args.jobs) as pool, path.open("a") as fh:
        futs = [pool.submit(exact_case, args.sensor, c, args.repeats, args.solver) for c in todo]
        for f in as_completed(futs):
            r = f.result()
            fh.write(json.dumps(r) + "\n")
            fh.flush()
            print(f"pair {r['index']}: {r['e1']:g} vs {r['e2']:g}: exact {r['exact']['value']} "
                  f"({r['cpu_s']:.1f} CPU s, {os.getloadavg()[0]:.1f} load)", flush=True)


def _sd(low, high) -> float | None:
    if low is None or high is None:
        return None
    return (high - low) / (2 * Z90)


def phase_table(args) -> None:
    from designkit._validation import InputError
    from designkit.query import min_contact
    from designkit.rig import model_start_s
    from designkit.sensor import load_sensor
    from designkit.tables.registry import table_for_sensor

    t0 = time.perf_counter()
    sen = load_sensor(args.sensor)
    table = table_for_sensor(sen)
    load_ms = 1e3 * (time.perf_counter() - t0)
    if table is None:
        sys.exit(f"no table registered for {args.sensor}: build it with 'designkit tables build --sensor ...'")
    start = model_start_s(sen) or 0.0

    def onset(v):  # the exact route's model time as the library gives it: from the rig's detected onset
        return None if v is None else max(v + start, 0.0)

    rows = [json.loads(line) for line in (Path(args.out) / "exact.jsonl").read_text().splitlines()]
    stated, hits, zs, cells, none, outside, times = [], 0, [], 0, 0, 0, []
    for r in sorted(rows, key=lambda r: r["index"]):
        c0 = time.perf_counter()  # the library's whole question: scene, route policy, the table's answer
        try:
            a = min_contact(r["e1"], r["e2"], sensor=args.sensor)
        except InputError as exc:  # outside the table's span: refused in one line
            times.append(time.perf_counter() - c0)
            r["table"] = {"refused": str(exc)}
            outside += 1
            continue
        times.append(time.perf_counter() - c0)
        d = a.to_dict()
        ex = r["exact_from_onset"] = {k: (onset(v) if k in ("value", "low", "high") else v)
                                      for k, v in r["exact"].items()}
        r["table"] = {"value": d["value"], "low": d["interval"]["low"], "high": d["interval"]["high"],
                      "coverage": d["interval"]["coverage"], "method": d["interval"]["method"]}
        if not all(d["in_grid"].values()):
            outside += 1
            continue
        last = float(table.axes["contact_s"][-1]) + start  # the table's last contact, from the onset
        if d["value"] is None:  # beyond the table's contact cap: a bound ("none up to LAST s"), held if the exact
            none += 1           # route finds none up to 10 s or one beyond LAST
            r["held"] = ex["value"] is None or ex["value"] > last
            r["reason"] = "bound: none up to the table's last contact"
            continue
        if ex["value"] is None:  # the table separates them, the exact route does not up to 10 s
            none += 1
            r["held"], r["reason"] = False, "the exact route finds none up to 10 s"
            continue
        if not d["interval"]["coverage"]:
            cells += 1
            r["held"] = d["interval"]["low"] <= ex["value"] <= d["interval"]["high"]
            continue
        held = d["interval"]["low"] <= ex["value"] <= d["interval"]["high"]
        r["held"] = held
        stated.append(r)
        hits += held
        st, se = _sd(d["interval"]["low"], d["interval"]["high"]), _sd(ex["low"], ex["high"])
        if st is not None and se is not None and st + se > 0:
            zs.append((d["value"] - ex["value"]) / math.hypot(st, se))
    n = len(stated)
    rel = [abs(r["table"]["value"] - r["exact_from_onset"]["value"]) / r["exact_from_onset"]["value"] for r in stated
           if r["exact_from_onset"]["value"]]
    summary = {
        "sensor": str(args.sensor), "table": table.name, "content_hash": table.header["content_hash"],
        "pairs": len(rows), "stated": n, "covered": hits, "coverage": hits / n if n else None,
        "grid_cells": cells, "grid_cells_held": sum(1 for r in rows if "held" in r and r not in stated and r["held"]),
        "no_answer": none, "no_answer_held": sum(1 for r in rows if r.get("reason") and r["held"]),
        "outside_span": outside, "missed": [{k: r.get(k) for k in ("index", "e1", "e2", "reason")}
                                             | {"table": r.get("table"), "exact": r.get("exact_from_onset")}
                                             for r in rows if r.get("held") is False],
        "z_sd": statistics.pstdev(zs) if len(zs) > 1 else None,
        "z_within_1.645": (sum(abs(z) <= Z90 for z in zs) / len(zs)) if zs else None,
        "median_rel_error": statistics.median(rel) if rel else None,
        "p95_rel_error": float(np.percentile(rel, 95)) if rel else None,
        "table_load_ms": load_ms, "question_ms_median": 1e3 * statistics.median(times),
        "build": table.header.get("stats", {}),
    }
    summary.update(projection(table, args.build_cpu_s))
    summary.update(fresh_shell(args))
    (Path(args.out) / "cases_scored.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    (Path(args.out) / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    print(json.dumps({k: v for k, v in summary.items() if k != "build"}, indent=1))


def projection(table, build_cpu_s: float | None, workers: int = 2) -> dict:
    """The build's time on an idle machine with ``workers`` cores, projected from its CPU seconds.

    The build ran on a shared machine, so its wall clock says little. Each chunk's cost is its wall time in its
    worker scaled to the build's CPU seconds (``build_cpu_s``: the process tree's, as ``tables build`` prints
    them); the chunks are handed to ``workers`` idle workers in the engine's order (longest contact first) and
    the projected wall time is when the last one finishes. Parallel efficiency: CPU over workers x that time.
    """
    run = (table.header.get("stats") or {}).get("run") or {}
    wall = np.asarray(run.get("chunk_wall_s") or [], dtype=np.float64)
    if not wall.size or not build_cpu_s:
        return {"projection": None}
    cost = wall * (build_cpu_s / wall.sum())  # [point, contact]
    order = [cost[p, k] for k in reversed(range(cost.shape[1])) for p in range(cost.shape[0])]
    free = [0.0] * workers
    for c in order:
        i = int(np.argmin(free))
        free[i] += c
    span = max(free)
    return {"projection": {"build_cpu_s": build_cpu_s, "build_wall_s_shared": run.get("elapsed_s"),
                           "workers": workers, "idle_wall_s": span,
                           "parallel_efficiency": build_cpu_s / (workers * span),
                           "longest_chunk_cpu_s": float(cost.max())}}


def fresh_shell(args, runs: int = 7) -> dict:
    """Wall time of the whole command from a fresh shell, and of ``import numpy`` in the same run (baseline)."""
    env = dict(os.environ)

    def wall(cmd) -> float:
        ts = []
        for _ in range(runs):
            t0 = time.perf_counter()
            subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            ts.append(time.perf_counter() - t0)
        return statistics.median(ts)

    py = sys.executable
    question = [py, "-m", "designkit", "min-contact", "--sensor", str(args.sensor), "--m1", "wood", "--m2", "glass"]
    wall(question)  # the first run writes the byte code
    out = {"fresh_shell_question_s": wall(question), "fresh_shell_import_numpy_s": wall([py, "-c", "import numpy"]),
           "fresh_shell_paper_question_s": wall([py, "-m", "designkit", "min-contact", "--m1", "wood", "--m2",
                                                 "glass"]),
           "load_average": os.getloadavg()[0]}
    out["question_over_numpy"] = out["fresh_shell_question_s"] / out["fresh_shell_import_numpy_s"]
    return out


def f1_draws(sensor_file: str, case: dict, contacts, calls: int, reps: int, out: Path) -> None:
    """Fresh-seed SVM F1 of the exact route's scene for one pair at fixed contacts (model time) [s]: ``calls``
    rounds of ``reps`` seeds at every contact, appended to ``out`` per (round, contact) with their CPU time.
    Seeds ``[900000 + index, round, contact, r]``: neither route's (the exact route's are ``[1000 + index, r, k]``,
    the table's ``[0, ...]``)."""
    from designkit.models import sensor_model
    from designkit.objects import ordered_pair
    from designkit.query.exact import _Run
    from designkit.query.inputs import pair_question
    from designkit.recognition.batched_svm import batched_cv_f1
    from designkit.recognition.features import feature_matrix
    from designkit.sensor import load_sensor
    from designkit.simulation import simulate_class

    sen = load_sensor(sensor_file)
    sc = _scene(sen)
    run = _Run.make(sensor=sen, model=sensor_model(sen), threshold=0.9, width=80.0, trials=100, folds=3, seed=0,
                    repeats=reps, z=2.0, jobs=1, n_mc=1000, solver="batched")
    low, high = ordered_pair(*pair_question(case["e1"], case["e2"], None, None, objects=None, width=80.0,
                                            diffusivity_m2_s=None, model=run.model).classes)
    for call in range(calls):
        for ci, c in enumerate(contacts):
            scene = run.scene(c, sc["noise_c"], sc["delta_t_c"])
            t = time.process_time()
            lo, hi, seeds = [], [], []
            for r in range(reps):
                base = [900000 + case["index"], call, ci, r]
                lo.append(feature_matrix(simulate_class(low, 100, sen, scene, base + [0], run.model).temperature_c,
                                         sen.sample_rate_hz))
                hi.append(feature_matrix(simulate_class(high, 100, sen, scene, base + [1], run.model).temperature_c,
                                         sen.sample_rate_hz))
                seeds.append(base + [2])
            res = batched_cv_f1(lo, hi, seeds=seeds, folds=3)
            with out.open("a") as fh:
                fh.write(json.dumps({"index": case["index"], "e1": case["e1"], "e2": case["e2"],
                                     "contact_model_s": round(float(c), 6), "round": call,
                                     "f1": [float(x) for x in res.f1],
                                     "fold_se": [float(x) for x in res.standard_error],
                                     "cpu_s": time.process_time() - t}) + "\n")


def true_crossing(contacts, draws, phi: float = 0.9, boot: int = 400, seed: int = 1) -> tuple[float, float]:
    """Where the mean F1 crosses ``phi``: a quadratic in ``log(contact)`` through the contacts' mean F1, solved on a
    fine grid (the first point at or above ``phi``), and its standard error by resampling each contact's seeds
    (``draws``: per contact the seeds' F1). NaN where the fit does not cross inside the contacts."""
    u = np.log(np.asarray(contacts, dtype=np.float64))
    grid = np.linspace(u.min(), u.max(), 4001)

    def cross(means):
        f = np.polyval(np.polyfit(u, means, 2), grid)
        k = np.flatnonzero(f >= phi)
        return float(np.exp(grid[k[0]])) if k.size and k[0] > 0 else math.nan

    rng = np.random.default_rng(seed)
    value = cross(np.array([d.mean() for d in draws]))
    b = np.array([cross(np.array([rng.choice(d, d.size).mean() for d in draws])) for _ in range(boot)])
    return value, float(np.nanstd(b))


def phase_truth(args) -> None:
    """The true crossing of chosen pairs (``--indices``) at this engine: fresh-seed F1 at ``--points`` contacts
    spanning both routes' answers (0.85 x the earlier to 1.12 x the later, model time), ``--rounds`` x 8 seeds
    each (resumable: appends to truth.jsonl), a smooth fit's crossing with its standard error; beside it each
    route's answer (from the detected onset)."""
    from designkit.query import min_contact
    from designkit.rig import model_start_s
    from designkit.sensor import load_sensor

    start = model_start_s(load_sensor(args.sensor)) or 0.0
    rows = {r["index"]: r for r in map(json.loads, (Path(args.out) / "exact.jsonl").read_text().splitlines())}
    path = Path(args.out) / "truth.jsonl"
    for i in (int(x) for x in args.indices.split(",")):
        r = rows[i]
        table = min_contact(r["e1"], r["e2"], sensor=args.sensor).value - start  # model time
        lo, hi = sorted((r["exact"]["value"], table))
        contacts = np.round(np.geomspace(0.85 * lo, 1.12 * hi, args.points), 3)
        have = [json.loads(x) for x in path.read_text().splitlines()] if path.exists() else []
        done = len({x["round"] for x in have if x["index"] == i})
        if done < args.rounds:
            f1_draws(args.sensor, r, contacts, args.rounds - done, 8, path)
    by = {}
    for x in map(json.loads, path.read_text().splitlines()):
        by.setdefault(x["index"], {}).setdefault(x["contact_model_s"], []).extend(x["f1"])
    for i, cs in sorted(by.items()):
        if i not in rows:  # its exact answer not computed yet
            continue
        r = rows[i]
        xs = sorted(cs)
        value, se = true_crossing(xs, [np.array(cs[c]) for c in xs])
        t = min_contact(r["e1"], r["e2"], sensor=args.sensor)
        print(f"pair {i} ({r['e1']:g} vs {r['e2']:g}): true {value + start:.3f} s +- {se:.3f} (from the onset; "
              f"{min(len(v) for v in cs.values())} seeds per contact); exact {r['exact']['value'] + start:.3f} s "
              f"({math.log((r['exact']['value']) / value):+.1%}); table {t.value:.3f} s [{t.interval[0]:.3f}, "
              f"{t.interval[1]:.3f}] ({math.log((t.value - start) / value):+.1%}); F1 "
              + " ".join(f"{c + start:.3f}:{np.mean(cs[c]):.3f}" for c in xs), flush=True)


def refit(row: dict, curvature: bool = True, pooled: bool = True) -> tuple:
    """The exact route's crossing estimate replayed on its own evaluations (``row["exact"]["evaluations"]``, model
    time): ``(value, low, high)`` with the route's floor at the ideal observer. The route's design depends only on
    the values it has seen, so the replay asks the same contacts and, with ``curvature=True`` and ``pooled=True``
    (this tree's fit), returns the route's own answer. ``curvature=False``: the straight-line fit of the route
    before issue 34's curvature term; ``pooled=False``: each evaluation's own error (the larger of its seeds' own
    errors and their spread, over sqrt(n), the normal quantile: the error model before the pooled one,
    :func:`designkit.query.crossing.pooled_seed_scale`), possible where the evaluations hold their seeds' draws
    (``per_seed``; rows computed before it hold the old error only, used as it is)."""
    from designkit.query.answer import ideal_floor
    from designkit.query.crossing import SeedDraws, estimate_crossing

    ex = row["exact"]

    def reading(e):
        if "per_seed" not in e:
            return e["svm_f1"], e["standard_error"]
        d = SeedDraws([r["f1"] for r in e["per_seed"]], [r["standard_error"] for r in e["per_seed"]])
        return d if pooled else (d.mean, d.standard_error())

    seen = {e["contact_s"]: reading(e) for e in ex["evaluations"]}
    iv = ex.get("ideal_interval")
    ideal = ex["ideal"]
    start = min(seen)  # the route searches from the ideal observer's contact (its first evaluation)
    e = estimate_crossing(lambda x: seen[x], start, max(seen), 0.9, curvature=curvature)
    floor = ideal_floor(ideal, None if iv is None else (iv["low"], iv["high"]))
    value = e.value if e.value is None or ideal is None else max(e.value, ideal)
    low = e.low if e.low is None or floor is None else max(e.low, floor)
    return value, low, e.high


def phase_bias(args) -> None:
    """--exact against the truth of ``--indices`` (``--truth``: fresh-seed F1 draws, :func:`phase_truth`), before
    and after issue 34's fix in one run. Before: the route at main as stored (``--before``, exact.jsonl of
    ``--phase exact``, the same seeds). Now: the route runs once per pair with this tree (appended to
    OUT/exact_evaluations.jsonl, resumable); beside it, its own evaluations fitted by the straight line
    (:func:`refit`, ``curvature=False``: the fix's share, apart from the Monte Carlo ideal bound's own change, which
    moves where the search starts). Errors are of the time from the rig's detected onset, as the answer states it.
    Prints per pair the truth, each estimate with its 90 % interval, its error and whether it holds the truth;
    then the median error, its range and the count held."""
    from designkit.rig import model_start_s
    from designkit.sensor import load_sensor
    from designkit.sweep.for_sensor import effusivity_span

    start = model_start_s(load_sensor(args.sensor)) or 0.0
    pairs = {r["index"]: r for r in draw_pairs(max(int(i) for i in args.indices.split(",")) + 1, args.seed,
                                              effusivity_span(material_set=args.materials).e_max)}
    path = Path(args.out) / "exact_evaluations.jsonl"
    rows = {r["index"]: r for r in map(json.loads, path.read_text().splitlines())} if path.exists() else {}
    before = {r["index"]: r for r in map(json.loads, Path(args.before).read_text().splitlines())}
    by: dict = {}
    for x in map(json.loads, Path(args.truth).read_text().splitlines()):
        by.setdefault(x["index"], {}).setdefault(x["contact_model_s"], []).extend(x["f1"])
    labels = {"main": "main's route (stored)", "own": "each evaluation's own error, these evaluations",
              "now": "now (pooled error)"}
    out: dict = {k: [] for k in labels}
    print(f"times from the onset [s]; pair e1 e2 | truth | " + " | ".join(labels.values()))
    for i in (int(x) for x in args.indices.split(",")):
        if i not in rows:
            r = exact_case(args.sensor, pairs[i], args.repeats, args.solver, evaluations=True)
            with path.open("a") as fh:
                fh.write(json.dumps(r) + "\n")
            rows[i] = r
        r = rows[i]
        cs = sorted(by[i])
        truth, se = true_crossing(cs, [np.array(by[i][c]) for c in cs])
        b = before[i]["exact"]
        est = {"main": (b["value"], b["low"], b["high"]), "own": refit(r, pooled=False), "now": refit(r)}
        if not math.isclose(est["now"][0], r["exact"]["value"], rel_tol=1e-9):
            sys.exit(f"pair {i}: the replay ({est['now'][0]}) is not the route's own answer ({r['exact']['value']})")
        line = f"{i:3d} {r['e1']:<7g} {r['e2']:<7g} | {truth + start:.3f} +- {se:.3f} "
        for k, (v, lo, hi) in est.items():
            err, held = math.log((v + start) / (truth + start)), lo <= truth <= hi
            out[k].append((err, held, (hi - lo) / (v + start)))
            line += f"| {v + start:.3f} [{lo + start:.3f}, {hi + start:.3f}] {err:+6.1%} {'held  ' if held else 'MISSED'} "
        print(line, flush=True)
    for k, label in labels.items():
        e = [x for x, _, _ in out[k]]
        w = statistics.median(x for _, _, x in out[k])
        print(f"{label}: median error {statistics.median(e):+.1%} (range {min(e):+.1%} to {max(e):+.1%}), "
              f"median relative width {w:.1%}, "
              f"{sum(h for _, h, _ in out[k])} of {len(e)} intervals hold the truth")


def phase_profile(args) -> None:
    """Where a build's CPU goes: one block of references (``--rows``) at each tabulated contact, run as a sweep worker
    runs it; per contact the fits per reference, CPU per fit, and the shares of simulation + features, libsvm's SMO
    (classes that overlap) and the rest of the solver. A projection of the whole build is printed beside it."""
    import dataclasses

    from designkit.recognition import batched_svm
    from designkit.sweep import scorer as scorer_mod
    from designkit.sweep.chunk import run_chunk
    from designkit.sweep.for_sensor import effusivity_span, sensor_sweep_config

    cfg = sensor_sweep_config(args.sensor, span=effusivity_span(material_set=args.materials))
    blocks = max(1, cfg.intervals // args.rows)
    cfg = dataclasses.replace(cfg, blocks=blocks)
    T: dict[str, float] = {}

    def timed(name, fn):
        def wrapper(*a, **k):
            t = time.process_time()
            try:
                return fn(*a, **k)
            finally:
                T[name] = T.get(name, 0.0) + time.process_time() - t
        return wrapper

    batched_svm._libsvm_smo = timed("libsvm", batched_svm._libsvm_smo)
    scorer_mod.PairScorer.features = timed("features", scorer_mod.PairScorer.features)
    block = blocks // 2 if args.block is None else args.block
    total = 0.0
    print(f"{cfg.intervals} intervals, sigma/dT {cfg.noise_ratio[0]:.5f}, contacts (model) "
          f"{[round(c, 3) for c in cfg.contact_s]}, max_repeats {cfg.max_repeats}; block {block} of {blocks}; "
          f"load {os.getloadavg()[0]:.1f}", flush=True)
    for k in ([int(x) for x in args.contacts.split(",")] if args.contacts else range(len(cfg.contact_s))):
        T.clear()
        t0 = time.process_time()
        r = run_chunk(cfg, (0,), block, k)
        cpu = time.process_time() - t0
        total += cpu * cfg.intervals / r.rows.size
        print(f"contact {cfg.contact_s[k]:.3f} s (model): {r.rows.size} refs, {r.fits / r.rows.size:.1f} fits/ref, "
              f"{cpu / max(r.fits, 1):.3f} CPU s/fit, {cpu / r.rows.size:.2f} CPU s/ref; libsvm "
              f"{T.get('libsvm', 0) / cpu:.0%}, simulation+features {T.get('features', 0) / cpu:.0%}; "
              f"J - i {np.median(r.J - r.rows):.0f} (median); load {os.getloadavg()[0]:.1f}", flush=True)
    print(f"projected build CPU for the contacts profiled: {total:.0f} s ({total / 2 / 60:.1f} min on 2 idle cores "
          "at this CPU per reference)", flush=True)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sensor", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--phase", choices=("exact", "table", "truth", "bias", "profile"), required=True)
    p.add_argument("--indices", default="0,1,2,17", help="truth, bias: the pairs (indices of exact.jsonl)")
    p.add_argument("--truth", default="benchmarks/results/sensor_table_truth.jsonl",
                   help="bias: the truth's F1 draws (truth.jsonl of --phase truth)")
    p.add_argument("--before", default="benchmarks/results/sensor_table_exact.jsonl",
                   help="bias: the exact route's answers at main (exact.jsonl of --phase exact)")
    p.add_argument("--points", type=int, default=7, help="truth: contacts per pair")
    p.add_argument("--rounds", type=int, default=4, help="truth: rounds of 8 fresh seeds at every contact")
    p.add_argument("--rows", type=int, default=20, help="profile: references per profiled block")
    p.add_argument("--first-within", type=float, nargs=2, default=None, metavar=("LO", "HI"),
                   help="exact: compute the pairs inside this effusivity range first")
    p.add_argument("--block", type=int, default=None, help="profile: which block of --rows references (default: the "
                   "middle one)")
    p.add_argument("--contacts", default=None, help="profile: contact indices, comma-separated (default all)")
    p.add_argument("--materials", default="paper12")
    p.add_argument("--pairs", type=int, default=60)
    p.add_argument("--seed", type=int, default=34)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--repeats", type=int, default=4, help="the exact route's seeds of 100 trials per class")
    p.add_argument("--solver", default="batched", help="the exact route's SVM solver (batched: the same classifier "
                   "as sklearn's, all seeds at once)")
    p.add_argument("--build-cpu-s", type=float, default=None, help="CPU seconds the build printed (projection)")
    args = p.parse_args()
    Path(args.out).mkdir(parents=True, exist_ok=True)
    {"exact": phase_exact, "table": phase_table, "truth": phase_truth, "bias": phase_bias,
     "profile": phase_profile}[args.phase](args)


if __name__ == "__main__":
    main()
