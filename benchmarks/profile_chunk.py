"""Where a sweep chunk's CPU goes: simulation and features, each solver stage, the search (issue 12).

Run from the repository root::

    python benchmarks/profile_chunk.py                          # svm-paper, sigma/dT 0.005, 2 s, block 1 of 2
    python benchmarks/profile_chunk.py --contact 10 --blocks 10 --block 3
    python benchmarks/profile_chunk.py --workdir WORK          # a finished sweep's search, per contact time

One chunk of ``tables/svm-paper.yaml`` (one sigma/dT, one contact time, one block of
references), run as a sweep worker runs it (``run_chunk``: BLAS on one thread). CPU
seconds of this process (``time.process_time``) per reference and per SVM fit, split
into: simulation + features (rendering trials, Savitzky-Golay slopes, preparing them
for the solver), the batched solver's stages (its own ``timings``), and the rest
(search bookkeeping, the ideal observer's floor). Also: fits and distinct pairs per
reference, feature matrices built (a bounded cache may rebuild some), solver calls
and pairs per call, and the fits on the pairs that certify the answers (``J - 1`` and
``J`` of each staircase), a floor for any search of the same staircases. This is a
profile, not a comparison: run it before and after a change (same chunk, similar
load; the load average is printed).

With ``--workdir`` it runs nothing: it reads the chunks a finished ``designkit sweep
--workdir WORK`` saved and prints, per contact time, the fits made against the fits on
the crossing pairs, and the share of the chunks' wall time a search told every answer
would save at most (where a chunk's time is proportional to its fits).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

from designkit.recognition import batched_svm
from designkit.sweep import chunk, scorer
from designkit.sweep.config import SweepConfig


def profile(config: str, noise: float, contact: float, blocks: int, block: int) -> dict:
    cfg = SweepConfig.from_yaml(config, noise_ratio=[noise], contact_s=[contact], blocks=blocks)
    T: dict[str, float] = {}
    made: list = []
    orig_init, orig_features, orig_f1 = scorer.PairScorer.__init__, scorer.PairScorer.features, batched_svm.batched_cv_f1

    def init(self, *a, **k):
        orig_init(self, *a, **k)
        made.append(self)

    def features(self, k, rep):
        t = time.process_time()
        T["builds"] = T.get("builds", 0) + ((k, rep) not in self._features)
        out = orig_features(self, k, rep)
        T["features"] = T.get("features", 0.0) + time.process_time() - t
        return out

    def f1(*a, **k):
        t = time.process_time()
        out = orig_f1(*a, timings=T, **k)
        T["solver"] = T.get("solver", 0.0) + time.process_time() - t
        return out

    scorer.PairScorer.__init__, scorer.PairScorer.features, batched_svm.batched_cv_f1 = init, features, f1
    try:
        t = time.process_time()
        res = chunk.run_chunk(cfg, (0,), block, 0)
        cpu = time.process_time() - t
    finally:
        scorer.PairScorer.__init__, scorer.PairScorer.features, batched_svm.batched_cv_f1 = (
            orig_init, orig_features, orig_f1)
    stages = {k: T.get(k, 0.0) for k in ("folds", "standardize", "gram", "solve", "predict")}
    split = {"simulation + features": T.get("features", 0.0), **stages,
             "solver glue": T.get("solver", 0.0) - sum(stages.values()),
             "search, bookkeeping, ideal floor": cpu - T.get("solver", 0.0) - T.get("features", 0.0)}
    sc = made[0] if made else None
    return {"rows": int(res.rows.size), "fits": int(res.fits), "pairs": int(len(res.cells)), "cpu_s": cpu,
            "crossing_fits": crossing_fits(res, cfg.intervals),
            "builds": int(T.get("builds", 0)), "calls": sc.calls if sc else 0, "fits_run": sc.fits if sc else 0,
            "split": split}


def crossing_fits(res, n: int) -> int:
    """Fits of the pairs that certify the chunk's answers: for each row, ``J - 1`` and ``J`` of each of its
    three staircases (J, J_lo, J_hi), with the repeats the repeat rule gave them.

    What a search that was told every answer in advance would still score, so a floor for any search of
    the same staircases (pairs below the ideal observer's floor need no fit and count only where scored).
    """
    reps = {(int(i), int(j)): int(r) for i, j, _, _, r in res.cells}
    total = 0
    for i, *Js in zip(res.rows.tolist(), res.J.tolist(), res.J_lo.tolist(), res.J_hi.tolist()):
        need = {j for J in Js for j in (J - 1, J) if i < j < n}
        total += sum(reps.get((i, j), 0) for j in need)
    return total


def search_overhead(workdir: str) -> None:
    """Print a finished sweep's fits against its crossing fits, per contact time (:func:`crossing_fits`)."""
    import json
    from pathlib import Path

    try:
        cfg = json.loads((Path(workdir) / "sweep.json").read_text())["config"]
        n, contacts = int(cfg["intervals"]), cfg["contact_s"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ValueError(f"{workdir} is no sweep's working folder: its sweep.json is missing or unreadable ({exc})") from None
    per: dict[float, list[float]] = {}
    for path in sorted((Path(workdir) / "chunks").glob("*.npz")):
        try:
            with np.load(path, allow_pickle=False) as z:
                res = chunk.ChunkResult.from_arrays({k: z[k] for k in z.files})
        except Exception as exc:  # numpy's and zipfile's errors for a damaged file, KeyError for a foreign one
            raise ValueError(f"chunk {path} is unreadable ({exc})") from None
        c = crossing_fits(res, n)
        a = per.setdefault(float(contacts[res.contact_index]), [0, 0, 0.0, 0.0])
        a[0] += res.fits
        a[1] += c
        a[2] += res.wall_s
        a[3] += res.wall_s * (1.0 - c / res.fits) if res.fits else 0.0
    if not per:
        raise ValueError(f"{workdir}: no finished chunks")
    tot = np.sum(list(per.values()), axis=0)
    print(f"{cfg['name']} ({workdir}): {int(tot[0]):,} fits, {int(tot[1]):,} on crossing pairs "
          f"({tot[0] / tot[1]:.2f}x); chunk wall {tot[2]:.0f} s, of which a search told the answers would "
          f"save at most {tot[3]:.0f} s ({100 * tot[3] / tot[2]:.1f} %)")
    print("  contact [s]   fits      crossing   ratio   chunk wall [s]")
    for k in sorted(per):
        f, c, w, _ = per[k]
        print(f"  {k:>10g}  {int(f):>8,}  {int(c):>8,}   {f / max(c, 1):5.2f}   {w:8.0f}")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--config", default="tables/svm-paper.yaml")
    p.add_argument("--noise-ratio", type=float, default=0.005)
    p.add_argument("--contact", type=float, default=2.0)
    p.add_argument("--blocks", type=int, default=2)
    p.add_argument("--block", type=int, default=1)
    p.add_argument("--workdir", help="a finished sweep's working folder: its search against the crossing fits")
    a = p.parse_args(argv)
    if a.workdir:
        try:
            search_overhead(a.workdir)
        except ValueError as exc:  # a folder that is no finished sweep's: one line, exit 2
            print(f"error: {exc}", file=sys.stderr)
            return 2
        return 0
    print(f"# {' '.join(sys.argv)}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}; {os.cpu_count()} cores")
    r = profile(a.config, a.noise_ratio, a.contact, a.blocks, a.block)
    n, f = r["rows"], max(r["fits"], 1)
    print(f"sigma/dT {a.noise_ratio}, contact {a.contact} s, block {a.block} of {a.blocks}: {n} references, "
          f"{r['fits']} fits ({r['fits'] / n:.1f} per reference), {r['pairs']} pairs ({r['pairs'] / n:.1f} per "
          f"reference), {r['builds']} feature matrices built, {r['calls']} solver calls "
          f"({r['fits_run'] / max(r['calls'], 1):.1f} pairs per call)")
    c = max(r["crossing_fits"], 1)
    print(f"fits on the crossing pairs alone (J - 1 and J of each staircase; a search told the answers would "
          f"still make these): {r['crossing_fits'] / n:.1f} per reference; this search makes {r['fits'] / c:.2f}x that")
    print(f"CPU {r['cpu_s']:.2f} s: {1e3 * r['cpu_s'] / n:.1f} ms per reference, {1e3 * r['cpu_s'] / f:.2f} ms per fit")
    width = max(len(k) for k in r["split"])
    for k, v in r["split"].items():
        print(f"  {k:<{width}}  {1e3 * v / n:7.1f} ms/ref  {1e3 * v / f:6.2f} ms/fit  {100 * v / r['cpu_s']:5.1f} %")
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    raise SystemExit(main())
