"""What checking a shipped table's arrays costs a question (issue 36): each array a question maps is hashed
(XXH3-128, :func:`designkit.tables.store.member_digest`; SHA-256 until issue 33's start-up work) on first read and compared with its shipped digest, once per process and file.

Measured in one process, same run: ``min-contact --e1 35000 --e2 20000`` on svm-fine (21 MB, mapped) from a
freshly loaded table, (a) with the per-process cache of checked arrays emptied first (what a fresh
``designkit min-contact`` pays), (b) with it warm (what every later question in a process pays: no hashing),
and the hashing alone: the whole file's bytes (every member the question reads, and a little more) with
the digest a member is checked by (XXH3-128) and with SHA-256 (what it was checked by before).

    PYTHONPATH=. python benchmarks/bench_table_verify.py [--runs 15]
"""

from __future__ import annotations

import argparse
import hashlib
import statistics
import time


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=15)
    args = ap.parse_args(argv)
    from designkit.query import min_contact
    from designkit.query import table as qt
    from designkit.tables import store

    def question(clear: bool) -> float:
        if clear:
            store._VERIFIED.clear()
        for f in (getattr(qt, n, None) for n in dir(qt)):  # the query layer's cached views of the table
            if hasattr(f, "cache_clear"):
                f.cache_clear()
        t0 = time.perf_counter()
        tab = store.load_table("svm-fine")
        min_contact(35000, 20000, noise_c=0.05, delta_t_c=10, table=tab)
        for name in tab.arrays:  # what the question read, at least: every array (mc_calibration reads them all)
            if name != "fits":
                tab.arrays[name]
        return time.perf_counter() - t0

    question(False)
    fresh, warm = [], []
    for _ in range(args.runs):
        fresh.append(question(True))
        warm.append(question(False))
    path = store.load_table("svm-fine").path
    data = path.read_bytes()
    t0 = time.perf_counter()
    for _ in range(args.runs):
        hashlib.sha256(data).digest()
    sha = (time.perf_counter() - t0) / args.runs
    t0 = time.perf_counter()
    for _ in range(args.runs):
        store.member_digest(data)
    xxh = (time.perf_counter() - t0) / args.runs
    out = {"fresh_ms": 1e3 * statistics.median(fresh), "warm_ms": 1e3 * statistics.median(warm),
           "sha256_whole_file_ms": 1e3 * sha, "member_digest_whole_file_ms": 1e3 * xxh, "file_mb": len(data) / 1e6}
    print(f"svm-fine ({out['file_mb']:.1f} MB): min-contact from a fresh table load, median of {args.runs}:\n"
          f"  arrays hashed (first question in a process) {out['fresh_ms']:7.1f} ms\n"
          f"  arrays checked already (cache warm)        {out['warm_ms']:7.1f} ms\n"
          f"  difference (the check)                      {out['fresh_ms'] - out['warm_ms']:7.1f} ms; "
          f"the whole file alone: member_digest (XXH3-128) {out['member_digest_whole_file_ms']:.1f} ms, "
          f"SHA-256 {out['sha256_whole_file_ms']:.1f} ms")
    return out


if __name__ == "__main__":
    main()
