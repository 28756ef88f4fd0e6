#!/usr/bin/env python3
"""A robot's touch loop that decides how long to keep contact, from an exported designkit table.

Needs only the Python standard library and a table module exported by designkit:

    designkit export --table svm-fine --format python --e-min 200 --e-max 30000 --out thermal_table.py
    python3 robot_loop.py                  # human-readable
    python3 robot_loop.py --json           # one JSON object per object (for logs and tests)

A sorting robot with a heated thermal tactile sensor picks objects off a conveyor.
For each object, vision narrows the material down to a few candidates; just before
the touch the robot reads its sensor's and the object's temperatures (dT), and it
knows its noise from calibration. The touch must separate every pair of
candidates, so the contact time is the largest over the pairs of the long end of
``min_contact_interval`` (designkit min-contact's 90 % interval: the answer is an
estimate, and the robot plans on the end that errs long), plus a safety margin,
rounded up to the control period. When no contact time
the gripper allows is enough at this dT, the robot heats the sensor further first
(a larger dT means a smaller sigma/dT); if even the hottest allowed sensor is not
enough, the object goes to a human.

The table module is exported with the full sigma/dT axis (no --noise/--delta-t),
because dT changes from touch to touch; --e-min/--e-max keep only the effusivities
of the candidate materials.
"""

from __future__ import annotations

import argparse
import importlib.util
import itertools
import json
import math
import sys
from pathlib import Path

# Identified effusivities of the paper's materials [J s^-1/2 K^-1 m^-2] (Bai et al., appendix).
MATERIALS = {
    "wood": 400.95,
    "acrylic": 635.49,
    "porcelain": 1276.59,
    "glass": 1433.31,
    "granite": 2749.87,
    "stainless steel": 10184.17,
    "aluminium": 17530.03,
    "copper": 23049.18,
}

# What arrives: a name, what vision says it may be, and the temperatures read just before the
# touch: sensor thermistor and object (ambient) [degC].
OBJECTS = [
    ("pan handle", ("aluminium", "stainless steel"), 34.9, 25.0),
    ("kitchen tile", ("porcelain", "granite", "glass"), 35.1, 25.0),
    ("shelf board", ("wood", "acrylic"), 30.2, 25.0),
    ("busbar", ("copper", "aluminium"), 35.0, 25.0),
    ("bottle", ("glass", "porcelain"), 27.0, 25.0),  # the sensor has not warmed up again yet
]

NOISE_C = 0.05  # noise sigma per sample [degC], from the sensor's calibration
MAX_CONTACT_S = 4.0  # longest touch the gripper allows [s]
MAX_DELTA_T_C = 15.0  # hottest the heater may run the sensor above the object [degC]
CONTROL_PERIOD_S = 0.01  # the controller's period: contact times are multiples of it


def load_table(path: Path):
    """Import the exported table module from its file (it needs nothing but the standard library)."""
    spec = importlib.util.spec_from_file_location("thermal_table", path)
    if spec is None or not path.is_file():
        sys.exit(f"no table module at {path}: export one with\n  designkit export --table svm-fine "
                 f"--format python --e-min 200 --e-max 30000 --out {path}")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def contact_needed(table, candidates, noise_c: float, delta_t_c: float):
    """Per pair of candidates, the shortest contact time [s] and its 90 % interval (None: none in the table
    suffices; an interval end None: open).

    Raises the table's OutsideTable when the scene lies outside the table's grid.
    """
    pairs = []
    for a, b in itertools.combinations(candidates, 2):
        t, low, high = table.min_contact_interval(MATERIALS[a], MATERIALS[b], noise_c, delta_t_c)
        pairs.append({"a": a, "b": b, "e_a": MATERIALS[a], "e_b": MATERIALS[b], "min_contact_s": t,
                      "interval_s": [low, high]})
    return pairs


def planned(pair) -> float:
    """The contact a pair asks for [s]: its interval's long end (its value where the interval is open)."""
    high = pair["interval_s"][1]
    return high if high is not None else pair["min_contact_s"]


def plan(table, candidates, noise_c: float, delta_t_c: float, margin: float) -> dict:
    """What to do with one object: touch (for how long), heat first (to which dT), or hand over."""
    def attempt(dt):
        try:
            pairs = contact_needed(table, candidates, noise_c, dt)
        except table.OutsideTable as exc:
            return None, None, str(exc)
        if any(p["min_contact_s"] is None for p in pairs):
            return pairs, None, "no tabulated contact time separates every pair"
        times = [planned(p) for p in pairs]
        periods = math.ceil(max(times) * (1 + margin) / CONTROL_PERIOD_S - 1e-9)
        contact = round(periods * CONTROL_PERIOD_S, 6)
        if contact > MAX_CONTACT_S:
            return pairs, None, f"needs {contact:.2f} s, more than the gripper's {MAX_CONTACT_S:g} s"
        return pairs, contact, ""

    pairs, contact, why = attempt(delta_t_c)
    out = {"noise_c": noise_c, "delta_t_c": delta_t_c, "pairs": pairs, "why": why}
    if contact is not None:
        return {**out, "action": "touch", "contact_s": contact}
    dt = math.floor(delta_t_c) + 1.0
    while dt <= MAX_DELTA_T_C:  # heat the sensor in 1 degC steps and ask the table again
        hot_pairs, contact, _ = attempt(dt)
        if contact is not None:
            return {**out, "action": "heat", "heat_to_delta_t_c": dt, "contact_s": contact, "pairs_hot": hot_pairs}
        dt += 1.0
    return {**out, "action": "human", "contact_s": None}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", type=Path, default=Path(__file__).with_name("thermal_table.py"),
                        help="exported table module (designkit export --format python)")
    parser.add_argument("--noise", type=float, default=NOISE_C, help="noise sigma per sample [degC]")
    parser.add_argument("--margin", type=float, default=0.1, help="safety margin on the contact time (0.1 = 10 %%)")
    parser.add_argument("--json", action="store_true", help="one JSON object per line")
    args = parser.parse_args(argv)
    table = load_table(args.table)
    if not args.json:
        print(f"table {table.SOURCE_TABLE} ({table.FIDELITY}, F1 >= {table.THRESHOLD:g}), {table.SOURCE_HASH}")
    for name, candidates, sensor_c, object_c in OBJECTS:
        decision = plan(table, candidates, args.noise, sensor_c - object_c, args.margin)
        decision = {"object": name, "candidates": list(candidates), **decision}
        if args.json:
            print(json.dumps(decision))
            continue
        print(f"{name}: {' or '.join(candidates)}?  dT {decision['delta_t_c']:.1f} degC, noise {args.noise:g} degC")
        for p in decision["pairs"] or []:
            t = p["min_contact_s"]
            low, high = p["interval_s"]
            span = f" (90% interval {low:.2f} to {high:.2f} s)" if low is not None and high is not None else ""
            print(f"    {p['a']} vs {p['b']}: " + (f"{t:.2f} s{span}" if t is not None else "not separable at this dT"))
        if decision["action"] == "touch":
            print(f"  -> touch for {decision['contact_s']:.2f} s")
        elif decision["action"] == "heat":
            print(f"  -> {decision['why']}: heat the sensor to dT {decision['heat_to_delta_t_c']:g} degC, "
                  f"then touch for {decision['contact_s']:.2f} s")
        else:
            print(f"  -> {decision['why']}; even at dT {MAX_DELTA_T_C:g} degC: hand it to a human")
    return 0


if __name__ == "__main__":
    sys.exit(main())
