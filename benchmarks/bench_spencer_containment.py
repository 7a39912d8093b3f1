"""Does the proposed model contain Spencer's? The proposed model fitted to synthetic tests made
by Spencer's model, and its predictions against that noise-free truth.

    python benchmarks/bench_spencer_containment.py [--seed 0]

Fits the proposed model (default preset, with the ensemble) on data/synthetic_spencer_sine_2mm_10Hz.csv
and data/synthetic_spencer_step_2mm_rise0.4s.csv (made from data/params_spencer_fit_synthetic_table5.json,
0.5 % noise: docs/data.md), prints the fit's summary (training NRMSE against the noise), then its
errors against Spencer's noise-free forces over the paper's §5 grid and the random input
(identification.analysis.paper_verification.grid_errors), with the ensemble's band width. docs/models.md quotes it.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

from fmu_src.parameter_files import load_parameters  # noqa: E402
from identification.fitting.fit import fit  # noqa: E402
from identification.analysis.paper_verification import format_errors, grid_errors  # noqa: E402
from identification.measured.rig_tests import training_tests  # noqa: E402
import harness  # noqa: E402

DATA = REPO / "data"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    started = time.perf_counter()
    print(harness.provenance())
    tests = training_tests(sine=[DATA / "synthetic_spencer_sine_2mm_10Hz.csv"],
                           step=[DATA / "synthetic_spencer_step_2mm_rise0.4s.csv"], rise_times_s=[0.4])
    result = fit(tests, model="proposed", seed=args.seed)
    fitted = time.perf_counter() - started
    print(result.summary())
    print(f"fit: {fitted:.0f} s")
    truth = load_parameters(DATA / "params_spencer_fit_synthetic_table5.json")
    print("against the noise-free Spencer truth:")
    print(format_errors(grid_errors(result, truth, model="proposed", truth_model="spencer")))
    print(f"total {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
