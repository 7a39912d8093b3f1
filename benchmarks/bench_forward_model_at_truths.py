"""How far is the fit's forward model from the truth, at the truth? (the reliability benchmark's truths)

    python benchmarks/bench_forward_model_at_truths.py [--truths 12] [--truths-file T.json]

For each truth of ``bench_fit_reliability.py`` (the same truths file), the paper's two
training tests are made noise-free from the continuous-time truth (16 substeps per 1 kHz
sample, as that benchmark does) and scored by the fit's objective at the true parameters,
with the 1 % noise level the benchmark adds. Printed per truth, for the steps per sample the
signal alone chooses and for the fit's refinement of them at the truth
(``identification.fitting.refinement``, with the region's delta chi^2 at the floor): the steps per
sample of the sine and the step, the sine's rms residual in noise levels, and chi^2 of the
sine, of the step and in all. A perfect forward model scores 0.
The total is how far above a perfect model the truth starts in every fit of its data: where it
approaches the ensemble's threshold (delta chi^2 = chi2.ppf(0.95, 14) = 23.7), the truth can
fall outside the 95 % region and its band. A truth whose simulation needs more than the fit's
FIT_MAX_SUBSTEPS substeps in a sample counts as failed there (printed as such; the fit then
sees it as worse than any candidate that runs).
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

from bench_fit_reliability import NOISE, TRAINING, load_or_draw_truths, truth_forces  # noqa: E402
from identification.forward.population import parameter_matrix  # noqa: E402
from identification.fitting.ensemble import misfit_threshold  # noqa: E402
from identification.measured.measurements import Measurement  # noqa: E402
from identification.measured.noise import NoiseEstimate  # noqa: E402
from identification.fitting.objectives import FAILED_RESIDUAL, FIT_MAX_SUBSTEPS, Objective  # noqa: E402
from identification.fitting.refinement import refine_steps  # noqa: E402
from identification.measured.rig_tests import RigTest  # noqa: E402


def chi2_at_truth(truth: dict) -> list[tuple]:
    """Per forward model (the signal's choice of steps per sample, then the fit's refinement of
    it at the truth): (steps per sample of each test, sine rms residual / noise, chi^2 of the
    sine, chi^2 of the step, whether the simulation failed: the objective's FAILED_RESIDUAL
    noise levels from there on) on noise-free data."""
    tests, levels = [], []
    for kind, protocol, rise in TRAINING:
        t, x, _, force = truth_forces(truth, protocol)
        tests.append(RigTest(Measurement(t, x, force, np.gradient(x, t), velocity_derived=True, source=kind),
                             kind, rise))
        rms = float(np.sqrt(np.mean(force ** 2)))
        levels.append(NoiseEstimate(NOISE * rms, rms))
    signal_chosen = Objective(tests, levels)
    core = parameter_matrix([truth])
    refined = refine_steps(signal_chosen, core, misfit_threshold(1.0, 1, 14)).objective
    rows = []
    for objective in (signal_chosen, refined):
        residuals = objective.residual_matrix(core)[0] * np.sqrt(objective.size)  # noise units
        sine_size = objective.tests[0].measured_N.size
        sine, step = residuals[:sine_size], residuals[sine_size:]
        failed = bool(np.any(np.isclose(np.abs(residuals), FAILED_RESIDUAL)))
        rows.append((objective.steps_per_sample, float(np.sqrt(np.mean(sine ** 2))), float(np.sum(sine ** 2)),
                     float(np.sum(step ** 2)), failed))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--truths", type=int, default=12)
    parser.add_argument("--truths-file", type=Path,
                        help="the reliability benchmark's truths file (if it does not exist: drawn and written)")
    args = parser.parse_args()
    drawn = load_or_draw_truths(args.truths, args.truths_file)
    threshold = misfit_threshold(1.0, 1, 14)   # delta chi^2 of 14 parameters at the floor, per 1 residual
    print(f"{'truth':10s} {'forward model':14s} {'steps':>6s} {'sine rms / noise':>17s} {'chi2 sine':>10s} "
          f"{'chi2 step':>10s} {'chi2 total':>11s}")
    for name, truth in drawn:
        with np.errstate(all="ignore"):
            rows = chi2_at_truth(truth)
        for label, (steps, rms, sine, step, failed) in zip(("signal's m", "refined"), rows):
            print(f"{name:10s} {label:14s} {'/'.join(map(str, steps)):>6s} {rms:17.3f} {sine:10.2f} {step:10.2f} "
                  f"{sine + step:11.2f}"
                  + (f"   (fails: more than {FIT_MAX_SUBSTEPS} substeps in a sample)" if failed else ""))
    print(f"\nthe ensemble's threshold: delta chi^2 = {threshold:.1f} (95 %, 14 parameters)")


if __name__ == "__main__":
    main()
