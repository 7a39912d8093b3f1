"""A synthetic band brake with backlash (issue 63's synthetic device): models fitted to its sine
matrix, scored on what the rig never played.

    python benchmarks/bench_band_brake.py [--models LIST] [--workers N] [--seed S]

The files are data/synthetic_band_* (``data/generate_band_brake.py``; the truth typed in
``tests/references/band_brake.py``): six training sines (1, 2.5 and 4 mm at 0.5 and 2 Hz) and
two held out, a 3 mm 1 Hz sine and a 20 s earthquake-like history. Each model is fitted with the
default preset to the six sines, without an ensemble; the NRMSE of each held-out file is printed
beside the training figures and the fit's time. The first line is the floor: the truth's own
laws, walked on the samples alone, against the noisy files.
"""
from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import harness  # noqa: F401  (the repository on the path)

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "references"))
TRAINING = tuple(f"sine_{a}mm_{f}Hz" for a in ("1", "2.5", "4") for f in ("0.5", "2"))
HELD_OUT = ("sine_3mm_1Hz", "earthquake_4mm")


def main() -> None:
    import band_brake
    from identification import fit, simulate
    from identification.fitting.objectives import nrmse
    from identification.measured.measurements import load_measurement
    from identification.measured.rig_tests import RigTest
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", default="kelvin_voigt+band,asymmetric_bouc_wen")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    records = {name: load_measurement(REPO / "data" / f"synthetic_band_{name}.csv") for name in TRAINING + HELD_OUT}
    floor = []
    for name, m in records.items():
        x = m.displacement_mm
        truth = band_brake.force(band_brake.PARAMETERS, m.time_s,
                                 lambda s: (np.interp(s, m.time_s, x), np.interp(s, m.time_s, m.velocity_mm_s)),
                                 substeps=1)
        floor.append(f"{name} {nrmse(truth, m.force_N):.2%}")
    print("the truth's laws against the noisy files (the floor): " + "; ".join(floor), flush=True)
    for model in args.models.split(","):
        began = time.perf_counter()
        result = fit([RigTest(records[name]) for name in TRAINING], model=model, ensemble=False, progress=False,
                     workers=args.workers, seed=args.seed)
        seconds = time.perf_counter() - began
        cells = []
        for name, m in records.items():
            score = nrmse(simulate(result, m.time_s, m.displacement_mm, m.measured_velocity_mm_s), m.force_N)
            cells.append(f"{name}{'' if name in TRAINING else ' (held out)'} {score:.2%}")
        print(f"{model} fitted on the six sines in {seconds:.0f} s: " + "; ".join(cells), flush=True)
        if model.startswith("kelvin_voigt+band"):
            fitted = {k: v for k, v in result.parameters.parameters.items() if k.startswith("band_") or k in ("k", "c", "preload")}
            print("  fitted: " + ", ".join(f"{k} {v:.4g}" for k, v in fitted.items()), flush=True)


if __name__ == "__main__":
    main()
