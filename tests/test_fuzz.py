"""Property-based CLI fuzzing (issue 15): hostile values in every option of every command.

The typer command tree is walked, so a new command or option is fuzzed without a change here.
Each command starts from a cheap valid invocation (``BASE``); hypothesis puts one or two options
to hostile values from a pool ('' , 'nan', '-1', '1e308', '0', very long text, unicode, paths,
a FIFO, /dev/null, a folder). Whatever the values:

* never a traceback, and never exit status 1 (the top-level guard's "this is a bug");
* a non-zero exit has exactly one line on stderr, ``Error: ...`` naming something;
* nothing hangs (a watchdog fails the example after WATCHDOG_S).

Then every case named in issue 15 is run as written. The counts (bad invocations, statuses) and
the time it all takes are printed by the last test (``pytest -s``).
"""

from __future__ import annotations

import re

import os
import signal
import time
from collections import Counter
from pathlib import Path

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from refusals import REFUSED_IN_ONE_LINE  # noqa: E402

WATCHDOG_S = 60
EXAMPLES = int(os.environ.get("DESIGNKIT_FUZZ_EXAMPLES", "15"))  # per command; derandomized, so CI sees the same invocations every run
#: DESIGNKIT_FUZZ_EXPLORE=1: random (not derandomized) examples, to look for new findings locally.
EXPLORE = os.environ.get("DESIGNKIT_FUZZ_EXPLORE") == "1"
STATS: Counter = Counter()
SLOW: list[str] = []  # invocations over 2 s, printed by the last test
T0 = time.perf_counter()

HOSTILE = ["", " ", "nan", "-nan", "inf", "-inf", "-1", "0", "1e308", "-1e308", "1e-320", "1e7", "100000000",
           "abc", "1,2,,", "x" * 5000, "\u00e9\u2603\U0001F600", "a\nb", "$(touch PWNED)", "%s%n",
           "@FOLDER", "@FIFO", "/dev/null", "@MISSING", "a/b/c", "@BADUTF8", "@EMPTYFILE", "-", "--json"]


class Hang(BaseException):
    """Raised by the watchdog: not an Exception, so the CLI runner does not swallow it."""


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    """A sandbox cwd (three levels deep, so '..' stays inside it) with the hostile files."""
    root = tmp_path_factory.mktemp("fuzz")
    cwd = root / "a" / "b" / "c"
    cwd.mkdir(parents=True)
    files = {"@FOLDER": str(root / "folder"), "@FIFO": str(root / "fifo.yaml"), "@MISSING": str(root / "missing.yaml"),
             "@BADUTF8": str(root / "bad.yaml"), "@EMPTYFILE": str(root / "empty.yaml")}
    (root / "folder").mkdir()
    os.mkfifo(root / "fifo.yaml")
    (root / "bad.yaml").write_bytes(b"name: \xff\xfe\n")
    (root / "empty.yaml").write_text("")
    (root / "port.txt").write_text("not a serial port\n")
    (root / "tiny.yaml").write_text("name: tiny\nfidelity: ideal\neffusivity: {min: 0, max: 40000, intervals: 4}\n"
                                    "trials: 6\nfolds: 2\nnoise_ratio: [0.005]\ncontact_s: [1]\n")
    old = Path.cwd()
    os.chdir(cwd)
    yield {"root": root, "cwd": cwd, "files": files}
    os.chdir(old)


@pytest.fixture(scope="module")
def run(env):
    """Invoke the CLI in-process (its click command built once) under the watchdog."""
    import typer.testing

    from designkit.cli import app

    # typer's runner rebuilds the click command on every invoke (~0.1 s): build it once
    build = typer.testing._get_command
    command = build(app)
    typer.testing._get_command = lambda a: command if a is app else build(a)
    runner = typer.testing.CliRunner()

    def alarm(signum, frame):
        raise Hang()

    def invoke(args: list[str]):
        args = [env["files"].get(a, a) for a in args]
        old = signal.signal(signal.SIGALRM, alarm)
        signal.alarm(WATCHDOG_S)
        t = time.perf_counter()
        try:
            return runner.invoke(app, args)
        except Hang:
            pytest.fail(f"hung for {WATCHDOG_S} s: designkit {' '.join(args)}")
        finally:
            STATS["seconds"] += time.perf_counter() - t
            if time.perf_counter() - t > 2:
                SLOW.append(f"{time.perf_counter() - t:.1f} s: designkit {' '.join(a[:30] for a in args)}")
            signal.alarm(0)
            signal.signal(signal.SIGALRM, old)

    yield invoke
    typer.testing._get_command = build


#: Findings whose fix lives in a file this change does not own (see the issue 15 report): skipped
#: by the fuzzer until the lead applies them, so the suite stays green and the list stays visible.
KNOWN: list = []  # (the validity --thickness/--horizon 1e308 findings are fixed in models/slab.py)


def _known(argv) -> bool:
    return any(argv[0] == cmd and any(a == opt and b == val for a, b in zip(argv, argv[1:]))
               for cmd, opt, val in KNOWN)


QUERIES = {"min-contact", "max-noise", "min-delta-t", "delta-e", "distinguishable"}


def _expensive(argv) -> bool:
    """A valid value of a forward-model option sends a question to the exact route (seconds to
    minutes of SVM fits): valid input, not this test's subject, and over its time budget."""
    if argv[0] not in QUERIES:
        return False
    for opt, val in zip(argv, argv[1:]):
        if opt in ("--conductance", "--thickness", "--diffusivity"):
            try:
                v = float(val)
            except ValueError:
                continue
            if 0 < v < float("inf"):
                return True
    return False


def check(r, args) -> None:
    """The contract of every invocation; counts it."""
    shown = " ".join(repr(a) if len(a) < 60 else repr(a[:20] + "...") for a in args)
    STATS["invocations"] += 1
    STATS[f"exit {r.exit_code}"] += 1
    exc = r.exception
    assert exc is None or isinstance(exc, SystemExit), f"traceback from designkit {shown}: {exc!r}"
    assert "Traceback" not in r.output, f"traceback from designkit {shown}:\n{r.output[-2000:]}"
    assert r.exit_code != 1, f"internal error (a bug) from designkit {shown}:\n{r.stderr[-2000:]}"
    assert r.exit_code in (0, 2, 3), f"exit {r.exit_code} from designkit {shown}:\n{r.output[-2000:]}"
    if r.exit_code != 0:
        STATS["bad invocations refused"] += 1
        # progress lines (a sweep's chunks) may come first; the error is one line, and the last
        lines = [line for line in r.stderr.splitlines() if line.strip()]
        errors = [line for line in lines if line.startswith("Error:")]
        assert len(errors) == 1 and lines[-1] == errors[0] and len(errors[0]) > 12, \
            f"designkit {shown}: expected one 'Error: ...' line, got:\n{r.stderr[-2000:]}"


# --------------------------------------------------------------- the command tree
def _leaves():
    import typer.main

    from designkit.cli import app

    out = []

    def walk(cmd, path):
        subs = getattr(cmd, "commands", None)
        if subs:
            for name, sub in sorted(subs.items()):
                walk(sub, path + [name])
            if path and any(p.param_type_name == "option" and p.name != "help" for p in cmd.params):
                out.append((" ".join(path), cmd))  # a group that runs on its own (calibrate)
        elif path:
            out.append((" ".join(path), cmd))

    walk(typer.main.get_command(app), [])
    return out


LEAVES = _leaves()

#: A cheap valid invocation of each command (or, for commands that stream, sweep for hours or
#: record from hardware, one refused after every option is parsed), and options never fuzzed
#: because a valid value would start long work (--exact, --jobs, dask) or replace the refusal.
PAIR = ["--e1", "35000", "--e2", "20000"]
BASE = {
    "min-contact": PAIR + ["--noise", "0.05", "--delta-t", "10"],
    "max-noise": PAIR + ["--contact", "2", "--delta-t", "10"],
    "min-delta-t": PAIR + ["--contact", "2", "--noise", "0.05"],
    "delta-e": ["--e", "20000", "--contact", "2", "--noise", "0.05", "--delta-t", "10"],
    "distinguishable": PAIR + ["--contact", "2", "--noise", "0.05", "--delta-t", "10"],
    "validity": ["--m", "acrylic", "--thickness", "0.003"],
    "export": ["--table", "f1-matrix-paper", "--format", "json", "--out", "out.json"],
    "emulate": ["--profile", "@MISSING"],
    "simulate": ["--e", "20000", "--contact", "1", "--trials", "2"],
    "f1": PAIR + ["--contact", "1", "--trials", "6", "--folds", "2"],
    "sweep": ["--config", "@TINY", "--workdir", "work", "--out", "tiny.npz", "--jobs", "1", "--fresh"],
    "reproduce": ["--out", "rep", "--only", "no-such-section"],
    "bench": ["--section", "no-such-section", "--quick"],
    "materials list": [],
    "matrix": ["--m", "copper", "--m", "wood", "--m", "glass", "--no-multiclass"],
    "materials show": ["copper"],
    "tables list": [],
    "tables show": ["ideal-paper"],
    "tables build": ["--sensor", "@MISSING", "--out", "built"],
    "calibrate record": ["--port", "@PORT", "--material", "wood", "--trials", "1", "--timeout", "0.5"],
    "calibrate fit": ["@MISSING"],
    "calibrate": ["--port", "@PORT", "--material", "wood", "--yes", "--timeout", "0.5"],
    "classify": ["--port", "@PORT", "--m", "wood", "--m", "copper", "--touches", "1", "--timeout", "0.5"],
    "design": ["--m", "copper", "--m", "wood", "--no-svm", "--skin", "alumina"],
}
SKIP = {"--exact", "--jobs", "--backend", "--scheduler", "--help", "--only", "--section", "--duration",
        "--quick", "--resume", "--fresh", "--workdir"}


def _fuzzable(cmd):
    opts, args = [], []
    for p in cmd.params:
        if p.param_type_name == "argument":
            args.append(p)
        elif p.param_type_name == "option" and p.opts[0] not in SKIP:
            opts.append(p)
    return opts, args


def _argv(name, base, choices, root):
    files = {"@TINY": str(root / "tiny.yaml"), "@PORT": str(root / "port.txt"), "@MISSING": str(root / "missing.yaml")}
    argv = [files.get(a, a) for a in base]
    for param, value in choices:
        if param is None:  # the positional argument
            if argv and not argv[0].startswith("-"):
                argv[0] = value
            else:
                argv.insert(0, value)
        elif getattr(param, "is_flag", False):
            argv.append(param.opts[0])
        else:
            argv += [param.opts[0], value]
    return argv


@pytest.mark.parametrize("name", [n for n, _ in LEAVES])
def test_hostile_values_in_every_option(name, env, run):
    cmd = dict(LEAVES)[name]
    assert name in BASE, f"new command {name!r}: give it a cheap invocation in BASE"
    opts, args = _fuzzable(cmd)
    params = opts + ([None] if args else [])
    value = st.sampled_from(HOSTILE)
    choice = st.tuples(st.sampled_from(params), value)

    @settings(max_examples=EXAMPLES, deadline=None, derandomize=not EXPLORE, database=None,
              suppress_health_check=list(HealthCheck))
    @given(st.lists(choice, min_size=1, max_size=2))
    def fuzz(choices):
        argv = name.split() + _argv(name, BASE[name], choices, env["root"])
        hypothesis.assume(not _known(argv) and not _expensive(argv))
        check(run(argv), argv)

    fuzz()


# ------------------------------------------------------------------ issue 15's cases
def _files(root: Path) -> dict[str, str]:
    d = root / "cases"
    if not d.exists():
        d.mkdir()
        sensor = "designkit_sensor: 1\neffusivity: 892\ndiffusivity_m2_s: 1.19e-9\n"
        (d / "tau.yaml").write_text(sensor + "tau_s: [1, 2]\n")
        (d / "name.yaml").write_text(sensor + "name: [a, b]\n")
        (d / "fast.yaml").write_text(sensor + "sample_rate_hz: 1e9\n")
        (d / "latin1.yaml").write_bytes(sensor.encode() + b"name: caf\xe9\n")
        (d / "fm.yaml").write_text('intervals: 10\ncontact_s: [1]\nfull_matrix: "no"\n')
        (d / "ten.yaml").write_text("intervals: ten\n")
        (d / "huge.yaml").write_text("intervals: 100000000000\n")
        (d / "empty.yaml").write_text("")
        (d / "tiny.yaml").write_text("name: tiny\nfidelity: ideal\neffusivity: {min: 0, max: 40000, intervals: 4}\n"
                                     "trials: 6\nfolds: 2\nnoise_ratio: [0.005]\ncontact_s: [1]\n")
        (d / "tablist.yaml").write_text("- just\n- a list\n")
        os.mkfifo(d / "fifo.yaml")
    return {p.stem: str(p) for p in d.iterdir()}


ISSUE_CASES = [
    # (argv, needle in the one Error line); '@x' is file x above
    (["simulate", "--e", "100", "--sensor", "@tau"], "tau_s: expected a number, got [1, 2]"),
    (["simulate", "--e", "100", "--sensor", "@name"], "name: expected text"),
    (["simulate", "--e", "100", "--sensor", "@fast"], "samples"),
    (["simulate", "--e", "100", "--sensor", "@fifo"], "FIFO"),
    (["simulate", "--e", "100", "--sensor", "/dev/null"], "sensor file /dev/null"),  # a device (or empty)
    (["simulate", "--e", "100", "--sensor", "@FOLDER"], "is a folder"),
    (["simulate", "--e", "100", "--sensor", "@latin1"], "not UTF-8"),
    (["sweep", "--config", "@fm"], "full_matrix: expected true or false, got 'no'"),
    (["sweep", "--config", "@ten"], "intervals: expected an integer, got 'ten'"),
    (["sweep", "--config", "@huge"], "intervals"),
    (["sweep", "--config", "@empty"], "empty"),
    (["sweep", "--config", "@fifo"], "FIFO"),
    (["sweep", "--config", "@tablist"], "mapping"),
    (["simulate", "--e", "100", "--contact", "1e7"], "limit"),
    (["simulate", "--e", "100", "--trials", "100000000"], "memory"),
    (["f1", "--e1", "35000", "--e2", "20000", "--trials", "100000000"], "memory"),
    (["f1", "--e1", "35000", "--e2", "20000", "--threshold", "2"], "threshold"),
    (["simulate", "--e", "100", "--sensor-temp", "nan"], "sensor-temp"),
    (["tables", "list", "--folder", "@NOWHERE"], "does not exist"),
    (["tables", "list", "--folder", "/dev/null"], "not a folder"),
    (["tables", "show", ""], "empty"),
    (["tables", "show", "@fifo"], "table"),
    (["min-contact", "--e1", "35000", "--e2", "20000", "--ideal-table", "nosuch"], "nosuch"),
    (["calibrate", "record", "--port", "/dev/null", "--material", "w", "--out", "rec", "--profile", "@fifo"],
     "FIFO"),
]
#: Cases fixed in the files of other layers (validity, the question layer, emulate, sweep).
LEAD = [
    (["validity", "--m", "acrylic", "--thickness", "0.003", "--horizon", "1e300"], "horizon"),
    (["validity", "--m", "acrylic", "--thickness", "0.003", "--delta-t", "0"], "delta-t"),
    (["min-delta-t", "--e1", "35000", "--e2", "20000", "--contact", "2", "--noise", "1e308"], "noise"),
    (["emulate", "--sensor-temp", "nan", "--duration", "0.1"], "sensor-temp"),
    (["sweep", "--resume", "--fresh", "--config", "@tiny", "--workdir", "rf", "--out", "rf.npz", "--jobs", "1"],
     "--fresh"),
]


@pytest.mark.parametrize("argv,needle", ISSUE_CASES + LEAD,
    ids=lambda v: " ".join(v)[:60] if isinstance(v, list) else None)
def test_every_case_of_issue_15_is_refused_in_one_line(argv, needle, env, run):
    files = {**env["files"], **{f"@{k}": v for k, v in _files(env["root"]).items()},
             "@NOWHERE": str(env["root"] / "no-such-folder" / "x")}
    argv = [files.get(a, a) for a in argv]
    r = run(argv)
    check(r, argv)
    assert r.exit_code == 2, r.output
    assert needle in r.stderr, r.stderr


# ------------------------------------------------------------------ every file format
# A valid document of each format with one key replaced by an arbitrary JSON/YAML value (or
# dropped): reading it either succeeds or raises designkit's one-line InputError, nothing else.
_LEAF = (st.none() | st.booleans() | st.integers(min_value=-(2 ** 70), max_value=2 ** 70)
         | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=12) | st.sampled_from(HOSTILE[:20]))
_VALUE = st.recursive(_LEAF, lambda c: st.lists(c, max_size=3) | st.dictionaries(st.text(max_size=8), c, max_size=3),
                      max_leaves=6)
_DROP = object()


def _mutate(doc: dict, key: str, value):
    out = dict(doc)
    if value is _DROP:
        out.pop(key, None)
    else:
        out[key] = value
    return out


def _one_line_input_error(fn) -> None:
    from designkit._validation import InputError

    STATS["file documents"] += 1
    try:
        fn()
    except InputError as exc:
        assert "\n" not in str(exc).strip() and str(exc).strip(), repr(exc)
        STATS["file documents refused"] += 1


def _format_cases(root: Path):
    import json

    import numpy as np
    import yaml

    from designkit import SENSORS
    from designkit.calibration.profiles import list_profiles, profile_from_dict
    from designkit.calibration.trials import read_trial_csv
    from designkit.sensor import Sensor
    from designkit.sweep.config import SweepConfig
    from designkit.tables.store import content_hash, load_table, table_header, write_table

    sensor = SENSORS["paper"].to_dict()
    sweep = {"name": "t", "fidelity": "ideal", "effusivity": {"min": 0, "max": 40000, "intervals": 4}, "trials": 6,
             "folds": 2, "noise_ratio": [0.005], "contact_s": [1, 2], "full_matrix": False}
    profile = yaml.safe_load(next(iter(list_profiles().values())).read_text())
    cfg = SweepConfig(name="f", intervals=4, noise_ratio=(0.005,), contact_s=(1.0,), fidelity="ideal")
    arrays = {"delta_up": np.full((1, 1, 4), 900.0), "delta_down": np.full((1, 1, 4), 900.0)}
    tdir = root / "fmt"
    tdir.mkdir(exist_ok=True)
    table = write_table(tdir / "f.npz", table_header(cfg, arrays), arrays)
    header = json.loads(table.with_suffix(".json").read_text())
    trial = tdir / "wood_001.csv"
    trial.write_text("time_s,active_temp_c\n" + "".join(f"{i / 10},{30 + i / 100}\n" for i in range(5)))
    sidecar = {"designkit_trial": 1, "file": trial.name, "material": "wood", "trial_index": 1}

    def table_reader(doc):
        from designkit._validation import InputError

        doc = dict(doc)
        try:  # re-hashed, so that the schema checks (not only the hash) meet the value
            doc["content_hash"] = content_hash(arrays, doc)
        except InputError:  # inf or nan: JSON writes it, the loader refuses it
            doc["content_hash"] = ""
        table.with_suffix(".json").write_text(json.dumps(doc, default=str))
        return lambda: load_table(table)

    def sidecar_reader(doc):
        trial.with_suffix(".json").write_text(json.dumps(doc))
        return lambda: read_trial_csv(trial)

    return {
        "sensor": (sensor, lambda d: lambda: Sensor.from_dict(d, source="sensor file s.yaml")),
        "sweep config": (sweep, lambda d: lambda: SweepConfig.from_mapping(d, source="sweep config c.yaml")),
        "device profile": (profile, lambda d: lambda: profile_from_dict(d, "profile p.yaml")),
        "table header": (header, table_reader),
        "trial sidecar": (sidecar, sidecar_reader),
    }


@pytest.mark.parametrize("fmt", ["sensor", "sweep config", "device profile", "table header", "trial sidecar"])
def test_every_file_format_refuses_wrong_values_in_one_line(fmt, env):
    doc, reader = _format_cases(env["root"])[fmt]
    keys = sorted(doc)

    @settings(max_examples=4 * EXAMPLES, deadline=None, derandomize=not EXPLORE, database=None,
              suppress_health_check=list(HealthCheck))
    @given(st.sampled_from(keys), st.one_of(st.just(_DROP), _VALUE))
    def fuzz(key, value):
        _one_line_input_error(reader(_mutate(doc, key, value)))

    fuzz()


# ------------------------------------------------------------------ issue 36: the third audit's cases
def _files36(root: Path) -> dict[str, str]:
    d = root / "cases36"
    if not d.exists():
        d.mkdir()
        from designkit.sensor import SENSORS

        sensor = "".join(f"{k}: {v}\n" for k, v in SENSORS["paper"].to_dict().items() if not isinstance(v, dict))
        (d / "ok.yaml").write_text(sensor)
        (d / "noversion.yaml").write_text(re.sub(r"^designkit_sensor: \d+\n", "", sensor, flags=re.M))
        (d / "dup.yaml").write_text(sensor + "effusivity: 900\n")
        (d / "e308.yaml").write_text(sensor.replace("effusivity: 892.0", "effusivity: 1e308"))
        (d / "fast.yaml").write_text(sensor.replace("sample_rate_hz: 200.0", "sample_rate_hz: 1e12"))
        (d / "newline.yaml").write_text(sensor.replace("name: paper", 'name: "two\\nlines"'))
        (d / "abs.yaml").write_text(f"name: {d / 'escaped'}\nfidelity: ideal\nintervals: 4\ncontact_s: [1]\n")
        from designkit.calibration.profiles import list_profiles


        prof = list_profiles()["designkit"].read_text()
        (d / "post.yaml").write_text(re.sub(r"post_s: .*", "post_s: 1e308", prof))
        (d / "empty-profile.yaml").write_text("")
        (d / "a-file").write_text("")
    return {f"@{p.stem}": str(p) for p in d.iterdir()}


#: The cases of issue 36 that read one of the hostile files above; the others run in tests/test_hardening.py
#: (one list: tests/refusals.py).
ISSUE36_CASES = [c for c in REFUSED_IN_ONE_LINE if any(a.startswith("@") for a in c[0])]


@pytest.mark.parametrize("argv,needle", ISSUE36_CASES,
    ids=lambda v: " ".join(v)[:60] if isinstance(v, list) else None)
def test_every_case_of_issue_36_is_refused_in_one_line(argv, needle, env, run):
    files = {**env["files"], **_files36(env["root"])}
    argv = [files.get(a, a) for a in argv]
    r = run(argv)
    check(r, argv)
    if needle is None:  # no internal error is the finding; the answer may be "none in the table"
        return
    assert r.exit_code == 2, r.output
    assert needle in r.stderr, r.stderr
    assert not (env["root"] / "cases36" / "escaped").exists() and not (env["root"] / "escaped.npz").exists()


# names: whatever the text, one file name inside its folder or a one-line refusal
@settings(max_examples=20 * EXAMPLES, deadline=None, derandomize=not EXPLORE, database=None)
@given(st.text(min_size=0, max_size=120) | st.sampled_from(["..", ".", "../x", "/etc/passwd", "a/b", "a\\b",
                                                             "x" * 101, "\u00e9" * 101, "a\x00b", "a\u2028b"]))
def test_a_name_that_becomes_a_file_stays_one_file_in_its_folder(name):
    from designkit._validation import InputError, check_file_name

    try:
        got = check_file_name("name", name)
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    folder = Path("/nonexistent-root/folder")
    target = folder / f"{got}.npz"
    assert target.parent == folder and len(target.parts) == len(folder.parts) + 1
    assert got not in (".", "..") and "/" not in got and all(ch >= " " for ch in got)
    assert len(got.encode("utf-8", "surrogatepass")) <= 200


# numbers: a touch's sample count is an index or a one-line refusal, never an allocation beyond the budget
@settings(max_examples=20 * EXAMPLES, deadline=None, derandomize=not EXPLORE, database=None)
@given(st.floats(allow_nan=True, allow_infinity=True), st.floats(min_value=1e-300, allow_infinity=False))
def test_a_touch_is_within_the_budget_or_refused(contact_s, rate_hz):
    from designkit._validation import InputError
    from designkit.sensor import MAX_SAMPLES_PER_TOUCH, last_sample_index

    try:
        k = int(last_sample_index(contact_s, rate_hz))
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    assert 0 <= k < MAX_SAMPLES_PER_TOUCH


# YAML: a key given twice is refused, wherever it lies (the last won silently)
@settings(max_examples=10 * EXAMPLES, deadline=None, derandomize=not EXPLORE, database=None,
          suppress_health_check=list(HealthCheck))
@given(keys=st.lists(st.sampled_from(["effusivity", "name", "depth_m", "a", "b"]), min_size=1, max_size=6),
       nested=st.booleans())
def test_a_yaml_key_given_twice_is_refused(tmp_path_factory, keys, nested):
    from designkit._schemas import load_yaml
    from designkit._validation import InputError

    body = "".join(f"{k}: {i}\n" for i, k in enumerate(keys))
    text = ("outer:\n" + "".join("  " + line + "\n" for line in body.splitlines())) if nested else body
    p = tmp_path_factory.mktemp("dup") / "x.yaml"
    p.write_text(text)
    if len(set(keys)) < len(keys):
        with pytest.raises(InputError, match="twice"):
            load_yaml(p, "file")
    else:
        load_yaml(p, "file")


def test_zz_counts():
    """Prints what the fuzzing did (run with -s); the suite's bad-invocation count is its target."""
    print(f"\nfuzz: {STATS['invocations']} invocations, {STATS['bad invocations refused']} refused with one "
          f"Error line, statuses {dict(sorted((k, v) for k, v in STATS.items() if k.startswith('exit')))}, "
          f"{time.perf_counter() - T0:.1f} s")
    print(f"file formats: {STATS['file documents']} mutated documents, {STATS['file documents refused']} refused "
          "with one line, the rest read")
    if SLOW:
        print("slow invocations:\n  " + "\n  ".join(SLOW))
    assert STATS["invocations"] > 0
