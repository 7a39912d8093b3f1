"""Identification across temperatures (the ``wlf`` law): each test runs at its own temperature in
the objective, predict and compare; first contact assumes the law on a temperature matrix; the
fit recovers the textbook truth's WLF constants from sines at -20, 23 and 60 degC and predicts
0 and 80 degC and a 40 degC random road (tests/references/thermal_rubber.py, data/
generate_thermal_rubber.py)."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import DATA
from fmu_src.model.registry import get_model
from identification.fitting.objectives import Objective, nrmse
from identification.measured.measurements import load_measurement
from identification.measured.rig_tests import RigTest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "references"))
import thermal_rubber  # noqa: E402

THERMAL = "kelvin_voigt+maxwell+iwan1+wlf"
TRAINING = [DATA / f"synthetic_thermal_{name}_{t}.csv" for t in ("m20C", "p23C", "p60C")
            for name in ("sine_1mm_2Hz", "sine_0.3mm_12Hz")]
HELD_OUT = [DATA / f"synthetic_thermal_{name}.csv" for name in ("sine_1mm_5Hz_p0C", "sine_1mm_5Hz_p80C",
                                                                  "random_2mm_p40C")]


def sine_tests(paths):
    return [RigTest(load_measurement(path), kind="sine") for path in paths]


def test_the_objective_runs_each_test_at_its_own_temperature():
    """At the truth the six tests at three temperatures sit at their noise floor (chi^2/n near 1);
    the same set with every test taken at 23 degC (the file's temperature column dropped) misses
    the -20 and 60 degC tests by hundreds of noise levels."""
    from dataclasses import replace
    model = get_model(THERMAL)
    truth = np.array([model.values(model.check(thermal_rubber.project_parameters()))])
    tests = sine_tests(TRAINING)
    at_their_own = Objective(tests, model=model).test_misfits(truth)[0]
    assert np.all((0.8 < at_their_own) & (at_their_own < 1.25)), at_their_own
    blind = [RigTest(replace(t.measurement, temperature_K=None), kind="sine") for t in tests]
    at_reference = Objective(blind, model=model).test_misfits(truth)[0]
    assert at_reference[2] == pytest.approx(at_their_own[2], rel=1e-9)       # the 23 degC tests
    assert min(at_reference[[0, 1, 4, 5]]) > 100.0


def test_predict_and_simulate_take_a_tests_temperature(tmp_path):
    """simulate_measurement runs a test at its own temperature; simulate at the set's; predict at
    the one it is given."""
    from fmu_src.parameter_files import save_parameters
    from identification.analysis.predict import predict
    from identification.forward.simulate import simulate, simulate_measurement
    file = save_parameters(tmp_path / "truth.json", thermal_rubber.project_parameters(), THERMAL)
    m = load_measurement(HELD_OUT[0])
    at_zero = simulate_measurement(file, m)
    assert nrmse(at_zero, m.force_N) < 0.01
    at_set = simulate(file, m.time_s, m.displacement_mm)                   # the set's own 23 degC
    assert nrmse(at_set, m.force_N) > 0.05
    np.testing.assert_array_equal(predict(file, m.time_s, m.displacement_mm, temperature_K=m.mean_temperature_K).force_N,
                                  at_zero)


def test_first_contact_assumes_the_law_on_a_temperature_matrix():
    from identification.analysis.first_contact import first_contact
    contact = first_contact(sine_tests(TRAINING))
    assert "wlf" in contact.tokens
    assert "-20, 23, 60 degC" in contact.format()
    assert "wlf" not in first_contact(sine_tests(TRAINING[2:4])).tokens       # one temperature


@pytest.mark.slow
def test_a_fit_across_three_temperatures_recovers_the_law_and_predicts_the_temperatures_it_never_saw():
    from identification.fitting.fit import fit
    result = fit(sine_tests(TRAINING), model=THERMAL, seed=1, progress=False)
    assert result.at_floor
    p = result.parameters.parameters
    truth = thermal_rubber.TRUTH
    for name in ("wlf_c1", "wlf_c2", "elastic_per_K", "friction_per_K"):
        members = [member[name] for member in result.ensemble]
        low, high = min(members), max(members)
        assert low <= truth[name] <= high or abs(p[name] - truth[name]) < 0.03 * abs(truth[name]), (name, low, high)
    for path in HELD_OUT:
        from identification.forward.simulate import simulate_measurement
        m = load_measurement(path)
        predicted = simulate_measurement(p, m, model=THERMAL)
        assert nrmse(predicted, m.force_N) < 0.02, path.name
