"""Peak resident memory of a sweep and of a table query (issue 3 targets: < 2 GB and < 150 MB).

Run from the repository root::

    /work/venv/bin/python benchmarks/bench_memory.py            # about 5-10 min on 1 core
    /work/venv/bin/python benchmarks/bench_memory.py --quick    # smaller grids

Every figure is the peak resident set (``ru_maxrss`` from ``wait4``) of one
``designkit`` process started as a user starts it, with baselines measured in
the same run (``python -c "import numpy"``, ``designkit --help``). Sweeps run
with ``--jobs 1`` (in-process), so the figure is one worker's peak; a sweep
with ``--jobs J`` holds about J such workers at once plus its parent.

What drives a sweep's memory, and how it is exercised cheaply:

* SVM fidelity: each chunk caches the feature matrix of every effusivity
  interval it touches (trials x 2 x samples floats, 3.2 MB per interval at
  10 s, 200 Hz, 100 trials). A noise-free scene (``--noise-ratio 0``) makes
  every neighbour distinguishable, so the search is one fit per reference
  and cheap, while every interval of the chunk is still touched: the memory
  of a long-contact chunk at a fraction of its usual time. Swept: the number
  of intervals in one chunk and the contact time; the fitted slope gives MB
  per cached interval, and the prediction for the shipped svm-paper grid.
* Ideal fidelity: the closed form needs O(n) memory per chunk, but turning
  the staircase into delta(e) (``engine.delta_from_staircase``) builds n x n
  arrays. Swept: intervals up to 8000; the fitted exponent tells where 2 GB is
  reached.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from designkit_lab.accuracy import fit_exponent, process_cost

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_query import console_script, svm_table_available  # noqa: E402


def sweep_rss(args: list[str], tmp: Path, tag: str):
    cmd = console_script() + ["sweep", "--name", tag, "--workdir", str(tmp / tag), "--out", str(tmp / f"{tag}.npz"),
                              "--jobs", "1", "--json", *args]
    r = process_cost(cmd, timeout=3600)
    if r.returncode:
        raise SystemExit(f"sweep {tag} failed: {r.stderr.strip()}")
    info = json.loads(r.stdout)
    return r.max_rss_mb, r.wall_s, info["svm_fits"]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="smaller grids")
    p.add_argument("--json", type=Path, default=None, help="also write the numbers to this JSON file")
    args = p.parse_args(argv)
    exe = console_script()
    out: dict = {}

    base = {"python -c 'import numpy'": process_cost([sys.executable, "-c", "import numpy"]).max_rss_mb,
            "designkit --help": process_cost(exe + ["--help"]).max_rss_mb}
    table_args = [] if svm_table_available() else ["--table", "ideal-paper"]
    q = process_cost(exe + ["min-contact", "--e1", "35000", "--e2", "20000", *table_args])
    base["designkit min-contact --e1 35000 --e2 20000" + (" --table ideal-paper" if table_args else "")] = q.max_rss_mb
    out["baselines_mb"] = base
    print("### Table query\n")
    print("| process | peak RSS [MB] |\n|---|---|")
    for k, v in base.items():
        print(f"| `{k}` | {v:.0f} |")
    print(f"\nTable query: {q.max_rss_mb:.0f} MB (target < 150 MB: {'met' if q.max_rss_mb < 150 else 'NOT met'}).")

    with tempfile.TemporaryDirectory(prefix="dk-bench-memory-") as td:
        tmp = Path(td)
        # ---- SVM: intervals in one chunk, at 10 s
        contact = 10.0
        ns = [50, 100, 200] if args.quick else [125, 250, 500]
        svm_rows = []
        for n in ns:
            print(f"  svm sweep, {n} intervals, contact {contact:g} s ...", file=sys.stderr, flush=True)
            rss, wall, fits = sweep_rss(["--fidelity", "svm", "--intervals", str(n), "--trials", "100",
                                         "--noise-ratio", "0", "--contact", f"{contact:g}", "--blocks", "1"],
                                        tmp, f"svm-n{n}")
            svm_rows.append({"intervals": n, "contact_s": contact, "rss_mb": rss, "wall_s": wall, "fits": fits})
        # ---- SVM: contact time at fixed intervals
        n_fixed = ns[1]
        for c in ([2.0, 5.0] if args.quick else [2.0, 5.0, 20.0]):
            print(f"  svm sweep, {n_fixed} intervals, contact {c:g} s ...", file=sys.stderr, flush=True)
            rss, wall, fits = sweep_rss(["--fidelity", "svm", "--intervals", str(n_fixed), "--trials", "100",
                                         "--noise-ratio", "0", "--contact", f"{c:g}", "--blocks", "1"],
                                        tmp, f"svm-c{c:g}")
            svm_rows.append({"intervals": n_fixed, "contact_s": c, "rss_mb": rss, "wall_s": wall, "fits": fits})
        out["svm"] = svm_rows
        print("\n### SVM sweep, one chunk (noise-free scene: one fit per reference, every interval touched), "
              "100 trials, 200 Hz, --jobs 1\n")
        print("| intervals in the chunk | contact [s] | peak RSS [MB] | SVM fits | wall [s] |\n|---|---|---|---|---|")
        for r in sorted(svm_rows, key=lambda r: (r["contact_s"], r["intervals"])):
            print(f"| {r['intervals']} | {r['contact_s']:g} | {r['rss_mb']:.0f} | {r['fits']} | {r['wall_s']:.1f} |")
        at10 = [r for r in svm_rows if r["contact_s"] == contact]
        per_interval_theory = 100 * 2 * (int(contact * 200) + 1) * 8 / 2**20
        from designkit.sweep.scorer import FEATURE_CACHE_MB

        cap = FEATURE_CACHE_MB / per_interval_theory  # intervals the chunk's feature cache holds at most
        uncapped = [r for r in at10 if r["intervals"] * 1.2 <= cap]
        fit_rows = uncapped if len(uncapped) >= 2 else at10
        slope, icpt = np.polyfit([r["intervals"] for r in fit_rows], [r["rss_mb"] for r in fit_rows], 1)
        fixed = [r for r in svm_rows if r["intervals"] == n_fixed]
        c_exp = fit_exponent([r["contact_s"] for r in fixed], [r["rss_mb"] - icpt for r in fixed])
        out["svm_fit"] = {"mb_per_interval_at_10s": slope, "intercept_mb": icpt,
                          "theory_mb_per_interval": per_interval_theory, "contact_exponent_above_base": c_exp}
        print(f"\nAt {contact:g} s: {slope:.2f} MB per interval in the chunk (features of 100 trials x "
              f"{2 * (int(contact * 200) + 1)} values: {per_interval_theory:.2f} MB each), plus {icpt:.0f} MB. "
              f"Above that base, memory grows with the contact time as t^{c_exp:.2f}.")
        # prediction for the shipped grid: 500 intervals in 2 blocks -> 250 references per chunk, their partners too
        for rows_per_chunk, label in ((250, "svm-paper (blocks: 2)"), (500, "blocks: 1")):
            # ~20 % more intervals touched as partners / repeats, at most what the feature cache keeps
            pred = icpt + slope * min(rows_per_chunk * 1.2, cap)
            print(f"Predicted peak of one worker at 10 s for {label}: about {pred:.0f} MB "
                  f"({rows_per_chunk} references per chunk, +20 % partners and repeated seeds, the feature cache "
                  f"capped at {FEATURE_CACHE_MB} MiB = {cap:.0f} intervals); with --jobs 2: about {2 * pred:.0f} MB "
                  f"in the workers.")
            out.setdefault("prediction", {})[label] = pred
        # ---- ideal: n x n arrays in delta_from_staircase
        ns_i = [1000, 2000, 4000] if args.quick else [1000, 2000, 4000, 8000]
        ideal_rows = []
        for n in ns_i:
            print(f"  ideal sweep, {n} intervals ...", file=sys.stderr, flush=True)
            rss, wall, _ = sweep_rss(["--fidelity", "ideal", "--intervals", str(n), "--noise-ratio", "0.005",
                                      "--contact", "2"], tmp, f"ideal-n{n}")
            ideal_rows.append({"intervals": n, "rss_mb": rss, "wall_s": wall})
        out["ideal"] = ideal_rows
        base_help = base["designkit --help"]
        above = [r["rss_mb"] - base_help for r in ideal_rows]
        e_mem = fit_exponent([r["intervals"] for r in ideal_rows[1:]], above[1:])
        print("\n### Ideal sweep (one scene, one contact)\n")
        print("| intervals | peak RSS [MB] | above `designkit --help` [MB] | wall [s] |\n|---|---|---|---|")
        for r, a in zip(ideal_rows, above):
            print(f"| {r['intervals']} | {r['rss_mb']:.0f} | {a:.0f} | {r['wall_s']:.1f} |")
        last = ideal_rows[-1]
        # below an exponent of 0.2 the growth is within the noise of a process's resident set
        n2g = last["intervals"] * ((2048 - base_help) / max(above[-1], 1e-9)) ** (1 / e_mem) if e_mem > 0.2 else None
        out["ideal_fit"] = {"memory_exponent": e_mem, "intervals_at_2gb": n2g}
        print(f"\nMemory above the CLI's own grows as n^{e_mem:.2f}"
              + (f"; 2 GB is reached near {n2g:,.0f} intervals." if n2g else
                 ": flat within measurement noise (no extrapolation to 2 GB)."))
    if args.json is not None:
        from designkit._io import atomic_write_text

        atomic_write_text(args.json, json.dumps(out, indent=1, default=float) + "\n")


if __name__ == "__main__":
    main()
