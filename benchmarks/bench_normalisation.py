"""What the normalised search space is worth: fits with and without it, side by side.

    python benchmarks/bench_normalisation.py [--seeds 0 1 2]

The same data (the synthetic Table 5 sine and step tests), preset and seeds; "normalised"
fixes alpha1 = alpha2 = 1 (14 coordinates, the model's redundancy removed), "raw" also
searches log10(alpha1), log10(alpha2) (16 coordinates). Prints E3 (the noise alone gives
about 1.28e-5), the evaluations and the time of each fit.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    args = parser.parse_args()
    from identification.fit import fit
    from identification.measurements import load_measurement
    from identification.objectives import Objective, StepTest
    from identification.search_space import SearchSpace

    sine = load_measurement(REPO / "data" / "synthetic_table5_sine_2mm_10Hz.csv")
    step = load_measurement(REPO / "data" / "synthetic_table5_step_2mm_rise0.4s.csv")
    objective = Objective([sine], StepTest(step, 0.4))
    print(f"{'space':12s} {'seed':>4s} {'E3':>10s} {'evaluations':>12s} {'seconds':>8s}")
    for normalise in (True, False):
        space = SearchSpace.from_measurements([sine], normalise=normalise)
        for seed in args.seeds:
            result = fit(objective, seed=seed, progress=False, space=space)
            print(f"{'normalised' if normalise else 'raw':12s} {seed:4d} {result.objective:10.3e} "
                  f"{result.evaluations:12d} {result.seconds:8.1f}", flush=True)


if __name__ == "__main__":
    main()
