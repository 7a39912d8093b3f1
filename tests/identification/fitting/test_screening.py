"""The screening on a prefix of each test (multistart.screen with ``prefix``, Objective.prefix,
presets.SCREENING_PREFIX): what it keeps, that a kept point's misfit is the one the whole tests
give it, bit for bit, and that on the paper's Table 5 tests it keeps the points the whole
screening would have started from."""
from pathlib import Path

import numpy as np
import pytest

from identification.fitting.engine import SerialEngine
from identification.fitting.fit import training_request
from identification.fitting.multistart import PrefixScreening, Problem, screen
from identification.fitting.presets import PRESETS, SCREENING_PREFIX, SearchSettings
from identification.fitting.search import begin
from identification.measured.kdyn_table import load_kdyn_table
from identification.measured.rig_tests import training_tests

DATA = Path(__file__).resolve().parents[3] / "data"


@pytest.fixture(scope="module")
def table5_problem():
    tests = training_tests(sine=[DATA / "synthetic_table5_sine_2mm_10Hz.csv"],
                           step=[DATA / "synthetic_table5_step_2mm_rise0.4s.csv"], rise_times_s=[0.4])
    search = begin(training_request(tests, "proposed"), SerialEngine(), False, 0.0)
    return tests, search.prepare()


def prefix_problem(tests, problem, fraction=SCREENING_PREFIX):
    return Problem(problem.objective.prefix(fraction), problem.space, "difference")


def test_the_prefix_is_the_start_of_every_test_with_its_noise_and_steps(table5_problem):
    tests, problem = table5_problem
    prefix = problem.objective.prefix(0.1)
    sine, whole = prefix.tests[0], problem.objective.tests[0]
    assert np.array_equal(sine.measured_N, whole.measured_N[:101])      # a tenth of the sine's 1001 samples
    step, whole = prefix.tests[1], problem.objective.tests[1]
    assert 0 < step.measured_N.size < whole.measured_N.size
    assert np.array_equal(step.measured_N[:400], whole.measured_N[:400])     # the ramp, where holds are not thinned
    assert [t.sigma_N for t in prefix.tests] == [t.sigma_N for t in problem.objective.tests]
    assert prefix.steps_per_sample == problem.objective.steps_per_sample


def test_screening_on_a_prefix_keeps_the_best_eighth_in_order_with_the_whole_tests_misfits(table5_problem):
    tests, problem = table5_problem
    theta, misfits = screen(problem, SerialEngine(), 256, seed=3,
                            prefix=PrefixScreening(prefix_problem(tests, problem), 1 / 8))
    all_theta, all_misfits = screen(prefix_problem(tests, problem), SerialEngine(), 256, seed=3)
    chosen = np.sort(np.argsort(all_misfits, kind="stable")[:32])
    assert theta.shape == (32, all_theta.shape[1]) and np.array_equal(theta, all_theta[chosen])
    # each candidate's simulation is its own: the same bits as the whole screening gives it
    assert np.array_equal(misfits, problem.misfit(theta))


def test_on_the_table5_tests_the_prefix_keeps_every_point_the_whole_screening_would_start_from(table5_problem):
    # the default preset's claim (presets.SCREENING_PREFIX), on 1024 points: the 16 best (the share
    # of the 128 starts of 8192) are all among the 128 kept
    tests, problem = table5_problem
    settings = PRESETS["default"]
    theta, misfits = screen(problem, SerialEngine(), 1024, seed=0,
                            prefix=PrefixScreening(prefix_problem(tests, problem), settings.prefix_kept))
    all_theta, all_misfits = screen(problem, SerialEngine(), 1024, seed=0)
    best = all_theta[np.argsort(all_misfits, kind="stable")[:16]]
    assert all(any(np.array_equal(point, kept) for kept in theta) for point in best)


def test_a_table_or_multi_axis_training_is_screened_whole():
    tests = training_tests(sine=[DATA / "synthetic_hydraulic_sine_1mm_8Hz.csv"])
    table = load_kdyn_table(DATA / "kdyn_synthetic_hydraulic_train.csv")
    problem = begin(training_request(tests, "hydraulic", kdyn=table), SerialEngine(), False, 0.0).prepare()
    assert problem.objective.prefix(0.1) is None


def test_a_prefix_setting_must_be_a_fraction():
    with pytest.raises(ValueError, match="fractions"):
        SearchSettings(100, ((4, 10),), prefix_fraction=1.5)
