"""Fuzz every designkit command with bad input and count what it does (issue 36).

Each case is a cheap, valid command line with one option's value replaced by a bad one (numbers, names,
paths, YAML files), plus the audit's own cases. Every invocation runs in this process through typer's
CliRunner (a fresh process each would take ten times longer), with a 60 s alarm. Counted:

* ``internal``: an internal error (exit 1, "internal error"), or an exception that escaped the CLI;
* ``hang``: still running after 60 s;
* ``multi-line``: a refusal (exit 2) whose stderr is more than its one ``Error:`` line;
* ``refused``: exit 2, one line; ``answered``: exit 0 or 3;
* ``accepted-bad``: answered although the case is bad input by any reading (listed, to be judged).

Run from the repository root (the tree on PYTHONPATH is the one fuzzed)::

    PYTHONPATH=. python benchmarks/fuzz_cli.py                 # this tree
    PYTHONPATH=/work/main python benchmarks/fuzz_cli.py        # another one, for a before/after
    python benchmarks/fuzz_cli.py --json out.json --limit 200

Prints the counts and every case that is not a clean refusal or a clean answer.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import signal
import sys
import tempfile
import time
from pathlib import Path

HANG_S = 60
#: Options that keep a question's exact route (a sensor file, a model) to a second or so.
EXACT_CHEAP = ["--trials", "10", "--repeats", "1", "--jobs", "1", "--n-mc", "200"]

# ------------------------------------------------------------------ values
BAD_FLOATS = ["nan", "inf", "-inf", "1e308", "-1e308", "abc", "", "1e400", " ", "0x10", "1,5"]
ODD_FLOATS = ["0", "-1", "1e-320", "-0", "1e9", "-1e9"]  # bad or not depending on the option: no expectation
BAD_INTS = ["abc", "", "1.5", "1e3", "99999999999999999999999"]
ODD_INTS = ["0", "-1", "-2", "1000000000"]
BAD_NAMES = ["", " ", "a\nb", "../../escaped", "/abs/x", "x" * 300, "a\tb", "\x1b[31mred"]
ODD_NAMES = ["nosuch", "-", "."]


def _yaml_files(d: Path) -> dict[str, Path]:
    """Sensor, profile and sweep-config files with one thing wrong each (all should be refused)."""
    from designkit.calibration.profiles import list_profiles
    from designkit.sensor import SENSORS

    out: dict[str, Path] = {}
    sensor = "".join(f"{k}: {v}\n" for k, v in SENSORS["paper"].to_dict().items() if not isinstance(v, dict))
    profile = list_profiles()["designkit"].read_text()
    config = ("name: tiny\nfidelity: ideal\neffusivity: {min: 0, max: 40000, intervals: 4}\ntrials: 6\nfolds: 2\n"
              "noise_ratio: [0.005]\ncontact_s: [1]\n")
    import re

    edits = {
        "sensor": (sensor, [
            ("no-version", lambda t: t.replace("designkit_sensor: 1\n", "")),
            ("dup-key", lambda t: t + "effusivity: 900\n"),
            ("e-1e308", lambda t: t.replace("effusivity: 892.0", "effusivity: 1e308")),
            ("rate-1e12", lambda t: t.replace("sample_rate_hz: 200.0", "sample_rate_hz: 1e12")),
            ("depth-1e308", lambda t: t.replace("depth_m: 8e-05", "depth_m: 1e308")),
            ("nan", lambda t: t.replace("effusivity: 892.0", "effusivity: .nan")),
            ("name-newline", lambda t: t.replace("name: paper", 'name: "two\\nlines"')),
            ("name-list", lambda t: t.replace("name: paper", "name: [a, b]")),
            ("empty", lambda t: ""), ("list", lambda t: "- a\n- b\n"), ("not-yaml", lambda t: "a: [\n"),
            ("latin1", None), ("negative", lambda t: t.replace("diffusivity_m2_s: 1.19e-09", "diffusivity_m2_s: -1")),
        ]),
        "profile": (profile, [
            ("post-1e308", lambda t: re.sub(r"post_s: .*", "post_s: 1e308", t)),
            ("rate-1e9", lambda t: re.sub(r"sample_rate_hz: .*", "sample_rate_hz: 1e9", t)),
            ("empty", lambda t: ""), ("dup-key", lambda t: t + "name: again\n"), ("list", lambda t: "- a\n"),
        ]),
        "config": (config, [
            ("name-traversal", lambda t: t.replace("name: tiny", "name: ../../escaped")),
            ("name-abs", lambda t: t.replace("name: tiny", f"name: {d}/abs")),
            ("name-empty", lambda t: t.replace("name: tiny", "name: ''")),
            ("dup-key", lambda t: t + "trials: 8\n"), ("intervals-huge", lambda t: t + "intervals: 100000000000\n"),
            ("empty", lambda t: ""), ("list", lambda t: "- a\n"), ("rate-1e12", lambda t: t + "sample_rate_hz: 1e12\n"),
        ]),
    }
    for kind, (base, variants) in edits.items():
        for name, fn in variants:
            p = d / f"{kind}-{name}.yaml"
            if fn is None:
                p.write_bytes(base.encode() + b"name2: caf\xe9\n")
            else:
                p.write_text(fn(base))
            out[f"{kind}:{name}"] = p
    return out


def cases(d: Path, rng: random.Random) -> list[tuple[list[str], bool]]:
    """(argv, bad): ``bad`` is True where any reading of the input says refuse."""
    out_json, out_h = str(d / "o.json"), str(d / "o.h")
    robot = Path(os.environ.get("DESIGNKIT_ROBOT_DATA", "/work/shared/data/robot-thermal-recordings")) / "index.csv"
    # base command lines: cheap and valid; options: (flag, kind) with kind float, int, name or a file kind
    bases = [
        (["min-contact", "--e1", "35000", "--e2", "20000"] + EXACT_CHEAP,
         [("--e1", "float"), ("--e2", "float"), ("--noise", "float"), ("--delta-t", "float"), ("--threshold", "float"),
          ("--m1", "name"), ("--table", "name"), ("--ideal-table", "name"), ("--sensor", "sensor"),
          ("--coverage", "float"), ("--width", "float"), ("--sensor-temp-spread", "float"), ("--model", "name"),
          ("--thickness", "float"), ("--conductance", "float")]),
        (["max-noise", "--e1", "35000", "--e2", "20000", "--contact", "2"] + EXACT_CHEAP,
         [("--contact", "float"), ("--delta-t", "float"), ("--threshold", "float"), ("--table", "name")]),
        (["min-delta-t", "--e1", "35000", "--e2", "20000", "--contact", "2"] + EXACT_CHEAP,
         [("--contact", "float"), ("--noise", "float"), ("--table", "name")]),
        (["delta-e", "--e", "35000", "--contact", "2"] + EXACT_CHEAP,
         [("--e", "float"), ("--contact", "float"), ("--noise", "float"), ("--table", "name")]),
        (["distinguishable", "--e1", "35000", "--e2", "20000", "--contact", "2"] + EXACT_CHEAP,
         [("--e1", "float"), ("--contact", "float"), ("--noise", "float"), ("--delta-t", "float"),
          ("--m2", "name"), ("--sensor", "sensor")]),
        (["matrix", "--m", "copper", "--m", "glass", "-q", "max-noise", "--contact", "2", "--no-multiclass"],
         [("--contact", "float"), ("--noise", "float"), ("--delta-t", "float"), ("--threshold", "float"),
          ("--m", "name"), ("--table", "name"), ("--plot", "path"), ("--out", "path"), ("--format", "name")]),
        (["validity", "--m", "acrylic", "--thickness", "0.003"],
         [("--thickness", "float"), ("--tolerance", "float"), ("--delta-t", "float"), ("--horizon", "float"),
          ("--backing", "name"), ("--plot", "path"), ("--m", "name")]),
        (["materials", "show", "copper"], []),
        (["materials", "list", "--format", "csv"], [("--format", "name")]),
        (["tables", "list"], [("--folder", "path")]),
        (["tables", "show", "svm-paper"], []),
        (["export", "--table", "svm-paper", "--out", out_json, "--contact", "2", "--noise", "0.05"],
         [("--table", "name"), ("--noise", "float"), ("--delta-t", "float"), ("--contact", "float"),
          ("--e-min", "float"), ("--e-max", "float"), ("--prefix", "name"), ("--out", "path"),
          ("--format", "name"), ("--kind", "name")]),
        (["simulate", "--e", "400", "--contact", "1"],
         [("--e", "float"), ("--contact", "float"), ("--noise", "float"), ("--sensor-temp", "float"),
          ("--ambient", "float"), ("--trials", "int"), ("--seed", "int"), ("--sensor", "sensor"), ("--out", "path"),
          ("--plot", "path"), ("--diffusivity", "float")]),
        (["f1", "--e1", "35000", "--e2", "20000", "--trials", "6", "--folds", "2", "--contact", "0.5"],
         [("--e1", "float"), ("--e2", "float"), ("--contact", "float"), ("--noise", "float"), ("--delta-t", "float"),
          ("--width", "float"), ("--trials", "int"), ("--folds", "int"), ("--threshold", "float"),
          ("--sensor", "sensor"), ("--ambient", "float")]),
        (["design", "--m", "wood", "--m", "copper"],
         [("--max-contact", "float"), ("--noise", "float"), ("--max-delta-t", "float"), ("--max-rate", "float"),
          ("--threshold", "float"), ("--depth-um", "name"), ("--skin", "name"), ("--plot", "path")]),
        (["sweep", "--name", "t", "--fidelity", "ideal", "--intervals", "4", "--contact", "1", "--noise-ratio",
          "0.01", "--trials", "6", "--folds", "2", "--out", str(d / "sw"), "--workdir", str(d / "wd")],
         [("--name", "name"), ("--intervals", "int"), ("--trials", "int"), ("--folds", "int"),
          ("--threshold", "float"), ("--e-min", "float"), ("--e-max", "float"), ("--noise-ratio", "float"),
          ("--contact", "float"), ("--sample-rate", "float"), ("--config", "config"), ("--sensor", "sensor"),
          ("--workdir", "path"), ("--jobs", "int")]),
        (["classify", "--m", "wood", "--m", "copper", "--export-c", out_h],
         [("--m", "name"), ("--noise", "float"), ("--error-rate", "float"), ("--max-contact", "float"),
          ("--delta-t", "float"), ("--object-temp", "float"), ("--time-offset", "float"), ("--prefix", "name"),
          ("--export-c", "path"), ("--sensor", "sensor"), ("--profile", "profile"), ("--touches", "int")]),
        (["emulate", "--material", "wood=400", "--duration", "0.2", "--speed", "100"],
         [("--material", "name"), ("--e", "float"), ("--touch-every", "float"), ("--noise", "float"),
          ("--sensor-temp", "float"), ("--ambient", "float"), ("--speed", "float"), ("--duration", "float"),
          ("--profile", "profile"), ("--sensor", "sensor"), ("--touches-per-material", "int")]),
        (["calibrate", "record", "--port", "/dev/null", "--material", "wood", "--out", str(d / "rec"), "--trials", "1",
          "--timeout", "0.5"],
         [("--port", "name"), ("--material", "name"), ("--trials", "int"), ("--timeout", "float"),
          ("--profile", "profile"), ("--out", "path")]),
        (["calibrate", "fit", str(robot), "--bootstrap", "0"],
         [("--depth-um", "float"), ("--bootstrap", "int"), ("--fit-to", "float"), ("--range", "name"),
          ("--out", "path"), ("--name", "name"), ("--offset-range", "name")]),
        (["bench", "--quick", "--section", "nosuch"], [("--jobs", "int"), ("--out", "path"), ("--table", "name")]),
        (["reproduce", "--out", str(d / "rep"), "--only", "nosuch"], [("--jobs", "int"), ("--tables", "path")]),
    ]
    files = _yaml_files(d)
    (d / "a-file").write_text("")
    paths_bad = ["", str(d / "missing" / "deeper" / "x.out"), str(d), str(d / "a-file" / "x.out"), "/proc/x/y"]
    out: list[tuple[list[str], bool]] = []
    cheap_base = {"min-contact", "max-noise", "min-delta-t", "delta-e", "distinguishable", "matrix", "validity",
                  "materials", "tables", "export", "simulate", "f1", "design", "sweep", "classify"}
    # bases whose answer takes seconds: only values that are bad by any reading (an answer is then a finding)
    odd_ok = {"min-contact", "max-noise", "min-delta-t", "delta-e", "distinguishable", "matrix", "validity",
              "materials", "tables", "export", "simulate", "classify"}

    def put(base, flag, value, bad):
        argv = list(base)
        if flag in argv:
            i = argv.index(flag)
            argv[i + 1] = value
        else:
            argv += [flag, value]
        out.append((argv, bad))

    for base, opts in bases:
        if base[0] in cheap_base:
            out.append((base, False))
        for flag, kind in opts:
            if kind == "float":
                for v in BAD_FLOATS:
                    put(base, flag, v, not (v == "1,5" and base[0] == "sweep"))  # a sweep's list of values
                for v in ODD_FLOATS if base[0] in odd_ok else ():
                    put(base, flag, v, False)
            elif kind == "int":
                for v in BAD_INTS:
                    put(base, flag, v, True)
                for v in ODD_INTS if base[0] in odd_ok else ():
                    put(base, flag, v, False)
            elif kind == "name":
                for v in BAD_NAMES:
                    put(base, flag, v, flag not in ("--port",) or not v.strip() or "\n" in v)
                for v in ODD_NAMES if base[0] in odd_ok else ():
                    put(base, flag, v, False)
            elif kind == "path":
                for v in paths_bad:
                    put(base, flag, v, flag not in ("--workdir",) or v in ("", str(d / "a-file" / "x.out")))
            elif kind in ("sensor", "profile", "config"):
                own = [a for a in base if a not in ("--name", "t")] if kind == "config" else base  # its name: its own
                for key, p in files.items():
                    if key.startswith(kind + ":"):
                        put(own, flag, str(p), True)
                for v in ("", "nosuch", str(d), "/dev/null"):
                    put(base, flag, v, True)
    # the audit's own cases (issue 36)
    fine = str(d / "fine-copy.npz")
    audit = [
        ["min-contact", "--m1", "copper", "--m2", "glass", "--exact", "--max-contact", "1e308"],
        ["matrix", "--m", "copper", "--m", "glass", "--m", "granite", "-q", "max-noise", "--contact", "1e308"],
        ["min-contact", "--e1", "35000", "--e2", "20000", "--exact", "--table", "svm-paper"],
        ["max-noise", "--e1", "35000", "--e2", "20000", "--contact", "2", "--exact", "--table", "svm-paper"],
        ["min-delta-t", "--e1", "35000", "--e2", "20000", "--contact", "2", "--exact", "--table", "svm-paper"],
        ["delta-e", "--e", "35000", "--contact", "2", "--exact", "--table", "svm-paper"],
        ["distinguishable", "--e1", "35000", "--e2", "20000", "--contact", "2", "--exact", "--table", "svm-paper"],
        ["matrix", "--m", "copper", "--m", "glass", "--set", "paper12"],
        ["matrix", "--m", "copper", "--m", "glass", "--from", "-"],
        ["classify", "--m", "wood", "--m", "copper", "--port", "/dev/null", "--export-c", out_h],
        ["f1", "--e1", "35000", "--e2", "20000", "--delta-t", "0", "--trials", "6", "--folds", "2"],
        ["design", "--set", "paper12", "--depth-um", "1:1e308"],
        ["bench", "--jobs", "0", "--section", "nosuch"],
        ["export", "--table", "svm-paper", "--contact", "1,,2", "--out", out_json],
        ["emulate", "--material", "=400", "--duration", "0.2"],
        ["emulate", "--material", "a\nb=400", "--duration", "0.2"],
        ["calibrate", "fit", str(robot), "--bootstrap", "0", "--format", "csv", "--out", str(d)],
        ["min-contact", "--m1", "copper", "--m2", "glass", "--table", fine],
    ]
    out += [(a, True) for a in audit]
    rng.shuffle(out)
    return out


class _Hang(BaseException):
    pass


def _alarm(signum, frame):
    raise _Hang()


def run_one(runner, app, argv: list[str]) -> dict:
    signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(HANG_S)
    t0 = time.perf_counter()
    try:
        r = runner.invoke(app, argv, input="")
    except _Hang:
        return {"outcome": "hang", "wall_s": time.perf_counter() - t0}
    finally:
        signal.alarm(0)
    wall = time.perf_counter() - t0
    err = getattr(r, "stderr", None)
    err = r.output if err is None else err
    text = r.output or ""
    exc = r.exception if r.exception is not None and not isinstance(r.exception, SystemExit) else None
    if exc is not None or "Traceback" in text or "internal error" in text or r.exit_code == 1:
        first = f"{type(exc).__name__}: {exc}" if exc is not None else (err.strip().splitlines() or [""])[0]
        return {"outcome": "internal", "exit": r.exit_code, "wall_s": wall, "line": first[:300]}
    if r.exit_code == 2:
        lines = [ln for ln in err.splitlines() if ln.strip()]
        if len(lines) != 1 or not lines[0].startswith("Error: "):
            return {"outcome": "multi-line", "exit": 2, "wall_s": wall, "line": " | ".join(lines)[:300]}
        return {"outcome": "refused", "exit": 2, "wall_s": wall, "line": lines[0][:300]}
    return {"outcome": "answered", "exit": r.exit_code, "wall_s": wall,
            "line": (text.strip().splitlines() or [""])[0][:200]}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=36)
    ap.add_argument("--limit", type=int, default=0, help="run only the first N cases (0: all)")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    os.environ.setdefault("DESIGNKIT_MEMORY_LIMIT_GB", "4")  # a request beyond it is refused, not swapped
    from typer.testing import CliRunner

    import designkit
    from designkit.cli import app

    work = Path(tempfile.mkdtemp(prefix="designkit-fuzz-"))
    # a copy of svm-fine edited in place (delta_up halved): class 1 of the audit
    from designkit.tables.store import load_table

    src = load_table("svm-fine").path
    import shutil

    shutil.copyfile(src.with_suffix(".json"), work / "fine-copy.json")
    blob = bytearray(src.read_bytes())
    import zipfile
    import struct

    with zipfile.ZipFile(src) as z:
        info = z.getinfo("delta_up.npy")
    n, extra = struct.unpack("<HH", blob[info.header_offset + 26:info.header_offset + 30])
    start = info.header_offset + 30 + n + extra + 128
    import numpy as np

    a = np.frombuffer(bytes(blob[start:start + 2720000]), dtype="<f8") / 2
    blob[start:start + 2720000] = a.tobytes()
    (work / "fine-copy.npz").write_bytes(bytes(blob))

    all_cases = cases(work, random.Random(args.seed))
    if args.limit:
        all_cases = all_cases[:args.limit]
    runner = CliRunner()
    counts: dict[str, int] = {}
    notable = []
    accepted_bad = []
    results = []
    cwd = os.getcwd()
    t0 = time.perf_counter()
    for argv_, bad in all_cases:
        os.chdir(work)
        try:
            res = run_one(runner, app, argv_)
        finally:
            os.chdir(cwd)
        results.append((argv_, res))
        counts[res["outcome"]] = counts.get(res["outcome"], 0) + 1
        if res["outcome"] in ("internal", "hang", "multi-line"):
            notable.append({"argv": argv_, **res})
        elif res["outcome"] == "answered" and bad:
            accepted_bad.append({"argv": argv_, **res})
    wall = time.perf_counter() - t0
    summary = {"designkit": str(Path(designkit.__file__).parent), "invocations": len(all_cases), "counts": counts,
               "accepted_bad": len(accepted_bad), "wall_s": round(wall, 1)}
    print(json.dumps(summary, indent=1))
    for item in notable:
        print(f"{item['outcome']:>11}: designkit {' '.join(map(repr, item['argv']))}\n             {item.get('line', '')}")
    slow = sorted(results, key=lambda x: -x[1]["wall_s"])[:8]
    print("slowest:", "; ".join(f"{x[1]['wall_s']:.1f} s {' '.join(x[0][:4])}" for x in slow))
    for item in accepted_bad:
        print(f"accepted-bad: designkit {' '.join(map(repr, item['argv']))}  (exit {item['exit']})")
    if args.json:
        args.json.write_text(json.dumps({**summary, "notable": notable, "accepted_bad": accepted_bad}, indent=1))
    shutil.rmtree(work, ignore_errors=True)
    return summary


if __name__ == "__main__":
    main()
