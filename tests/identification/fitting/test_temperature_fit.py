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
    """simulate_record runs a test at its own temperature; simulate at the set's; predict at
    the one it is given."""
    from fmu_src.parameter_files import save_parameters
    from identification.analysis.predict import predict
    from identification.forward.simulate import simulate, simulate_record
    file = save_parameters(tmp_path / "truth.json", thermal_rubber.project_parameters(), THERMAL)
    m = load_measurement(HELD_OUT[0])
    at_zero = simulate_record(file, m)
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
        from identification.forward.simulate import simulate_record
        m = load_measurement(path)
        predicted = simulate_record(p, m, model=THERMAL)
        assert nrmse(predicted, m.force_N) < 0.02, path.name


def _first_harmonic(amplitude_mm, frequency_hz, temperature_K, cycles, steps=64):
    """|K*| [N/mm] and the loss angle [deg] of the textbook bushing's last of ``cycles`` cycles from
    rest, the first harmonic by the rectangle rule over its ``steps`` points."""
    n = steps * cycles
    t = np.arange(n + 1) / (steps * frequency_hz)
    x = amplitude_mm * np.sin(2 * np.pi * frequency_hz * t)
    v = amplitude_mm * 2 * np.pi * frequency_hz * np.cos(2 * np.pi * frequency_hz * t)
    force = thermal_rubber.force(thermal_rubber.TRUTH, temperature_K, t, x, v)
    phase = 2 * np.pi * frequency_hz * t[n - steps:n]
    b, a = 2 * np.mean(force[n - steps:n] * np.sin(phase)), 2 * np.mean(force[n - steps:n] * np.cos(phase))
    return abs(complex(b, a)) / amplitude_mm, np.degrees(np.arctan2(a, b))


def test_a_data_sheet_runs_each_row_at_its_own_temperature():
    from identification.fitting.objectives import PreparedTable
    from identification.measured.kdyn_table import KdynTable
    model = get_model(THERMAL)
    amplitude, frequency = np.array([0.5, 0.5, 0.5, 1.0]), np.array([2.0, 10.0, 10.0, 5.0])
    temperature = np.array([253.15, 253.15, 333.15, 296.15])
    table = KdynTable(amplitude, frequency, np.zeros(4), np.ones(4), np.full(4, 10.0), np.ones(4), "sheet", temperature)
    prepared = PreparedTable.of(table, model)
    truth = np.array([model.values(model.check(thermal_rubber.project_parameters(temperature_K=200.0)))])
    kdyn, angle = prepared.stiffness(truth, model)
    for i in range(4):
        want = _first_harmonic(amplitude[i], frequency[i], temperature[i], int(prepared.cycles[i]))
        assert kdyn[0, i] == pytest.approx(want[0], rel=1e-9) and angle[0, i] == pytest.approx(want[1], abs=1e-9)
    assert kdyn[0, 1] > 2 * kdyn[0, 2]             # -20 degC against 60 degC, the same sine


def test_a_data_sheets_temperature_column_is_read_and_checked(tmp_path):
    from identification.errors import IdentificationError
    from identification.measured.kdyn_table import load_kdyn_table
    path = tmp_path / "sheet.csv"
    path.write_text("amplitude_mm,frequency_hz,kdyn_N_per_mm,loss_angle_deg,temperature_C\n"
                    "0.5,10,900,25,-20\n0.5,10,400,19,60\n1,5,370,33,23\n")
    table = load_kdyn_table(path)
    np.testing.assert_allclose(table.temperature_K, [253.15, 333.15, 296.15])
    assert [index.tolist() for _, index in table.subset(np.array([True, True, False])).temperature_groups()] == [[0], [1]]
    path.write_text("amplitude_mm,frequency_hz,kdyn_N_per_mm,loss_angle_deg,temperature_C\n0.5,10,900,25,-20\n"
                    "0.5,10,910,25,-20\n")
    with pytest.raises(IdentificationError, match=r"line 3: the case 0.5 mm, 10 Hz, preload 0 mm at -20 C is given "
                                                  r"twice \(also line 2\)"):
        load_kdyn_table(path)
    path.write_text("amplitude_mm,frequency_hz,kdyn_N_per_mm,loss_angle_deg,temperature\n0.5,10,900,25,-20\n")
    with pytest.raises(IdentificationError, match="temperature_K, temperature_C"):
        load_kdyn_table(path)
    path.write_text("amplitude_mm,frequency_hz,kdyn_N_per_mm,loss_angle_deg,temperature_C\n0.5,10,900,25,-300\n")
    with pytest.raises(IdentificationError, match="absolute zero"):
        load_kdyn_table(path)


def test_a_data_sheet_over_temperature_is_written_read_back_and_refused_without_a_law(tmp_path):
    from fmu_src.parameter_files import save_parameters
    from identification.errors import IdentificationError
    from identification.forward.dynamic_stiffness import characterise_at_temperatures, write_temperature_sheet
    from identification.measured.kdyn_table import load_kdyn_table
    file = save_parameters(tmp_path / "truth.json", thermal_rubber.project_parameters(), THERMAL)
    tables = characterise_at_temperatures(file, [253.15, 353.15], [0.5], [2.0, 10.0])
    cold, warm = (table for _, table in tables)
    assert np.all(cold.kdyn_N_per_mm > warm.kdyn_N_per_mm) and np.all(cold.loss_angle_deg > warm.loss_angle_deg)
    sheet = load_kdyn_table(write_temperature_sheet(tmp_path / "sheet.csv", tables))
    np.testing.assert_array_equal(sheet.temperature_K, [253.15, 253.15, 353.15, 353.15])
    np.testing.assert_allclose(sheet.kdyn_N_per_mm, np.concatenate([cold.kdyn_N_per_mm, warm.kdyn_N_per_mm]),
                               rtol=1e-9)
    with pytest.raises(IdentificationError, match="-150 degC: .*temperature = 123.15 \\[K\\] must be in"):
        characterise_at_temperatures(file, [123.15], [0.5], [2.0])
    plain = save_parameters(tmp_path / "plain.json", dict(k=100.0, c=1.0, preload=0.0), "kelvin_voigt")
    with pytest.raises(IdentificationError, match="the kelvin_voigt model has no temperature law"):
        characterise_at_temperatures(plain, [253.15], [0.5], [2.0])


def test_report_runs_each_file_at_its_temperature(tmp_path):
    from fmu_src.parameter_files import save_parameters
    from identification.analysis.paper_verification import data_errors
    file = save_parameters(tmp_path / "truth.json", thermal_rubber.project_parameters(), THERMAL)
    rows = data_errors(file, [load_measurement(path) for path in HELD_OUT[:2]])
    assert all(case.nrmse < 0.013 for case, _ in rows), [case.nrmse for case, _ in rows]


def test_a_test_whose_temperature_the_law_refuses_is_an_error_naming_it():
    from dataclasses import replace
    from fmu_src.model.parameter_specs import ParameterError
    from identification.forward.simulate import simulate_record
    [test] = sine_tests(TRAINING[:1])
    hot = RigTest(replace(test.measurement, temperature_K=np.full(len(test.measurement), 600.0)), kind="sine")
    with pytest.raises(ParameterError, match=r"synthetic_thermal_sine_1mm_2Hz_m20C.csv: its temperature_K sets the "
                                             r"kelvin_voigt\+maxwell\+iwan1\+wlf model's temperature = 600.0 \[K\]"):
        Objective([hot], model=get_model(THERMAL))
    with pytest.raises(ParameterError, match=r"temperature = 600.0 \[K\] must be in"):
        simulate_record(thermal_rubber.project_parameters(), hot.measurement, model=THERMAL)


def test_a_law_constant_that_moves_nothing_is_held():
    """friction_per_K in a model without a sliding level, C1 and C2 in one without a dashpot."""
    search = get_model("proposed+wlf").search
    assert "friction_per_K" not in {c.parameter for c in search.coordinates}
    assert ("friction_per_K", 0.0) in search.held and "wlf_c1" in {c.parameter for c in search.coordinates}
    fractional = {c.parameter for c in get_model("fractional+wlf").search.coordinates}
    assert not {"wlf_c1", "wlf_c2"} & fractional and "friction_per_K" in fractional
    assert {"wlf_c1", "wlf_c2", "elastic_per_K", "friction_per_K"} <= {c.parameter for c in
                                                                      get_model(THERMAL).search.coordinates}


def test_fit_many_takes_a_model_with_options_and_names_a_bad_one(tmp_path):
    import json
    import shutil
    from identification.fitting.fleet import fit_many
    for name, model in (("bad", "proposed+stops"),):
        folder = tmp_path / "fleet" / name
        folder.mkdir(parents=True)
        shutil.copy(TRAINING[0], folder)
        (folder / "tests.json").write_text(json.dumps({"sine": [TRAINING[0].name], "model": model}))
    [row] = fit_many(tmp_path / "fleet", tmp_path / "out", ensemble=False, workers=1)
    assert "unknown model option 'stops'" in row.error and "wlf, arrhenius and heating" in row.error
