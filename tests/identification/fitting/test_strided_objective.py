"""A sine sampled far more finely than a fit needs counts every stride-th sample's force, each for
stride samples (identification.fitting.objectives: FIT_SAMPLES_PER_CYCLE): chi^2/n keeps its
scale for white noise and for a model's own error, and the fit's figures stay those of every
sample."""
import numpy as np
import pytest

from conftest import paper_force, paper_parameters
from fmu_src.model.registry import get_model
from identification.fitting.objectives import FIT_SAMPLES_PER_CYCLE, Objective, fit_stride
from identification.forward.population import parameter_matrix
from identification.measured.measurements import Measurement
from identification.measured.rig_tests import RigTest


def slow_sine(noise_N, seed=0, rate_hz=1024.0, frequency_hz=0.5, seconds=6.0):
    params = paper_parameters("table5")
    t = np.arange(0.0, seconds, 1.0 / rate_hz)
    w = 2 * np.pi * frequency_hz
    force = paper_force(params, t, lambda s: 2.0 * np.sin(w * s), lambda s: 2.0 * w * np.cos(w * s))
    force = force + np.random.default_rng(seed).normal(0.0, noise_N, t.size)
    return params, RigTest(Measurement(t, 2.0 * np.sin(w * t), force, 2.0 * w * np.cos(w * t), False, "slow.csv"),
                           "sine")


def test_a_slow_sine_at_1024_hz_counts_every_eighth_sample():
    _, test = slow_sine(10.0)
    assert fit_stride(test) == int(1024.0 / 0.5 // FIT_SAMPLES_PER_CYCLE) == 8
    assert fit_stride(RigTest(test.measurement, "random")) == 1


def test_the_misfit_keeps_its_scale_at_the_truth_and_off_it():
    params, test = slow_sine(10.0)
    objective = Objective([test], model=get_model("proposed"))
    assert objective.strides == [8] and objective.size == pytest.approx(test.measurement.time_s.size, abs=8)
    full = objective.tests[0].driven.sample_index.size * 8
    assert full == pytest.approx(test.measurement.time_s.size, abs=8)
    truth = parameter_matrix([params])
    # white noise of 10 N at the truth: chi^2/n about 1 (the estimated noise level's scatter aside)
    assert objective(truth)[0] == pytest.approx(1.0, abs=0.15)
    # a set 5 % stiffer: a smooth misfit, the same whichever samples count
    stiffer = parameter_matrix([dict(params, k0=1.05 * params["k0"])])
    every = Objective([test], model=get_model("proposed"))
    every.tests = [every.tests[0].__class__(t.name, *_every_sample(test, t)) for t in every.tests]
    every.size = test.measurement.time_s.size
    assert objective(stiffer)[0] == pytest.approx(every(stiffer)[0], rel=0.02)


def _every_sample(test, prepared):
    from identification.forward.input_path import prepare_input
    m = test.measurement
    driven = prepare_input(m.time_s, m.displacement_mm, m.measured_velocity_mm_s, decimate_holds=True)
    return driven, m.force_N[driven.sample_index], prepared.sigma_N * np.sqrt(prepared.driven.stride)
