"""How the servo's torque log limits the torque estimate (paper Figs. 13-14), measured.

Runs the paper's ramp (Fig. 5) on the simulated servo logged at every controller step
(0.2 ms), then builds the 1 ms torque log two ways: one controller sample per millisecond
(what the log recorded before) and the mean over each millisecond (what it records now).
Each is decimated to the appraiser's 10 ms like the position, and scored by the fit of the
best linear estimate of the torque from the measured position (least squares on the record
itself, ``clpc_paper.experiment.analysis.linear_bound``), with and without Coulomb friction.

    python benchmarks/torque_logging.py
"""

from __future__ import annotations

import numpy as np

from clpc.appraiser.decimation import decimate
from clpc_paper.experiment.analysis import linear_bound
from clpc_paper.experiment.settings import RAMP, RAMP_DURATION
from clpc_paper.plants import ServoParameters, ramp_with_saturation, simulate_servo


def main() -> None:
    base = ServoParameters()
    cases = {
        "Table 1 servo": base,
        "no Coulomb friction": base.replace(motor_coulomb_friction=0.0, load_coulomb_friction=0.0),
    }
    slow = ramp_with_saturation(
        RAMP_DURATION, 0.001, start=RAMP.start, ramp_time=RAMP.ramp_time, level=RAMP.level
    )
    print(f"{'servo':22s} {'one sample per ms':>18s} {'mean over each ms':>18s}  [fit %]")
    for name, params in cases.items():
        rec = simulate_servo(np.repeat(slow, 5), sample_time=0.0002, params=params, seed=0)
        n = rec.time.size // 5 * 5
        tau = rec.torque_command[:n].reshape(-1, 5)
        y = decimate(rec.position[:n:5], 10)
        sample = linear_bound(decimate(tau[:, 0], 10), y)
        mean = linear_bound(decimate(tau.mean(axis=1), 10), y)
        print(f"{name:22s} {sample:18.1f} {mean:18.1f}")


if __name__ == "__main__":
    main()
