"""Table queries: fresh-shell wall time, what they import, in-process time, and memory (issue 3 targets).

Run from the repository root::

    /work/venv/bin/python benchmarks/bench_query.py             # 15 runs of each command
    /work/venv/bin/python benchmarks/bench_query.py --runs 30 --json out.json

Measured in one run, on whatever machine runs it:

1. ``designkit min-contact --e1 35000 --e2 20000`` as a user types it, started
   from a fresh shell (the console script, a new process each time): wall time
   over ``--runs`` runs (median, best, worst), against two baselines measured
   in the same run and interleaved with it: ``python -c pass`` (the
   interpreter alone) and ``python -c "import numpy"``. Target: < 0.5 s.
2. Proof that the query path does not import scikit-learn (nor matplotlib,
   dask, joblib): the same command under ``PYTHONPROFILEIMPORTTIME=1``, whose
   import log lists every module the process imported; the heaviest imports
   are printed.
3. In-process query time with the tables already loaded (the library call a
   program would make in a loop): median over many calls. Target: < 1 ms.
4. Peak resident memory of the query process (its own ``ru_maxrss``).
   Target: < 150 MB.

The SVM table ``svm-paper`` is the default table of ``min-contact``; while it
is not built the script queries ``ideal-paper`` (``--table ideal-paper``) and
says so.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import sys
import timeit
from pathlib import Path

from designkit_lab.accuracy import process_cost

PAIR = ["--e1", "35000", "--e2", "20000"]
NUMPY = "python -c 'import numpy'"


def console_script() -> list[str]:
    """The installed ``designkit`` console script next to this interpreter (else on PATH)."""
    here = Path(sys.executable).with_name("designkit")
    if here.exists():
        return [str(here)]
    found = shutil.which("designkit")
    if found:
        return [found]
    raise SystemExit("the designkit console script is not installed (pip install -e .)")


def svm_table_available() -> bool:
    from designkit.tables.store import list_tables

    return "svm-paper" in list_tables()


def summary(walls: list[float]) -> dict[str, float]:
    return {"median_s": statistics.median(walls), "best_s": min(walls), "worst_s": max(walls),
            "runs": len(walls)}


def fresh_shell(runs: int, table_args: list[str]) -> dict:
    exe = sys.executable
    commands = {
        "python -c pass": [exe, "-c", "pass"],
        NUMPY: [exe, "-c", "import numpy"],
        "designkit min-contact": console_script() + ["min-contact", *PAIR, *table_args],
        "designkit min-contact --json": console_script() + ["min-contact", *PAIR, *table_args, "--json"],
    }
    walls = {k: [] for k in commands}
    rss = {k: 0.0 for k in commands}
    outputs = {}
    for _ in range(runs):  # interleaved, so that machine load hits all commands alike
        for name, cmd in commands.items():
            r = process_cost(cmd)
            if r.returncode != 0:
                raise SystemExit(f"{name} failed ({r.returncode}): {r.stderr.strip()}")
            walls[name].append(r.wall_s)
            rss[name] = max(rss[name], r.max_rss_mb)
            outputs[name] = r.stdout
    return {name: {**summary(w), "max_rss_mb": rss[name]} for name, w in walls.items()} | {"_outputs": outputs}


def imports(table_args: list[str]) -> dict:
    r = process_cost(console_script() + ["min-contact", *PAIR, *table_args],
                     env={"PYTHONPROFILEIMPORTTIME": "1"})
    mods = []
    for line in r.stderr.splitlines():
        if not line.startswith("import time:") or "|" not in line:
            continue
        parts = [p.strip() for p in line[len("import time:"):].split("|")]
        try:
            self_us, cum_us = int(parts[0]), int(parts[1])
        except ValueError:
            continue  # the header line
        mods.append((parts[2].strip(), self_us, cum_us))
    names = {m[0] for m in mods}
    top = sorted((m for m in mods if not m[0].startswith(" ")), key=lambda m: -m[2])[:8]
    heavy = {pkg: any(n == pkg or n.startswith(pkg + ".") for n in names)
             for pkg in ("sklearn", "matplotlib", "dask", "joblib", "scipy", "numpy", "rich")}
    return {"modules_imported": len(names), "imported": heavy, "top_cumulative_us": top}


def in_process(table: str, ideal_table: str, number: int = 200) -> dict:
    from designkit.query import table as query
    from designkit.tables.store import load_table

    tab = load_table(table)
    itab = load_table(ideal_table)
    ans = query.min_contact(35000, 20000, table=tab, ideal_table=itab)  # warm caches
    timer = timeit.Timer(lambda: query.min_contact(35000, 20000, table=tab, ideal_table=itab))
    per_call = [t / number for t in timer.repeat(repeat=7, number=number)]
    load = min(timeit.Timer(lambda: load_table(table)).repeat(repeat=5, number=1))
    return {"median_s": statistics.median(per_call), "best_s": min(per_call), "table_load_s": load,
            "answer_s": ans.value, "interval_s": list(ans.interval), "ideal_s": ans.ideal, "table": tab.name}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=15, help="fresh-shell runs of each command")
    p.add_argument("--json", type=Path, default=None, help="also write the numbers to this JSON file")
    args = p.parse_args(argv)

    svm = svm_table_available()
    table_args = [] if svm else ["--table", "ideal-paper"]
    table = "svm-paper" if svm else "ideal-paper"
    if not svm:
        print("NOTE: tables/svm-paper is not built yet: querying ideal-paper (--table ideal-paper); the SVM table "
              "is loaded the same way and is smaller, so expect the same or shorter times.\n")

    fs = fresh_shell(args.runs, table_args)
    outputs = fs.pop("_outputs")
    base0 = fs["python -c pass"]["median_s"]
    base1 = fs[NUMPY]["median_s"]
    print(f"### 1. From a fresh shell ({args.runs} runs each, interleaved; table {table})\n")
    print("| command | median [s] | best [s] | worst [s] | median / python | median / import numpy | "
          "peak RSS [MB] |")
    print("|---|---|---|---|---|---|---|")
    for name, s in fs.items():
        print(f"| `{name}` | {s['median_s']:.3f} | {s['best_s']:.3f} | {s['worst_s']:.3f} | "
              f"{s['median_s'] / base0:.1f} | {s['median_s'] / base1:.2f} | {s['max_rss_mb']:.0f} |")
    q = fs["designkit min-contact"]
    print(f"\nTarget < 0.5 s: median {q['median_s']:.3f} s "
          f"({'met' if q['median_s'] < 0.5 else 'NOT met'}); the query adds "
          f"{q['median_s'] - base1:.3f} s to importing numpy.")
    print("\nWhat it printed:\n")
    print("    " + outputs["designkit min-contact"].strip().replace("\n", "\n    "))

    imp = imports(table_args)
    print("\n### 2. Imports on the query path (PYTHONPROFILEIMPORTTIME=1)\n")
    print(f"{imp['modules_imported']} modules imported. " +
          ", ".join(f"{k}: {'IMPORTED' if v else 'not imported'}" for k, v in imp["imported"].items()))
    print("\nHeaviest top-level imports (cumulative):\n")
    print("| module | cumulative [ms] |\n|---|---|")
    for name, _, cum in imp["top_cumulative_us"]:
        print(f"| {name.strip()} | {cum / 1e3:.1f} |")
    if imp["imported"]["sklearn"]:
        print("\nFAILED: scikit-learn is imported on the table-query path")

    ip = in_process(table, "ideal-paper")
    print("\n### 3. In-process query, tables loaded\n")
    print(f"`query.min_contact(35000, 20000)` on {ip['table']}: median {ip['median_s'] * 1e3:.3f} ms per call "
          f"(best {ip['best_s'] * 1e3:.3f} ms); target < 1 ms: {'met' if ip['median_s'] < 1e-3 else 'NOT met'}. "
          f"Loading the table once: {ip['table_load_s'] * 1e3:.1f} ms. Answer {ip['answer_s']} s "
          f"(interval {ip['interval_s']}, ideal observer {ip['ideal_s']} s).")

    print("\n### 4. Memory\n")
    print(f"Peak resident memory of the query process: {q['max_rss_mb']:.0f} MB (target < 150 MB: "
          f"{'met' if q['max_rss_mb'] < 150 else 'NOT met'}); `python -c 'import numpy'` alone: "
          f"{fs[NUMPY]['max_rss_mb']:.0f} MB.")

    if args.json is not None:
        from designkit._io import atomic_write_text

        atomic_write_text(args.json, json.dumps({"table": table, "fresh_shell": fs, "imports": imp,
                                                 "in_process": ip}, indent=1, default=str) + "\n")
        print(f"\nwrote {args.json}", file=sys.stderr)


if __name__ == "__main__":
    main()
