"""How much a sequential decision can save, against the thermistor's time constant (issue 17).

Run from the repository root::

    python benchmarks/bench_sequential_bound.py          # about 1.5 min on one core
    python benchmarks/bench_sequential_bound.py --noise 0.5 --eps 0.01

The paper's guideline pair (35,000 vs 20,000 J s^-1/2 K^-1 m^-2, classes 80 wide,
noise 0.05 degC, dT 10 degC, 200 Hz, fixed initial conditions) on the paper's sensor
with the thermistor moved closer to the surface: ``tau = x^2 / (4 alpha_s)`` scaled by
1, 0.3, 0.1 and 0.03. For each error rate eps (the same on both classes): the shortest
fixed contact at which the ideal observer reaches it (closed form), the bound no
sequential test beats (:func:`designkit_lab.sequential_bound.optimal_test`:
backward induction, each class at its centre), Wald's SPRT's mean time under the same
recursion, and the ratio fixed / bound: the most any live decision can save.

Nothing is simulated: the figures are the recursion's (``bench_sequential.py``
checks them against simulated touches on the paper's sensor). The information of a
sample grows steeply after contact (the response is flat until about tau, then
rises), so the evidence arrives late and a sequential test cannot stop much earlier
than a fixed one; the time constant moves that ratio only slowly.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time

import numpy as np

from designkit import SENSORS
from designkit.recognition.sequential import SequentialTest
from designkit_lab.sequential_bound import optimal_test


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--eps", type=float, nargs="+", default=[0.1, 0.01], help="error rates (default 0.1 0.01)")
    p.add_argument("--tau-scale", type=float, nargs="+", default=[1.0, 0.3, 0.1, 0.03],
                   help="factors on the paper sensor's tau (default 1 0.3 0.1 0.03)")
    p.add_argument("--noise", type=float, default=0.05, help="noise sigma [degC] (default 0.05)")
    args = p.parse_args(argv)
    base = SENSORS["paper"]
    print(f"35000 vs 20000 J s^-1/2 K^-1 m^-2 (classes 80 wide), noise {args.noise:g} degC, dT 10 degC, "
          f"200 Hz; load average {os.getloadavg()[0]:.2f} at the start\n")
    print("| eps | tau [s] | fixed contact, ideal [s] | bound, any sequential test [s] | SPRT [s] | fixed / bound | CPU [s] |")
    print("|---|---|---|---|---|---|---|")
    for eps in args.eps:
        for scale in args.tau_scale:
            sensor = dataclasses.replace(base, depth_m=base.depth_m * float(np.sqrt(scale)))
            t0 = time.process_time()
            test = SequentialTest([("20000", (20000, 20080)), ("35000", (35000, 35080))], sensor,
                                  noise_c=args.noise, sensor_temp_c=35.0, ambient_temp_c=25.0, error_rate=eps,
                                  max_contact_s=6.0)
            o = optimal_test(test, points=1, step=0.05, nodes=8, iterations=12)
            fixed = test.plan.fixed_contact_s
            print(f"| {eps:g} | {sensor.tau_s:.3f} | {fixed:.3f} | {o.bound_s:.3f} | {o.sprt_time_s:.3f} | "
                  f"{fixed / o.bound_s:.2f}x | {time.process_time() - t0:.1f} |", flush=True)


if __name__ == "__main__":
    main()
