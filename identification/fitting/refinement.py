"""More communication steps per sample where the fitted bushing responds sharply.

The forward model (``identification.forward.input_path``) chooses its steps per sample m from
the input alone: at most 0.07 rad of the signal's phase per step, so one step per 1 kHz
sample on a 10 Hz sine. That is enough for the paper's bushings, but not for one whose
Bouc-Wen block saturates sharply (n > 1 with a large beta: the force then follows the
velocity's change within a sample). Measured on the reliability benchmark's truths
(``benchmarks/bench_forward_model_at_truths.py``): at the true parameters, one step per
sample leaves up to 0.17 noise levels of rms residual on the 10 Hz sine, a chi^2 of 27.8,
more than the whole 95 % region (delta chi^2 = 23.7 for 14 parameters), so the truth falls
outside the ensemble's band by the forward model's error alone. Two steps per sample bring
that to 0.035; doubling m everywhere would cost 1.5-1.7x on every fit.

So the fit asks the candidate that decides: before its last least-squares stage (at the
best start so far) and again at the best fit, every test's m is doubled while the forces at
m and 2m differ by a chi^2 (in the test's noise units, over the samples the objective
counts) of more than ERROR_BUDGET of the region's delta chi^2, shared equally among the
tests. The difference estimates the error of m (the input path's error falls about 4x per
halving, ``tests/identification/forward/test_forward_model.py``), so the forward model's own error uses at most about
a tenth of the region. Where the fit stays above the noise floor, delta chi^2 is widened by
s^2 (``identification.fitting.ensemble``) and the budget with it: a model error far above the
forward model's is not worth finer steps. m stops at MAX_REFINED_STEPS.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from identification.forward.input_path import prepare_input
from identification.fitting.objectives import FIT_MAX_SUBSTEPS, Objective
from identification.forward.simulate import simulate_driven

ERROR_BUDGET = 0.1
"""The share of the confidence region's delta chi^2 that the forward model's error may use."""
MAX_REFINED_STEPS = 16
"""Steps per sample the refinement goes up to (the signal alone chooses at most
``input_path.MAX_STEPS_PER_SAMPLE``); m is only doubled, so it stops at the last double
within this."""


@dataclass(frozen=True)
class Refinement:
    """The outcome of one check: the objective to use (the same one if nothing changed),
    whether the steps changed, the chi^2 of m against 2m per test at the steps kept (NaN
    where 2m was not simulated: at the cap, or where it fails), and the cost of the check in
    candidate evaluations (simulations of every test)."""
    objective: Objective
    changed: bool
    error_chi2: tuple[float, ...]
    evaluations: int


def refine_steps(objective: Objective, row: np.ndarray, delta_chi2: float) -> Refinement:
    """Double each test's steps per sample while its forward-model error at the candidate
    ``row`` (one row of the objective's model's parameters) exceeds its share of ``ERROR_BUDGET * delta_chi2``
    (see the module docstring); returns the objective to use from here on.

    Where the candidate fails at m (more than FIT_MAX_SUBSTEPS substeps in a communication
    step), finer steps may run it (the substep limit is per step); where it runs at m but
    fails at 2m, m is kept. If it fails at every m, the test keeps the m it had. The tests are
    the objective's own (``Objective.rig_tests``)."""
    tests = objective.rig_tests
    candidate = np.atleast_2d(row)
    if not tests:      # a dynamic-stiffness table alone: its steps per cycle are fixed
        return Refinement(objective, False, (), 0)
    budget = ERROR_BUDGET * delta_chi2 / len(tests)
    steps, errors, work = [], [], 0
    for test, prepared in zip(tests, objective.tests):
        first = m = prepared.driven.steps_per_sample
        coarse = simulate_driven(candidate, prepared.driven, FIT_MAX_SUBSTEPS, objective.bushing)[0]
        work += m
        error = math.nan
        while 2 * m <= MAX_REFINED_STEPS:
            measurement = test.measurement
            finer = replace(prepare_input(measurement.time_s, measurement.displacement_mm,
                                          measurement.measured_velocity_mm_s, decimate_holds=True, steps=2 * m,
                                          rest_force_N=prepared.driven.rest_force_N, stride=prepared.driven.stride),
                            conditions=prepared.driven.conditions)
            fine = simulate_driven(candidate, finer, FIT_MAX_SUBSTEPS, objective.bushing)[0]
            work += 2 * m
            runs, ran = bool(np.all(np.isfinite(fine))), bool(np.all(np.isfinite(coarse)))
            if ran and not runs:
                error = math.nan
                break
            with np.errstate(over="ignore", invalid="ignore"):
                error = float(np.sum(((fine - coarse) / prepared.sigma_N) ** 2)) if ran else math.inf
            if error <= budget:
                break
            m, coarse, error = 2 * m, fine, math.nan
        if not np.all(np.isfinite(coarse)):
            m, error = first, math.nan      # it fails at every m: finer steps buy nothing
        steps.append(m)
        errors.append(error)
    changed = steps != objective.steps_per_sample
    refined = objective.with_steps(steps) if changed else objective
    # cost in evaluations of every test at its signal's m (a simulation's cost grows with m)
    evaluations = math.ceil(work / max(1, sum(objective.steps_per_sample)))
    return Refinement(refined, changed, tuple(errors), evaluations)
