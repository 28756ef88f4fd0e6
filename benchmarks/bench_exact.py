"""``--exact`` min-contact for one pair: wall time, and whether it agrees with the table (issue 3 target).

Run from the repository root::

    /work/venv/bin/python benchmarks/bench_exact.py              # 3 runs, all cores (the CLI default)
    /work/venv/bin/python benchmarks/bench_exact.py --jobs 1     # one process
    /work/venv/bin/python benchmarks/bench_exact.py --e1 5000 --e2 6000 --noise 0.02

Measured in one run:

1. ``designkit min-contact --e1 35000 --e2 20000 --exact --json`` from a fresh
   shell, as a user runs it (``--jobs`` processes; the CLI default is all
   cores), ``--runs`` times: wall time against the table query of the same
   pair in the same run. Target: < 10 s on 2 cores.
2. The exact answer against the table's: is the exact contact time inside the
   table's Monte Carlo interval, is the table's inside the exact one, and how
   far apart they are (the table's interpolation error for this pair). With
   no SVM table yet, only the ideal-observer bounds are compared (the table
   ``ideal-paper`` against the exact closed form) and the script says so.
3. Where the time goes: the SVM evaluations (contact times tried, seeds,
   F1 with standard errors) from the exact answer's own record.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

from designkit_lab.accuracy import process_cost

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_query import console_script, svm_table_available  # noqa: E402


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--e1", type=float, default=35000.0)
    p.add_argument("--e2", type=float, default=20000.0)
    p.add_argument("--noise", type=float, default=0.05)
    p.add_argument("--delta-t", type=float, default=10.0)
    p.add_argument("--jobs", type=int, default=-1, help="worker processes for --exact (-1: all cores)")
    p.add_argument("--repeats", type=int, default=4, help="seeds per evaluation (the CLI default is 4)")
    p.add_argument("--runs", type=int, default=3, help="runs of the exact command")
    p.add_argument("--json", type=Path, default=None, help="also write the numbers to this JSON file")
    args = p.parse_args(argv)

    svm = svm_table_available()
    table = "svm-paper" if svm else "ideal-paper"
    pair = ["--e1", f"{args.e1:g}", "--e2", f"{args.e2:g}", "--noise", f"{args.noise:g}",
            "--delta-t", f"{args.delta_t:g}"]
    exe = console_script()
    tab_cmd = exe + ["min-contact", *pair, "--table", table, "--json"]
    ex_cmd = exe + ["min-contact", *pair, "--exact", "--jobs", str(args.jobs), "--repeats", str(args.repeats),
                    "--json"]
    t_tab, t_ex, answers = [], [], []
    tab_ans = None
    for _ in range(args.runs):
        r = process_cost(tab_cmd)
        if r.returncode:
            raise SystemExit(r.stderr)
        t_tab.append(r.wall_s)
        tab_ans = json.loads(r.stdout)
        r = process_cost(ex_cmd, timeout=900)
        if r.returncode:
            raise SystemExit(r.stderr)
        t_ex.append(r.wall_s)
        answers.append(json.loads(r.stdout))
    ex = answers[-1]

    def flat(d):  # the answer schema's min-contact figures
        return {"value": d["value"], "interval": [d["interval"]["low"], d["interval"]["high"]],
                "ideal": d["ideal"]["value"]}

    tab_f, ex_f = flat(tab_ans), flat(ex)
    med_ex, med_tab = statistics.median(t_ex), statistics.median(t_tab)
    print(f"### --exact min-contact, {args.e1:g} vs {args.e2:g}, noise {args.noise:g} °C, dT {args.delta_t:g} °C\n")
    if not svm:
        print("NOTE: tables/svm-paper is not built yet; the table side is ideal-paper, so only the ideal-observer "
              "answers can be compared with the table.\n")
    print("| command | runs | median [s] | best [s] | worst [s] |\n|---|---|---|---|---|")
    print(f"| `designkit min-contact ... --table {table}` | {args.runs} | {med_tab:.3f} | {min(t_tab):.3f} | "
          f"{max(t_tab):.3f} |")
    print(f"| `designkit min-contact ... --exact --jobs {args.jobs} --repeats {args.repeats}` | {args.runs} | "
          f"{med_ex:.2f} | {min(t_ex):.2f} | {max(t_ex):.2f} |")
    print(f"\nTarget < 10 s: median {med_ex:.2f} s ({'met' if med_ex < 10 else 'NOT met'}); "
          f"exact / table = {med_ex / med_tab:.0f}x. Compute inside the exact run: "
          f"{ex['computation'].get('wall_s', float('nan')):.2f} s (the rest is process start-up and imports).")

    def inside(v, iv):
        lo, hi = iv
        return v is not None and (lo is None or v >= lo - 1e-9) and (hi is None or v <= hi + 1e-9)

    print("\n| answer | contact time [s] | interval [s] | ideal observer [s] |\n|---|---|---|---|")
    print(f"| table {table} | {tab_f['value']} | {tab_f['interval']} | {tab_f['ideal']} |")
    print(f"| --exact | {ex_f['value']} | {ex_f['interval']} | {ex_f['ideal']} |")
    facts = {}
    if svm and tab_f["value"] is not None and ex_f["value"] is not None:
        facts = {"exact_in_table_interval": inside(ex_f["value"], tab_f["interval"]),
                 "table_in_exact_interval": inside(tab_f["value"], ex_f["interval"]),
                 "difference_s": tab_f["value"] - ex_f["value"]}
        print(f"\nexact inside the table's interval: {facts['exact_in_table_interval']}; table inside the exact "
              f"interval: {facts['table_in_exact_interval']}; table - exact = {facts['difference_s']:+.3f} s "
              f"(the table's interpolation plus Monte Carlo error for this pair).")
    ti, ei = tab_f["ideal"], ex_f["ideal"]
    if ti is not None and ei is not None:
        facts["ideal_difference_s"] = ti - ei
        print(f"Ideal observer: table {ti:.3f} s vs exact closed form {ei:.3f} s ({ti - ei:+.3f} s: the table's "
              f"interpolation error alone, no Monte Carlo).")
    print("\nSVM evaluations of the exact run (contact time, mean F1 over seeds, standard error):\n")
    for ev in ex["computation"].get("evaluations", []):
        print(f"    {ev['contact_s']:7.3f} s   F1 {ev['svm_f1']:.3f} ± {ev['standard_error']:.3f}")
    print(f"\n{len(ex['computation'].get('evaluations', []))} contact times x {args.repeats} seeds = "
          f"{len(ex['computation'].get('evaluations', [])) * args.repeats} SVM fits (3-fold cross-validation each).")
    if args.json is not None:
        from designkit._io import atomic_write_text

        atomic_write_text(args.json, json.dumps({"table": table, "table_wall_s": t_tab, "exact_wall_s": t_ex,
                                                 "table_answer": tab_ans, "exact_answer": ex, **facts},
                                                indent=1) + "\n")


if __name__ == "__main__":
    main()
