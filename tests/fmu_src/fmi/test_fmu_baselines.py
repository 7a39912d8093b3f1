"""The models other than the paper's as FMUs: the FMU issue's checks (validation, units, equal to
the model, bad values on the pythonfmu and the native FMU, state) for each, and every model side by
side in one process."""
import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from fmu_src.fmi.fmu_inputs import default_parameter_file
from fmu_harness import BushingFmu, simulate_with_fmpy
from fmu_src.model.registry import MODELS
from fmu_src.parameter_files import load_parameters
from identification.forward.population import simulate_model_held
from identification.measured.signals import Sine, sample_times
from paper_units import PARAMETER_UNITS, fmu_parameter_units

BASELINES = tuple(name for name in MODELS if name != "proposed")
MM = 1e-3
BAD_VALUES = [  # model, parameter, value, what the message says after "<name> = <value> " (both FMUs)
    ("spencer", "c1", 0.0, "[N.s/mm] must be > 0"),
    ("single_bouc_wen", "n", -1.0, "[1] must be > 0"),
    ("kelvin_voigt", "k", float("nan"), "[N/mm]"),
    ("berg", "x2", 0.0, "[mm] must be > 0"),
    ("berg", "Ff_max", -10.0, "[N] must be >= 0"),
    ("berg", "c2", -1.0, "[N.s/mm] must be > 0"),
    ("fractional", "alpha", 1.0, "[1] must be in (0, 1)"),
    ("fractional", "alpha", -0.2, "[1] must be in (0, 1)"),
    ("fractional", "k3", -1.0, "[N/mm^3] must be >= 0"),
    # the hydraulic mount: a fluid column without mass, a chamber without a wall, a negative travel
    ("hydraulic", "mf", 0.0, "[N.s^2/mm] must be > 0"),
    ("hydraulic", "kb", -5.0, "[N/mm] must be > 0"),
    ("hydraulic", "gap", -0.1, "[mm] must be >= 0"),
    ("hydraulic", "ct", float("inf"), "[N.s^2/mm^2]"),
    # the free plate: a negative travel, engagement width or cage, a plate without centring
    ("hydraulic_free_decoupler", "gap", -0.12, "[mm] must be >= 0"),
    ("hydraulic_free_decoupler", "width", -0.005, "[mm] must be >= 0"),
    ("hydraulic_free_decoupler", "kcage", -100.0, "[N/mm] must be >= 0"),
    ("hydraulic_free_decoupler", "kd", 0.0, "[N/mm] must be > 0"),
]


@pytest.fixture(scope="session")
def baseline_fmus(pythonfmu_model_fmus):
    """One FMU per baseline, built with its default parameter set from data/ (conftest)."""
    return {model: pythonfmu_model_fmus[model] for model in BASELINES}


@pytest.mark.parametrize("model", BASELINES)
def test_baseline_fmu_validates_and_declares_its_own_identifier_and_units(baseline_fmus, model):
    path = baseline_fmus[model]
    assert validate_fmu(str(path)) == []
    description = read_model_description(str(path))
    assert description.coSimulation.modelIdentifier == MODELS[model].identifier
    variables = {v.name: v for v in description.modelVariables}
    assert {"x", "v", "F"} <= set(variables)
    assert (variables["x"].unit, variables["v"].unit, variables["F"].unit) == ("m", "m/s", "N")
    defaults = load_parameters(default_parameter_file(model), model)
    assert {v.name for v in description.modelVariables if v.causality == "parameter"} == set(fmu_parameter_units(model))
    for name, unit in fmu_parameter_units(model).items():
        assert variables[name].unit == unit and float(variables[name].start) == defaults.get(name, 0.0), name


@pytest.mark.parametrize("model", BASELINES)
def test_baseline_fmu_equals_the_model_through_fmpy(baseline_fmus, model):
    t = sample_times(0.3, 1000.0)
    # no sample at a turning point: there the velocity is ~1e-15 mm/s, and fmpy's interpolation
    # of the input table may give it either sign, so a friction model may rightly reverse in one
    # run and not in the other
    x, v = Sine(2.0, 10.0).signals(t + 3.7e-4)
    params = load_parameters(default_parameter_file(model), model)
    np.testing.assert_allclose(simulate_with_fmpy(baseline_fmus[model], t, x, v),
                               simulate_model_held(model, params, t, x, v), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("kind", ["pythonfmu", "native"])
@pytest.mark.parametrize("model, name, value, fragment", BAD_VALUES)
def test_baseline_fmu_refuses_a_bad_parameter_and_recovers(baseline_fmus, native_model_fmus, kind, model, name, value,
                                                           fragment):
    fmu = BushingFmu(baseline_fmus[model] if kind == "pythonfmu" else native_model_fmus[model])
    assert fmu.step(0.0, 0.01, 1e-3) == "ok"
    good = fmu.get(name)
    force = fmu.get("F")
    fmu.set(name, value)
    assert fmu.step(1e-5, 0.01, 1e-3) == "discard"
    assert any(f"{name} = " in message and fragment in message for message in fmu.messages_with("error")), \
        fmu.messages
    assert np.isfinite(fmu.get("F")) and fmu.get("F") == force
    fmu.set(name, good)
    assert fmu.step(1e-5, 0.01, 1e-3) == "ok"
    fmu.free()


@pytest.mark.parametrize("model", BASELINES)
def test_baseline_fmu_state_restores_bit_for_bit(baseline_fmus, model):
    fmu = BushingFmu(baseline_fmus[model])
    sine = Sine(2.0, 10.0)

    def drive(first, count):
        out = []
        for k in range(first, first + count):
            x, v = sine.signals(np.array([k * 1e-3]))
            assert fmu.step(x[0] * MM, v[0] * MM, 1e-3) == "ok"
            out.append(fmu.get("F"))
        return out

    drive(0, 30)
    saved = fmu.fmu.getFMUstate()
    first = drive(30, 25)
    fmu.fmu.setFMUstate(saved)
    assert drive(30, 25) == first
    fmu.free()


def test_every_model_runs_side_by_side_in_one_process(fmu_path, baseline_fmus):
    # pythonfmu shares sys.modules between FMUs: each must still run its own model.
    paths = {"proposed": fmu_path, **baseline_fmus}
    instances = {model: BushingFmu(path, instance_name=model) for model, path in paths.items()}
    t = sample_times(0.05, 1000.0)
    x, v = Sine(2.0, 10.0).signals(t)
    forces = {model: [] for model in paths}
    for k in range(t.size - 1):
        for model, fmu in instances.items():
            assert fmu.step(x[k] * MM, v[k] * MM, 1e-3) == "ok"
            forces[model].append(fmu.get("F"))
    for model in paths:
        params = load_parameters(default_parameter_file(model), model)
        np.testing.assert_allclose(forces[model], simulate_model_held(model, params, t, x, v)[1:], rtol=1e-9, atol=1e-9,
                                   err_msg=model)
        instances[model].free()
    assert len({round(f[-1], 3) for f in forces.values()}) == len(paths)
