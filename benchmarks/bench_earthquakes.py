"""The real friction damper's earthquakes (issue 63): a model fitted to the two DBE records, scored
on all four, started at rest holding the force each record holds (the default) and virgin.

    python benchmarks/bench_earthquakes.py [--models LIST] [--rate HZ] [--workers N] [--seed S]

The records of ``data/brfd/`` (36 lb band tension) at 1024 Hz, or decimated to ``--rate`` (every
k-th sample: a rate-independent model's force depends on the path, which 256 Hz still samples
finely at these 1-5 Hz motions). Each model is fitted with the default preset to
``earthquake_KocaeliDBE`` and ``earthquake_ImperialValleyDBE`` as random-input tests, without an
ensemble; then simulated on every record at 1024 Hz with ``rest_force_N`` the record's held force
(``offsets.held_force``) and with none (virgin), and the NRMSE printed, the training records marked;
with ``--ensemble`` the fit samples its ensemble, and the share of each record's samples inside its
band (``predict``'s envelope widened by the record's noise level, and ``predict``'s likely band: the
envelope widened by 1.96 times the fit's rms misfit on its training records) is printed.
"""
from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

import harness  # noqa: F401  (the repository on the path)

REPO = Path(__file__).resolve().parents[1]
RECORDS = ("KocaeliDBE", "ImperialValleyDBE", "KocaeliMCE", "ImperialValleyMCE")
TRAINING = RECORDS[:2]


def main() -> None:
    from identification import fit, simulate
    from identification.fitting.objectives import nrmse
    from identification.measured.measurements import Measurement, load_measurement
    from identification.measured.offsets import held_force
    from identification.measured.rig_tests import RigTest
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", default="asymmetric_bouc_wen")
    parser.add_argument("--rate", type=float, default=1024.0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--ensemble", action="store_true",
                        help="sample each fit's ensemble and print the share of each record's samples its band "
                             "(widened by the record's noise level) covers")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    records = {name: load_measurement(REPO / "data" / "brfd" / f"earthquake_{name}.csv.gz") for name in RECORDS}
    step = max(1, int(round(1024.0 / args.rate)))
    training = []
    for name in TRAINING:
        m = records[name]
        cut = slice(None, None, step)
        training.append(RigTest(Measurement(m.time_s[cut], m.displacement_mm[cut], m.force_N[cut],
                                            m.velocity_mm_s[cut], False, m.source)))
    for name, m in records.items():
        print(f"{name}: held force at rest {held_force(m):+.1f} N", flush=True)
    for model in args.models.split(","):
        began = time.perf_counter()
        result = fit(training, model=model, ensemble=args.ensemble, progress=False, workers=args.workers,
                     seed=args.seed)
        seconds = time.perf_counter() - began
        cells = []
        for name, m in records.items():
            scores = [nrmse(simulate(result, m.time_s, m.displacement_mm, m.measured_velocity_mm_s, rest_force_N=rest),
                            m.force_N) for rest in (held_force(m), np.nan)]
            cells.append(f"{name}{' (training)' if name in TRAINING else ''} {scores[0]:.1%} (virgin {scores[1]:.1%})")
        print(f"{model} fitted on the DBE pair at {1024.0 / step:g} Hz in {seconds:.0f} s: " + "; ".join(cells),
              flush=True)
        if args.ensemble:
            from identification import predict
            from identification.analysis.predict import MISFIT_WIDENING
            from identification.measured.noise import estimate_noise
            bands = {name: predict(result, m.time_s, m.displacement_mm, m.measured_velocity_mm_s,
                                   rest_force_N=held_force(m)) for name, m in records.items()}
            envelope, likely = [], []
            for name, m in records.items():
                noise = estimate_noise(m.force_N).sigma_N
                band, force = bands[name], m.force_N
                inside = (force >= band.lower_N - noise) & (force <= band.upper_N + noise)
                envelope.append(f"{name} {np.mean(inside):.1%}")
                inside = (force >= band.likely_lower_N) & (force <= band.likely_upper_N)
                likely.append(f"{name} {np.mean(inside):.1%}")
            print(f"  its ensemble of {len(result.ensemble)} sets covers the measured force (the band widened by "
                  f"the noise level) at: " + "; ".join(envelope), flush=True)
            print(f"  predict's likely band (the envelope widened by {MISFIT_WIDENING} x the fit's training misfit, "
                  f"{bands[TRAINING[0]].misfit_N:.0f} N rms) covers it at: " + "; ".join(likely), flush=True)


if __name__ == "__main__":
    main()
