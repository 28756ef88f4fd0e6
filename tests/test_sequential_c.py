"""The C sequential update function: compiled with the system C compiler, fed the same streams as
the Python object, it gives identical decisions at identical samples; fixed memory, no allocation."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from designkit import SENSORS
from designkit._validation import InputError
from designkit.export.sequential_c import write_sequential_c
from designkit.objects import ObjectClass
from designkit.recognition.sequential import SequentialTest
from designkit.scene import Scene
from designkit.simulation import simulate_class

CC = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc") or shutil.which("clang")
pytestmark = pytest.mark.skipif(CC is None, reason="no C compiler (cc, gcc or clang) on PATH: the C header "
                                                   "cannot be compiled here")
PAPER = SENSORS["paper"]

MAIN = r"""
#include <stdio.h>
#include <stdlib.h>
#include "seq.h"
/* stdin: a line "R ts0 ta" starts a touch, then lines "t y". stdout: per touch "answer n time_s" at the
   first final answer (or after its last sample), and every BAD_RATE / INVALID answer as "E code". */
int main(void) {
    char line[256];
    seq_state st;
    int done = 1, last = SEQ_KEEP_TOUCHING;
    seq_init(&st, SEQ_DEFAULT_TS0_C, SEQ_DEFAULT_TA_C);
    while (fgets(line, sizeof line, stdin)) {
        double t, y;
        if (line[0] == 'R') {
            if (!done) printf("%d %ld %.17g\n", last, st.n, st.time_s);
            if (sscanf(line + 1, "%lf %lf", &t, &y) != 2) return 3;
            if (seq_init(&st, t, y) != 0) { printf("E init\n"); return 0; }
            done = 0; last = SEQ_KEEP_TOUCHING;
            continue;
        }
        if (sscanf(line, "%lf %lf", &t, &y) != 2) return 3;
        last = seq_update(&st, t, y);
        if (last == SEQ_BAD_RATE || last == SEQ_INVALID) { printf("E %d\n", last); continue; }
        if (!done && last != SEQ_KEEP_TOUCHING) { printf("%d %ld %.17g\n", last, st.n, st.time_s); done = 1; }
    }
    if (!done) printf("%d %ld %.17g\n", last, st.n, st.time_s);
    return 0;
}
"""

def _build(tmp_path: Path, test: SequentialTest, flags=("-O2",)) -> Path:
    (tmp_path / "seq.h").write_bytes(write_sequential_c(test, "seq"))
    (tmp_path / "main.c").write_text(MAIN)
    exe = tmp_path / "seqmain"
    subprocess.run([CC, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", *flags,
                    "-o", str(exe), str(tmp_path / "main.c"), "-lm"], check=True, capture_output=True)
    return exe


def _python(make, temps0, times, temps):
    out = []
    for (ts0, ta), row in zip(temps0, temps):
        test = make(ts0, ta)
        for t, y in zip(times, row):
            d = test.update(t, y)
            if d.final:
                break
        names = [c.name for c in test.candidates]
        code = names.index(d.material) if d.state == "decided" else {"no decision by the longest contact": -2,
                                                                     "no decision possible": -3}.get(d.state, -1)
        out.append((code, d.n_samples, d.time_s))
    return out


def _c(exe: Path, temps0, times, temps):
    lines = []
    for (ts0, ta), row in zip(temps0, temps):
        lines.append(f"R {float(ts0)!r} {float(ta)!r}")
        lines.extend(f"{float(t)!r} {float(y)!r}" for t, y in zip(times, row))
    r = subprocess.run([str(exe)], input="\n".join(lines) + "\n", capture_output=True, text=True, check=True)
    out = []
    for ln in r.stdout.split("\n"):
        if ln:
            a, n, t = ln.split()
            out.append((int(a), int(n), float(t)))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("cands,e_true,noise", [
    ((("20000", (20000.0, 20080.0)), ("35000", (35000.0, 35080.0))), [(20000.0, 20080.0), (35000.0, 35080.0)], 0.1),
    ((("wood", (331.0, 506.46)), ("acrylic", (550.0, 650.0)), ("metal", (12767.0, 25972.0))),
     [(331.0, 506.46), (550.0, 650.0), (12767.0, 25972.0)], 0.3),
])
def test_c_decisions_equal_python(tmp_path, cands, e_true, noise):
    sigma = 0.05 if len(cands) == 2 else 0.2

    def make(ts0, ta):
        return SequentialTest(list(cands), PAPER, noise_c=sigma, sensor_temp_c=ts0, ambient_temp_c=ta,
                              error_rate=0.01, max_contact_s=3.0)
    exe = _build(tmp_path, make(35.0, 25.0))
    temps = np.vstack([simulate_class(ObjectClass("x", r), 30, PAPER, Scene(contact_s=3.0, noise_c=noise),
                                      seed=[4, i]).temperature_c for i, r in enumerate(e_true)])
    # each touch its own initial temperatures (as a robot measures them), shifted readings to match
    rng = np.random.default_rng(7)
    shift = rng.uniform(-3.0, 3.0, temps.shape[0])
    ta = 25.0 + rng.uniform(-2.0, 2.0, temps.shape[0])
    temps = temps + shift[:, None]  # the same touches, seen from other set points (Ta differs too: both sides get it)
    temps0 = list(zip(35.0 + shift, ta))
    times = np.arange(temps.shape[1]) / PAPER.sample_rate_hz
    py, c = _python(make, temps0, times, temps), _c(exe, temps0, times, temps)
    assert len(c) == len(py)
    assert c == py
    codes = {a for a, _, _ in py}
    assert len(codes - {-1, -2}) >= 2  # the streams exercise more than one decision


def test_c_refuses_off_grid_samples_and_hopeless_pairs(tmp_path):
    test = SequentialTest([("a", 20000.0), ("b", 35000.0)], PAPER, noise_c=0.05, sensor_temp_c=35,
                          ambient_temp_c=25, error_rate=0.05, max_contact_s=2.0)
    exe = _build(tmp_path, test)
    r = subprocess.run([str(exe)], input="R 35 25\n0 35\n0.001 35\n0.005 35\nnan 35\n", capture_output=True,
                       text=True, check=True)
    assert r.stdout.split("\n")[:2] == ["E -4", "E -5"]
    r = subprocess.run([str(exe)], input="R 35 35\n", capture_output=True, text=True, check=True)
    assert r.stdout == "E init\n"
    hopeless = SequentialTest([("a", 20000.0), ("b", 20050.0)], PAPER, noise_c=0.05, sensor_temp_c=35,
                              ambient_temp_c=25, error_rate=0.01, max_contact_s=2.0)
    exe = _build(tmp_path, hopeless)
    assert subprocess.run([str(exe)], input="R 35 25\n0 35\n", capture_output=True,
                          text=True).stdout.startswith("-3 ")


def test_c_header_escapes_names_and_validates_the_prefix(tmp_path):
    test = SequentialTest([('x */ "evil"??/', 20000.0), ("b\n#include <stdlib.h>", 35000.0)], PAPER,
                          noise_c=0.05, sensor_temp_c=35, ambient_temp_c=25, max_contact_s=2.0)
    text = write_sequential_c(test, "seq").decode()
    assert [ln for ln in text.splitlines() if ln.startswith("#include")] == ["#include <math.h>"]
    _build(tmp_path, test, flags=("-O0", "-fsanitize=address,undefined"))
    with pytest.raises(InputError, match="prefix"):
        write_sequential_c(test, "1bad")
    assert "malloc" not in text and "static" in text


def test_c_header_compiles_strictly_in_a_program_that_calls_nothing(tmp_path):
    """Every function is ``static inline``: a program that includes the header and calls none of them (or only
    some) compiles under -std=c99 -Wall -Wextra -Werror -pedantic (``static`` gave -Wunused-function)."""
    test = SequentialTest([("a", 20000.0), ("b", 35000.0)], PAPER, noise_c=0.05, sensor_temp_c=35,
                          ambient_temp_c=25, error_rate=0.05, max_contact_s=2.0)
    (tmp_path / "seq.h").write_bytes(write_sequential_c(test, "seq"))
    (tmp_path / "none.c").write_text('#include "seq.h"\nint main(void) { return 0; }\n')
    proc = subprocess.run([CC, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-c", "none.c"],
                          cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
