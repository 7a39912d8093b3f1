"""The fit's refinement of the forward model's steps per sample, against scipy's Radau on the
paper's equations (tests/conftest.py)."""
import functools

import numpy as np
import pytest
from scipy.stats import chi2

from conftest import paper_force, paper_parameters
from identification.forward.population import parameter_matrix
from identification.measured.measurements import Measurement
from identification.measured.noise import NoiseEstimate
from identification.fitting.objectives import Objective
from identification.measured.signals import sample_times
from identification.fitting.ensemble import misfit_threshold
from identification.fitting.refinement import MAX_REFINED_STEPS, refine_steps
from identification.measured.rig_tests import RigTest

SHARPLY_SATURATING = {
    # the reliability benchmark's "random 7" (benchmarks/bench_fit_reliability.py, truths seed 1):
    # block 2 saturates within a fraction of a sample (beta2 = 290, n2 = 0.52)
    "c0": 146.5025, "k0": 1519.0631, "c1": 260450.4798, "k1": 9610.6586, "c2": 4.8012, "k2": 23.1713,
    "alpha1": 1.0, "alpha2": 1.0, "beta1": 5.2461, "beta2": 290.0705, "gamma1": 3.8024, "gamma2": -217.9707,
    "n1": 0.9652, "n2": 0.5153, "A1": 14777.8322, "A2": 10347.9706}
DELTA_CHI2 = chi2.ppf(0.95, 14)   # the ensemble's region at the noise floor, 14 parameters


@functools.cache
def radau_sine(items, duration_s, frequency_hz, amplitude_mm):
    """The paper's equations under a 1 kHz sine, by scipy's Radau (computed once per set)."""
    omega = 2 * np.pi * frequency_hz
    t = sample_times(duration_s, 1000.0)
    force = paper_force(dict(items), t, lambda s: amplitude_mm * np.sin(omega * s),
                        lambda s: amplitude_mm * omega * np.cos(omega * s))
    force.flags.writeable = False
    return t, amplitude_mm * np.sin(omega * t), force


def sine_test(params, duration_s=0.3, frequency_hz=10.0, amplitude_mm=2.0):
    """A noise-free 1 kHz sine test whose force is Radau's on the paper's equations, with the
    noise level 1 % of its rms force; returns (tests, objective)."""
    t, x, force = radau_sine(tuple(sorted(params.items())), duration_s, frequency_hz, amplitude_mm)
    tests = [RigTest(Measurement(t, x, force, np.gradient(x, t), velocity_derived=True, source="sine.csv"), "sine")]
    rms = float(np.sqrt(np.mean(force ** 2)))
    return tests, Objective(tests, [NoiseEstimate(0.01 * rms, rms)])


def rms_residual_in_noise_levels(objective, params):
    residuals = objective.residual_matrix(parameter_matrix([params]))[0]
    return float(np.sqrt(np.sum(residuals ** 2)))   # residuals are r/sigma/sqrt(n)


def test_a_sharply_saturating_bushing_gets_finer_steps_and_then_meets_the_forward_model_target():
    tests, objective = sine_test(SHARPLY_SATURATING)
    assert objective.steps_per_sample == [1]                                  # the signal alone asks for one
    assert rms_residual_in_noise_levels(objective, SHARPLY_SATURATING) > 0.1  # measured 0.17: not enough
    refinement = refine_steps(objective, parameter_matrix([SHARPLY_SATURATING]), DELTA_CHI2)
    assert refinement.changed and refinement.objective.steps_per_sample == [2]
    # the target for the forward model at the truth: <= 0.1 of a 1 % noise level (measured 0.036)
    assert rms_residual_in_noise_levels(refinement.objective, SHARPLY_SATURATING) <= 0.1


@pytest.mark.parametrize("table", ["table2", "table5"])
def test_the_papers_bushings_keep_one_step_per_sample(table):
    params = paper_parameters(table)
    tests, objective = sine_test(params)
    refinement = refine_steps(objective, parameter_matrix([params]), DELTA_CHI2)
    assert not refinement.changed and refinement.objective is objective
    assert rms_residual_in_noise_levels(objective, params) <= 0.1


def test_far_above_the_floor_the_widened_region_does_not_ask_for_finer_steps():
    # delta chi^2 as the fit computes it: at the floor it asks for finer steps; for a fit at
    # chi^2/n = 10 (NRMSE about 3x the noise) s^2 = 10 widens the region and the budget
    tests, objective = sine_test(SHARPLY_SATURATING)
    core = parameter_matrix([SHARPLY_SATURATING])
    n = objective.size
    assert refine_steps(objective, core, misfit_threshold(1.0, n, 14) * n).changed
    assert not refine_steps(objective, core, misfit_threshold(10.0, n, 14) * n).changed


def test_steps_are_only_doubled_and_never_beyond_the_cap():
    tests, _ = sine_test(SHARPLY_SATURATING)
    for start, most in ((3, 12), (12, 12), (5, 10)):
        objective = Objective(tests, None, [start])
        refinement = refine_steps(objective, parameter_matrix([SHARPLY_SATURATING]), 0.0)  # no budget at all
        assert refinement.objective.steps_per_sample == [most] and most <= MAX_REFINED_STEPS
