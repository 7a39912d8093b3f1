"""Self-heating (``heating``, fmu_src/model/options/heating.py) against the textbook bushing of
tests/references/thermal_rubber.py heated by its own elements' dissipation (the dashpots' c v^2,
the Maxwell dashpot's f^2/c, the slider's level times its slip) and cooled to its surroundings:
the forward model and both FMUs on a 3 mm, 10 Hz sine, the temperature within a few mK of it;
refusals."""
from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from fmu_src.model.parameter_specs import ParameterError
from fmu_src.model.registry import get_model
from identification.forward.population import CommunicationPoints, simulate_population_at

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "references"))
import thermal_rubber  # noqa: E402

HEATED = "kelvin_voigt+maxwell+iwan1+wlf+heating"
CAPACITY_J_K, RESISTANCE_K_W = 540.0, 1.2


def durability(stop_s, dt=1e-3):
    """A 3 mm, 10 Hz sine: times, the path and its velocity [mm/s] at the points, the mean
    velocity over each step (the next point's secant, a host's consistent input)."""
    t = np.arange(0.0, stop_s + dt / 2, dt)
    x = 3.0 * np.sin(2 * np.pi * 10.0 * t)
    v = 3.0 * 2 * np.pi * 10.0 * np.cos(2 * np.pi * 10.0 * t)
    return t, x, v, np.append(np.diff(x) / dt, 0.0)


def params():
    return dict(thermal_rubber.project_parameters(), thermal_capacity=CAPACITY_J_K, thermal_resistance=RESISTANCE_K_W)


def test_the_forward_model_heats_as_the_textbook_bushing_does():
    model = get_model(HEATED)
    assert [s.name for s in model.states][-1] == "rubber_temperature"
    t, x, v, secant = durability(20.0)
    want, temperature = thermal_rubber.heated_force(thermal_rubber.TRUTH, CAPACITY_J_K, RESISTANCE_K_W, 296.15, t, x, v)
    got = simulate_population_at([model.check(params())], CommunicationPoints(t, x, secant, np.arange(t.size), v),
                                 model=model)[0]
    assert 1.5 < temperature[-1] - 296.15 < 2.5            # it warms, and softens: the force falls
    assert np.sqrt(np.mean((got - want) ** 2)) < 1e-4 * np.sqrt(np.mean(want ** 2))
    cold = thermal_rubber.force(thermal_rubber.TRUTH, 296.15, t, x, v)
    assert np.max(np.abs(got[-100:])) < np.max(np.abs(cold[-100:]))


@pytest.mark.parametrize("kind", ["native", "pythonfmu"])
def test_the_fmus_rubber_temperature_is_the_textbook_bushings(kind, tmp_path):
    import build_fmu
    from fmpy import simulate_fmu
    from fmu_src.parameter_files import save_parameters
    if kind == "native" and shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    file = save_parameters(tmp_path / "params.json", params(), HEATED)
    fmu = (build_fmu.build_native_fmu(file, tmp_path, model=HEATED, fmi_version=2).path if kind == "native"
           else build_fmu.build_fmu(file, tmp_path, model=HEATED))
    t, x, v, secant = durability(10.0)
    signals = np.zeros(t.size, dtype=[("time", float), ("x", float), ("v", float)])
    signals["time"], signals["x"], signals["v"] = t, x * 1e-3, secant * 1e-3
    result = simulate_fmu(str(fmu), stop_time=t[-1], step_size=1e-3, output_interval=1e-3, input=signals,
                          output=["F", "rubber_temperature"])
    # the FMU's dashpot reads the velocity held over the step: so does this reference
    held = np.append(0.0, secant[:-1])
    want, temperature = thermal_rubber.heated_force(thermal_rubber.TRUTH, CAPACITY_J_K, RESISTANCE_K_W, 296.15, t, x,
                                                    held)
    n = len(result)
    assert temperature[n - 1] - 296.15 > 0.9
    np.testing.assert_allclose(result["rubber_temperature"], temperature[:n], rtol=0, atol=2e-3)
    assert np.sqrt(np.mean((result["F"] - want[:n]) ** 2)) < 2e-3 * np.sqrt(np.mean(want[:n] ** 2))


def test_heating_needs_a_law_and_positive_constants():
    with pytest.raises(ParameterError, match="heating: a thermal state heats the rubber of a model with a temperature "
                                             "law; add one of wlf, arrhenius"):
        get_model("kelvin_voigt+maxwell+heating")
    model = get_model(HEATED)
    with pytest.raises(ParameterError, match=r"thermal_capacity = 0.0 \[J/K\] must be > 0"):
        model.check({**params(), "thermal_capacity": 0.0})
    with pytest.raises(ParameterError, match=r"thermal_resistance = -1.0 \[K/W\] must be > 0"):
        model.check({**params(), "thermal_resistance": -1.0})


def test_a_model_whose_step_has_constants_of_its_own_is_refused_not_miscompiled():
    from fmu_src.model.definition import ModelContractError
    with pytest.raises(ModelContractError, match="fractional model's step has constants of its own per step size"):
        get_model("fractional+wlf+heating")


def test_a_model_without_states_of_its_own_heats_too():
    """Kelvin-Voigt's force is its spring's and its dashpot's: the heat c v^2 alone."""
    model = get_model("kelvin_voigt+wlf+heating")
    p = dict(k=150.0, c=0.4, preload=0.0, temperature=296.15, temperature_ref=296.15, wlf_c1=4.0, wlf_c2=200.0,
             elastic_per_K=-0.004, friction_per_K=0.0, thermal_capacity=CAPACITY_J_K, thermal_resistance=RESISTANCE_K_W)
    t, x, v, secant = durability(5.0)
    forces = simulate_population_at([model.check(p)], CommunicationPoints(t, x, secant, np.arange(t.size), v),
                                    model=model)[0]
    assert np.all(np.isfinite(forces))
    # 5 s of c v^2 (7 W) warm it by about 0.07 K: softer by 0.03 %
    assert np.max(np.abs(forces[-100:])) < np.max(np.abs(forces[:100]))


def test_the_six_axis_fmus_axis_heats_as_the_one_axis_model(tmp_path):
    from element_checks import assert_six_axis_z_is_the_forward_model
    assert_six_axis_z_is_the_forward_model(get_model(HEATED), params(), tmp_path)


def test_an_ssv_parameter_set_of_a_model_with_options_reads_back_as_that_model(tmp_path):
    from fmu_src.parameter_files import read_parameter_set, save_parameters
    file = save_parameters(tmp_path / "heated.ssv", params(), HEATED)
    read = read_parameter_set(file)
    assert read.model.name == HEATED and read.parameters == params()


def test_model_exchange_integrates_the_heat_with_cvode(tmp_path):
    """The rubber's temperature as a continuous state (dT/dt = (F v - (T - T_amb)/R)/C) under CVode:
    the force on a 3 mm, 10 Hz sine over its fourth second, which warms the rubber by 0.4 K (the
    force 0.85 % of its peak off the bushing held at the surroundings' temperature), against the
    textbook bushing walked on 0.1 ms pieces, within 5e-5 of the peak (1.0e-5 measured)."""
    import math
    import build_fmu
    from fmu_src.parameter_files import save_parameters
    from model_exchange import simulate_model_exchange
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    file = save_parameters(tmp_path / "heated.json", params(), HEATED)
    fmu = build_fmu.build_native_fmu(file, tmp_path, model=HEATED, fmi_version=2).path
    w = 2 * np.pi * 10.0
    t_out = np.linspace(3.9, 4.0, 101)
    run = simulate_model_exchange(fmu, np.concatenate([[0.0], t_out]), lambda s: 3e-3 * math.sin(w * s),
                                  lambda s: 3e-3 * w * math.cos(w * s), rtol=1e-7)
    t, x, v, _ = durability(4.0, dt=1e-4)
    want, temperature = thermal_rubber.heated_force(thermal_rubber.TRUTH, CAPACITY_J_K, RESISTANCE_K_W, 296.15, t, x, v)
    at = np.searchsorted(t, t_out - 1e-9)
    peak = np.max(np.abs(want[at]))
    assert temperature[-1] - 296.15 > 0.3
    error = np.max(np.abs(run.force_N[1:] - want[at]))
    assert error < 5e-5 * peak, error / peak       # measured 2026-12-04: 1.0e-5
    cold = thermal_rubber.force(thermal_rubber.TRUTH, 296.15, t, x, v)[at]
    assert np.max(np.abs(cold - want[at])) > 100 * error
