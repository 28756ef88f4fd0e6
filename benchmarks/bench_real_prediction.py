"""designkit's predictions against the real robot (issue 34): calibrate on some trial sets, compare on the others.

Run from the repository root (minutes on the shared 2 cores; be nice)::

    nice -n 10 python benchmarks/bench_real_prediction.py [--candidate NAME] [--json out.json]

The steps are :mod:`designkit_lab.reproduce.prediction`'s (the ``real-prediction`` section of
``designkit reproduce`` runs the same code): calibration as ``designkit calibrate fit`` does by
default on the first fifth of the trial sets; the exact route's predicted F1 and min-contact for the
rig as calibrated (contact from the detected onset); the real rig's own SVM F1 on the other trial
sets, cut after the detected onset; and what each part of the rig's scene changes.

Why the prediction was too optimistic (the model before this benchmark's issue-34 fix predicted
min-contact 0.148 s against the real 0.59 s): three things the simulated touches did not do as the
real ones, each measured on the calibration touches and now played by the rig's scene
(:func:`designkit.rig.rig_scene`):

- the recorder's onset: the simulated SVM saw the samples from the model's first heat flow, 0.643 s
  (129 samples) before the detected onset, which the real recognizer never sees;
- the noise: the identified model's residual (0.031 °C RMS) is not white but wanders smoothly
  (autocorrelation 0.88 at 0.25 s, 0.70 at 0.5 s; a Matern-3/2 length of 0.68 s fitted): it does
  not average away over a touch's samples as white noise of the same RMS does;
- the press: real presses vary in pace and in where the onset fires (the 24 calibration touches'
  first contact from 0.52 s before to 0.36 s after the median's, SD 0.32 s); every simulated touch
  followed the median ramp.

Alone, the correlated noise does most (worst error 0.127 -> 0.077); the onset window alone changes
little with white noise (the samples before the onset carry almost no signal) but matters with
correlated noise (they would let the SVM read the wander's level before the signal); the presses
alone lower F1 at 0.25 s only. Together: the table this prints. (That table scores each scene with
:func:`~designkit.recognition.svm.pair_f1` and 2 seeds, the headline with the exact route and 4: they
differ by Monte Carlo error, about 0.03 at 0.25 s.)

Measured and not adopted (an exploratory simulation from the identified model, each simulated touch
taking one calibration touch's own value): the touches' initial-temperature spread (Ts0 SD 0.07 °C,
object SD 0.3 °C) and heater drift (0.11 ± 0.02 °C/s) on top of the correlated residual made the
prediction too pessimistic at 0.25 s (F1 0.76-0.79 against the real 0.86): the calibration fits
them per touch, and the residual's slow part already carries touch-to-touch level changes. The
host's smoothing of the whole recording past the recognizer's cut (the real cut's last 0.25 s have
seen later samples): F1 0.814 -> 0.820 at 0.25 s, no change from 0.5 s on.

Not yet robust to the calibration touches (``--first-set 9``, results/real_prediction_sets9-12.txt):
calibrated on the original sets 9-12 instead (their residual 0.022 °C against 0.031, their presses'
first contact SD 0.21 s against 0.32 s), the same model predicts F1 up to 0.083 above the real one
and min-contact 0.25 s (0.23-0.28) against the real 0.58 s. Four trial sets (24 touches) estimate
the rig's touch-to-touch variability loosely, and the predicted interval carries only the
simulation's uncertainty, not that of the variability. (On that split the default selection among
all candidates ends with e_s unidentified; the benchmark refuses it in one line.)
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from designkit._validation import InputError
from designkit_lab.reproduce.prediction import CONTACTS_S, predict_against_real
from designkit_lab.reproduce.robot import load_real


def _default_data() -> Path:
    env = os.environ.get("DESIGNKIT_ROBOT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data" / "robot-thermal-recordings"


def rotated(data: Path, first: int, out: Path) -> Path:
    """The recordings with their trial sets renumbered cyclically so that set ``first`` comes first (symbolic
    links named by the new numbers, and their index): calibration then fits the first fifth from there on."""
    import csv

    with (data / "index.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    n = max(int(r["trial_set"]) for r in rows)
    out.mkdir(parents=True, exist_ok=True)
    with (out / "index.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, list(rows[0]))
        w.writeheader()
        for r in rows:
            k = (int(r["trial_set"]) - first) % n + 1
            name = f"set{k:02d}_{r['file'].split('_', 1)[1]}"
            if not (out / name).exists():
                (out / name).symlink_to((data / r["file"]).resolve())
            w.writerow({**r, "trial_set": str(k), "file": name})
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=_default_data())
    ap.add_argument("--candidate", default=None, help="fit this candidate only (default: choose as calibrate does)")
    ap.add_argument("--repeats", type=int, default=10, help="real F1: shuffles of the 3-fold CV")
    ap.add_argument("--trials", type=int, default=100, help="predicted F1: simulated touches per class")
    ap.add_argument("--sim-repeats", type=int, default=4, help="predicted F1: seeds per evaluation")
    ap.add_argument("--no-min-contact", action="store_true", help="skip the predicted min-contact (minutes)")
    ap.add_argument("--no-parts", action="store_true", help="skip what each part of the rig's scene changes")
    ap.add_argument("--first-set", type=int, default=1, help="calibrate from this trial set on (the sets renumbered "
                    "cyclically): another honest split of the same recordings")
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args()
    if args.first_set != 1:
        import tempfile

        args.data = rotated(args.data, args.first_set, Path(tempfile.mkdtemp()) / "rotated")
        print(f"trial sets renumbered: original set {args.first_set} is set 1 (calibration takes the first fifth)")
    try:
        touches = load_real(args.data, contact_s=max(CONTACTS_S))
        res = predict_against_real(args.data, touches, candidate=args.candidate, repeats=args.repeats,
                                   trials=args.trials, sim_repeats=args.sim_repeats, parts=not args.no_parts,
                                   min_contact=not args.no_min_contact)
    except InputError as exc:
        print(f"bench_real_prediction: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    print(f"targets: |predicted - real F1| <= 0.05 at every contact 0.25-1.5 s: worst {res['worst_error']:.3f} "
          f"({'met' if res['f1_met'] else 'missed'}); real min-contact inside the interval or within 25 %: "
          f"{res.get('min_contact_met')}; the real F1 inside the predicted F1's interval at {res['inside']} of "
          f"{len(res['rows'])} contacts (that interval is the simulation's uncertainty only); total {res['total_s']:.0f} s, load {os.getloadavg()[0]:.1f}")
    if args.json:
        args.json.write_text(json.dumps(res, indent=1, default=float))


if __name__ == "__main__":
    main()
