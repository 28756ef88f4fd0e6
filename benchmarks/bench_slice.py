"""CPU per SVM fit of a fixed slice of svm-paper: another engine (a source tree) against this one, same run.

Run from the repository root::

    python benchmarks/bench_slice.py --old-tree ../main --out /tmp/slice
    python benchmarks/compare_svm_paper.py --workdir /tmp/slice/new     # the slice against the shipped table

The slice: ``tables/svm-paper.yaml`` at one sigma/dT (``--noise-ratio``, default 0.005), every contact
time, one block of references (``--blocks`` / ``--block``, default block 1 of 4: references 125-249).
Each chunk runs as a sweep worker runs it (``run_chunk``: one BLAS thread, the steady heap) in a fresh
process, alternately with the old tree's code and this tree's (``PYTHONPATH``), so that both see the
same load on a shared machine. Printed per contact time and in total: CPU seconds of the chunk
(``time.process_time``, imports not counted), SVM fits, CPU ms per fit, the worker's peak resident
memory (``ru_maxrss``, imports included), and the new/old ratio of CPU per fit. From the slice's CPU ratio
(fewer fits count too) and a full build's figures (``--full-wall-s``, ``--full-cpu-s``: the last from-scratch build of svm-paper,
benchmarks/results/svm-paper-rebuild.txt) it projects the full build's 2-core wall time. Each engine's
chunks are written to ``OUT/old`` and ``OUT/new`` as a sweep's working folder, for
``compare_svm_paper.py --workdir``. No figure here is asserted anywhere.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

_WORKER = r"""
import json, resource, sys, time
from pathlib import Path
import numpy as np
from designkit.sweep.config import SweepConfig
from designkit.sweep.chunk import run_chunk
a = json.loads(sys.argv[1])
cfg = SweepConfig.from_yaml(a["config"], noise_ratio=[a["noise"]], blocks=a["blocks"])
t = time.process_time()
res = run_chunk(cfg, (0,), a["block"], a["contact_index"])
cpu = time.process_time() - t
out = Path(a["out"])
(out / "chunks").mkdir(parents=True, exist_ok=True)
(out / "sweep.json").write_text(json.dumps({"config": cfg.to_dict()}))
np.savez(out / "chunks" / f"c{a['contact_index']:02d}.npz", **res.to_arrays())
print(json.dumps({"cpu_s": cpu, "fits": int(res.fits), "maxrss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def run_one(tree: str, args: argparse.Namespace, contact_index: int, out: Path) -> dict:
    env = {**os.environ, "PYTHONPATH": str(Path(tree).resolve()), "OPENBLAS_NUM_THREADS": "1",
           "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    payload = json.dumps({"config": str(Path(args.config).resolve()), "noise": args.noise_ratio,
                          "blocks": args.blocks, "block": args.block, "contact_index": contact_index,
                          "out": str(out)})
    r = subprocess.run([sys.executable, "-c", _WORKER, payload], capture_output=True, text=True, env=env,
                       cwd=str(Path(tree).resolve()))
    if r.returncode != 0:
        raise SystemExit(f"error: the chunk at contact index {contact_index} failed with {tree}: "
                         f"{r.stderr.strip().splitlines()[-1] if r.stderr.strip() else r.returncode}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--old-tree", required=True, help="source tree of the engine to compare with (e.g. ../main)")
    p.add_argument("--new-tree", default=".", help="source tree of the new engine (default: this one)")
    p.add_argument("--out", required=True, type=Path, help="folder for both engines' chunks")
    p.add_argument("--config", default="tables/svm-paper.yaml")
    p.add_argument("--noise-ratio", type=float, default=0.005)
    p.add_argument("--blocks", type=int, default=4)
    p.add_argument("--block", type=int, default=1)
    p.add_argument("--contacts", type=int, nargs="*", help="contact indices (default: all)")
    p.add_argument("--full-wall-s", type=float, default=820.0, help="the last full build's wall [s] (13 min 40 s)")
    p.add_argument("--full-cpu-s", type=float, default=1628.0, help="the last full build's CPU [s]")
    p.add_argument("--old-vs-full", type=float, default=1.0,
                   help="the old tree's CPU relative to the engine of that build (e.g. 0.904 for engine version 2 "
                        "against the version-1 build of 1,628 CPU s, engine-v2-slice.txt)")
    a = p.parse_args(argv)
    from designkit.sweep.config import SweepConfig

    contacts = SweepConfig.from_yaml(a.config).contact_s
    idx = a.contacts if a.contacts else list(range(len(contacts)))
    print(f"# bench_slice: {a.config}, sigma/dT {a.noise_ratio}, block {a.block} of {a.blocks}, contacts "
          f"{[contacts[k] for k in idx]}; old {a.old_tree}, new {a.new_tree}; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; load average "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}; {os.cpu_count()} cores", flush=True)
    print("  contact [s]   old: CPU [s]  fits  ms/fit  RSS [MB]   new: CPU [s]  fits  ms/fit  RSS [MB]   "
          "ratio (CPU per fit)", flush=True)
    tot = {"old": [0.0, 0, 0.0], "new": [0.0, 0, 0.0]}
    for k in idx:
        row = {}
        for name, tree in (("old", a.old_tree), ("new", a.new_tree)) if k % 2 == 0 else \
                (("new", a.new_tree), ("old", a.old_tree)):
            row[name] = r = run_one(tree, a, k, a.out / name)
            t = tot[name]
            t[0] += r["cpu_s"]
            t[1] += r["fits"]
            t[2] = max(t[2], r["maxrss_mb"])
        o, n = row["old"], row["new"]
        ratio = (n["cpu_s"] / max(n["fits"], 1)) / (o["cpu_s"] / max(o["fits"], 1))
        print(f"  {contacts[k]:>10g}   {o['cpu_s']:11.1f} {o['fits']:6d} {1e3 * o['cpu_s'] / max(o['fits'], 1):7.2f} "
              f"{o['maxrss_mb']:8.0f}   {n['cpu_s']:11.1f} {n['fits']:6d} {1e3 * n['cpu_s'] / max(n['fits'], 1):7.2f} "
              f"{n['maxrss_mb']:8.0f}   {ratio:.3f}", flush=True)
    o, n = tot["old"], tot["new"]
    per_old, per_new = o[0] / max(o[1], 1), n[0] / max(n[1], 1)
    ratio = per_new / per_old
    print(f"total: old {o[0]:.1f} CPU s, {o[1]} fits, {1e3 * per_old:.2f} ms/fit, peak RSS {o[2]:.0f} MB; "
          f"new {n[0]:.1f} CPU s, {n[1]} fits, {1e3 * per_new:.2f} ms/fit, peak RSS {n[2]:.0f} MB")
    # the slice's CPU, not CPU per fit: a search that makes fewer fits (engine version 3) counts too
    slice_ratio = n[0] / max(o[0], 1e-9) * a.old_vs_full
    print(f"CPU per fit new/old: {ratio:.3f}; slice CPU new/old: {n[0] / max(o[0], 1e-9):.3f}")
    print(f"projected full build on 2 idle cores: {a.full_wall_s * slice_ratio / 60:.1f} min wall "
          f"({a.full_cpu_s * slice_ratio:.0f} CPU s), from the last build's {a.full_wall_s / 60:.1f} min / "
          f"{a.full_cpu_s:.0f} CPU s times the slice's CPU ratio" + (f" and {a.old_vs_full:g} (the old tree's own "
          "ratio to that build)" if a.old_vs_full != 1.0 else ""))
    print(f"load average at end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
