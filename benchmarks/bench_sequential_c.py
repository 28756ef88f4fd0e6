"""Nanoseconds per sample of the C sequential update function (issue 17 target: <= 1 us).

Run from the repository root::

    python benchmarks/bench_sequential_c.py

The header comes from :func:`designkit.export.sequential_c.write_sequential_c`
and is compiled with the system C compiler (``cc -std=c99 -O2``). Streams are
simulated touches (seeded), written as raw doubles; the harness reads them into
one buffer, then times (CPU time of the process, ``clock_gettime(CLOCK_PROCESS_CPUTIME_ID)``, so that the shared machine's load inflates it less than wall time) ``PREFIX_update``
on every sample of every touch up to its final answer, repeated until at least
0.5 s has passed. Two tests: the paper's guideline pair (two 80-wide classes, one
prior piece each) and three database-wide materials (wood, acrylic, metal; 3 + 2 + 14
pieces, the costly case: every piece costs two erfc). The Python object's
:meth:`SequentialTest.update` is timed on the same streams as the baseline.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from designkit import SENSORS, Scene
from designkit.export.sequential_c import write_sequential_c
from designkit.objects import ObjectClass
from designkit.recognition.sequential import SequentialTest
from designkit.simulation import simulate_class

PAPER = SENSORS["paper"]
HARNESS = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "seq.h"
int main(int argc, char **argv) {
    long n_touch = atol(argv[2]), m = atol(argv[3]), calls = 0, reps = 0, i, k;
    double *y = malloc(sizeof(double) * n_touch * m), el = 0.0;
    FILE *f = fopen(argv[1], "rb");
    struct timespec a, b;
    int sink = 0;
    if (!y || !f || fread(y, sizeof(double), n_touch * m, f) != (size_t)(n_touch * m)) return 2;
    while (el < 0.5) {
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &a);
        for (i = 0; i < n_touch; i++) {
            seq_state st;
            seq_init(&st, SEQ_DEFAULT_TS0_C, SEQ_DEFAULT_TA_C);
            for (k = 0; k < m; k++) {
                int r = seq_update(&st, (double)k / SEQ_SAMPLE_RATE_HZ, y[i * m + k]);
                calls++;
                if (r != SEQ_KEEP_TOUCHING) { sink += r; break; }
            }
        }
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &b);
        el += (b.tv_sec - a.tv_sec) + 1e-9 * (b.tv_nsec - a.tv_nsec);
        reps++;
    }
    printf("%.3f %ld %ld %d\n", 1e9 * el / calls, calls / reps, reps, sink);
    return 0;
}
"""


def bench(name, cands, truths, noise, contact, cc, tmp):
    test = SequentialTest(cands, PAPER, noise_c=noise, sensor_temp_c=35.0, ambient_temp_c=25.0, error_rate=0.01,
                          max_contact_s=contact)
    temps = np.vstack([simulate_class(ObjectClass("x", r), 100, PAPER, Scene(contact_s=contact, noise_c=noise),
                                      seed=[2, i]).temperature_c for i, r in enumerate(truths)])
    (tmp / "seq.h").write_bytes(write_sequential_c(test, "seq"))
    (tmp / "main.c").write_text(HARNESS)
    (tmp / "y.bin").write_bytes(np.ascontiguousarray(temps, dtype="<f8").tobytes())
    subprocess.run([cc, "-std=c99", "-O2", "-o", str(tmp / "b"), str(tmp / "main.c"), "-lm"], check=True)
    out = subprocess.run([str(tmp / "b"), str(tmp / "y.bin"), str(temps.shape[0]), str(temps.shape[1])],
                         capture_output=True, text=True, check=True).stdout.split()
    ns, calls = float(out[0]), int(out[1])
    times = np.arange(temps.shape[1]) / PAPER.sample_rate_hz
    t0, n = time.process_time(), 0
    for row in temps:
        test.reset()
        for t, y in zip(times, row):
            n += 1
            if test.update(t, y).final:
                break
    py_ns = 1e9 * (time.process_time() - t0) / n
    pieces = sum(len(c.log_mass) for c in test.candidates)
    print(f"{name}: {len(cands)} candidates, {pieces} prior pieces, {temps.shape[0]} touches, {calls} updates per pass: "
          f"C {ns:.0f} ns per sample; Python object {py_ns / 1e3:.1f} us per sample ({py_ns / ns:.0f}x the C); "
          f"static data {(tmp / 'seq.h').stat().st_size:,} bytes of header")


def main() -> int:
    cc = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
    if cc is None:
        print("no C compiler: nothing to measure")
        return 0
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; {cc} -O2")
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        bench("guideline pair 35000 vs 20000, noise 0.05", [("20000", (20000.0, 20080.0)), ("35000", (35000.0, 35080.0))],
              [(20000.0, 20080.0), (35000.0, 35080.0)], 0.05, 3.0, cc, tmp)
        bench("wood / acrylic / metal (database ranges), noise 0.2",
              [("wood", (331.0, 506.46)), ("acrylic", (550.0, 650.0)), ("metal", (12767.0, 25972.0))],
              [(331.0, 506.46), (550.0, 650.0), (12767.0, 25972.0)], 0.2, 3.0, cc, tmp)
    return 0


if __name__ == "__main__":
    sys.exit(main())
