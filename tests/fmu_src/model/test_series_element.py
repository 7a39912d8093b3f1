"""The series compliance (``series``, fmu_src/model/options/series.py): a device on a spring in
series, against what it is by its definition: a Kelvin-Voigt device in series with a spring is the
standard linear solid, solved exactly here under the walk's piecewise-linear x (the co-simulation
walk first order in its step) and by scipy's Radau under a sine (model exchange with CVode); a stiff device leaves the compliance alone on a
slow ramp; a compliance of 0 is the device bit for bit; the compiled path and both FMUs equal
its Python kernels; refusals."""
from __future__ import annotations

import math
import shutil

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from fmu_src.model.parameter_specs import ParameterError
from fmu_src.model.registry import get_model
from fmu_src.parameter_files import save_parameters
from element_checks import (assert_fmu_is_the_forward_model, assert_sensitivities_are_central_differences,
                            assert_six_axis_z_is_the_forward_model)
from example_parameter_files import defaults
from python_core import simulate_python_core

ZENER = dict(k=200.0, c=2.0, preload=0.0, series_compliance=1 / 500.0)
"""A Kelvin-Voigt device (200 N/mm, 2 N.s/mm) on a 500 N/mm spring: relaxation time c/(k + 500) = 2.9 ms."""


def simulate(name, params, t, x, v):
    from identification.forward.population import simulate_population_held
    model = get_model(name)
    return simulate_population_held([model.check(params)], t, x, v, model=model)[0]


def zener_reference(t, x, v, p=ZENER):
    """F [N] of the standard linear solid under x piecewise linear between the samples (as the
    walk takes it), exactly: k u + c du/dt = (x - u)/compliance is linear, du/dt = a x - b u with
    a = 1/(compliance c), b = (1/compliance + k)/c, so over a step where x = x_k + v_k s,
    u = alpha + beta s + (u_k - alpha) e^(-b s), beta = a v_k / b, alpha = (a x_k - beta)/b."""
    compliance = p["series_compliance"]
    a, b = 1.0 / (compliance * p["c"]), (1.0 / compliance + p["k"]) / p["c"]
    u = np.zeros(t.size)
    for k in range(t.size - 1):
        h = t[k + 1] - t[k]
        beta = a * v[k] / b
        alpha = (a * x[k] - beta) / b
        u[k + 1] = alpha + beta * h + (u[k] - alpha) * math.exp(-b * h)
    return (x - u) / compliance


def sine_reference(t, amplitude=2.0, hz=5.0, p=ZENER):
    """F [N] of the standard linear solid under the smooth sine, solved by scipy's Radau."""
    compliance, w = p["series_compliance"], 2 * np.pi * hz
    solution = solve_ivp(lambda s, u: [((amplitude * math.sin(w * s) - u[0]) / compliance - p["k"] * u[0]) / p["c"]],
                         (t[0], t[-1]), [0.0], t_eval=t, method="Radau", rtol=1e-10, atol=1e-12)
    return (amplitude * np.sin(w * t) - solution.y[0]) / compliance


def sine(dt, stop=0.6, amplitude=2.0, hz=5.0):
    t = np.arange(0.0, stop + dt / 2, dt)
    x = amplitude * np.sin(2 * np.pi * hz * t)
    return t, x, np.append(np.diff(x) / dt, 0.0)      # x walked exactly: v the secant


def test_a_kelvin_voigt_device_in_series_is_the_standard_linear_solid_first_order_in_the_step():
    # each step moves the device at the one velocity that balances the spring at its end (backward
    # Euler in the device's travel): measured 2026-12-03, 1.21 % of the peak at 1 ms, 0.33 % at 0.25 ms
    errors = []
    for dt in (1e-3, 2.5e-4):
        t, x, v = sine(dt)
        want = zener_reference(t, x, v)
        got = simulate("kelvin_voigt+series", ZENER, t, x, v)
        errors.append(np.max(np.abs(got - want)) / np.max(np.abs(want)))
    assert errors[0] < 0.015 and errors[1] < 0.004
    assert errors[0] / errors[1] > 3.0            # first order: a quarter of the step, about a quarter


def test_a_stiff_device_leaves_the_compliance_alone_on_a_slow_ramp():
    # a device of 1e6 N/mm with a small dashpot on a 1e-2 mm/N spring: F = x / (compliance + 1/k)
    params = dict(k=1e6, c=1e-3, preload=0.0, series_compliance=1e-2)
    t = np.arange(0.0, 1.0 + 5e-4, 1e-3)
    x, v = 0.5 * t, np.full(t.size, 0.5)
    got = simulate("kelvin_voigt+series", params, t, x, v)
    np.testing.assert_allclose(got, x / (1e-2 + 1e-6), rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("name, base", [("kelvin_voigt+series", "kelvin_voigt"),
                                        ("single_bouc_wen+maxwell+series+rig", "single_bouc_wen+maxwell+rig"),
                                        ("asymmetric_bouc_wen+band+series", "asymmetric_bouc_wen+band")])
def test_a_compliance_of_0_is_the_device_bit_for_bit(name, base):
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 0.5, 1e-3)
    x = np.cumsum(rng.normal(0.0, 0.05, t.size))
    v = np.append(np.diff(x) / 1e-3, 0.0)
    params = dict(defaults(base.split("+")[0]), maxwell_k=50.0, maxwell_c=1.0, rig_displacement_zero=0.1,
                  rig_force_zero=20.0, band_gap=0.5, band_k=1000.0, band_depth=0.2, band_f=100.0,
                  band_ratio_pos=4.0, band_ratio_neg=2.0, band_travel=2.0)
    device = {spec.name: params[spec.name] for spec in get_model(base).specs}
    np.testing.assert_array_equal(simulate(name, dict(device, series_compliance=0.0), t, x, v),
                                  simulate(base, device, t, x, v))


def test_the_rigs_load_cell_zero_stays_outside_the_spring():
    t, x, v = sine(1e-3, stop=0.3)
    with_zero = simulate("kelvin_voigt+series+rig", dict(ZENER, rig_displacement_zero=0.0, rig_force_zero=50.0),
                         t, x, v)
    np.testing.assert_allclose(with_zero - 50.0, simulate("kelvin_voigt+series", ZENER, t, x, v), rtol=0,
                               atol=1e-9)


def test_the_compiled_series_element_equals_its_python_kernels_bitwise():
    from identification.forward.population import simulate_population_held
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 0.4, 1e-3)
    x = np.cumsum(rng.normal(0.0, 0.05, t.size))
    v = np.append(np.diff(x) / 1e-3, 0.0)
    model = get_model("single_bouc_wen+maxwell+series+rig")
    params = dict(defaults("single_bouc_wen"), maxwell_k=50.0, maxwell_c=1.0, series_compliance=1e-3,
                  rig_displacement_zero=0.1, rig_force_zero=20.0)
    compiled = simulate_population_held([model.check(params)], t, x, v, model=model)[0]
    np.testing.assert_array_equal(compiled, simulate_python_core(params, t, x, v, model=model.name))


@pytest.mark.parametrize("kind", ["pythonfmu", "native2", "native3"])
def test_both_fmus_of_a_model_with_a_compliance_in_series_equal_its_forward_model(kind, tmp_path):
    params = dict(defaults("single_bouc_wen"), maxwell_k=50.0, maxwell_c=1.0, series_compliance=1e-3,
                  rig_displacement_zero=0.1, rig_force_zero=20.0)
    assert_fmu_is_the_forward_model(kind, get_model("single_bouc_wen+maxwell+series+rig"), params, tmp_path,
                                    stop_s=0.5)


@pytest.mark.parametrize("version", [2, 3])
def test_model_exchange_integrates_the_standard_linear_solid(version, tmp_path):
    import build_fmu
    from model_exchange import simulate_model_exchange
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    model = get_model("kelvin_voigt+series")
    file = save_parameters(tmp_path / "series.json", ZENER, model.name)
    fmu = build_fmu.build_native_fmu(file, tmp_path, model=model.name, fmi_version=version).path
    w = 2 * np.pi * 5.0
    t = np.linspace(0.0, 0.6, 121)
    run = simulate_model_exchange(fmu, t, lambda s: 2.0e-3 * math.sin(w * s), lambda s: 2.0e-3 * w * math.cos(w * s))
    want = sine_reference(t)
    # measured 2026-12-03: CVode at rtol 1e-8 against Radau at 1e-10
    np.testing.assert_allclose(run.force_N, want, rtol=0, atol=1e-5 * np.max(np.abs(want)))


@pytest.mark.parametrize("value, fragment", [(-1e-3, "series_compliance = -0.001 [mm/N] must be >= 0")])
def test_a_negative_compliance_is_refused_with_unit_and_range(value, fragment):
    with pytest.raises(ParameterError, match=fragment.replace("[", r"\[").replace("]", r"\]")):
        get_model("kelvin_voigt+series").check(dict(ZENER, series_compliance=value))


@pytest.mark.parametrize("name", ["kelvin_voigt+series", "single_bouc_wen+maxwell+series+rig"])
def test_the_fits_exact_jacobian_through_the_series_iteration_equals_central_differences(name):
    # the sensitivities are the tangents of the kernels, the iteration over the device's velocity
    # included: they must be those of the converged step, not of the path the iteration took
    from identification.forward.population import CommunicationPoints
    from identification.measured.signals import Random, sample_times
    model = get_model(name)
    params = (ZENER if name.startswith("kelvin") else
              dict(defaults("single_bouc_wen"), maxwell_k=50.0, maxwell_c=1.0, series_compliance=1e-3,
                   rig_displacement_zero=0.1, rig_force_zero=20.0))
    t = sample_times(0.2, 1000.0)
    x, v = Random(2.0, 0.3, seed=5).signals(t)
    row = np.array([model.values(model.check(params))])
    # a preload of 0 N steps by 1 mN, every other value by 1e-6 of itself
    assert_sensitivities_are_central_differences(model, row, CommunicationPoints(t, x, v, np.arange(t.size), v),
                                                 lambda j, value: 1e-6 * abs(value) if value != 0.0 else 1e-3)



def test_compare_weighs_the_compliance_and_recovers_it_from_the_standard_linear_solid(tmp_path, capsys):
    # two sines of a standard linear solid solved by Radau (not by the model), 0.2 % noise: the
    # Kelvin-Voigt model alone misses the stiffening with frequency; with the compliance tried it
    # is at the noise floor, recommended, and its values are the truth's
    import csv
    import json

    from identification.__main__ import main
    from identification.measured.measurements import write_measurement
    rng = np.random.default_rng(1)
    files = []
    for hz, amplitude, dt in ((1.0, 2.0, 1e-3), (30.0, 0.5, 2.5e-4)):
        t = np.arange(0.0, 4.0 / hz, dt)
        w = 2 * np.pi * hz
        x = amplitude * np.sin(w * t)
        compliance = ZENER["series_compliance"]
        solution = solve_ivp(lambda s, u: [((amplitude * math.sin(w * s) - u[0]) / compliance - ZENER["k"] * u[0])
                                           / ZENER["c"]], (0.0, t[-1]), [0.0], t_eval=t, method="Radau",
                             rtol=1e-10, atol=1e-12, max_step=dt)
        force = (x - solution.y[0]) / compliance
        files.append(tmp_path / f"sine_{hz:g}Hz.csv")
        write_measurement(files[-1], t, x, force + rng.normal(0.0, 2e-3 * np.max(np.abs(force)), t.size),
                          comments=["synthetic: a standard linear solid solved by scipy's Radau, 0.2 % noise"])
    out = tmp_path / "compare"
    assert main(["compare", *[a for f in files for a in ("--sine", str(f))], "--models", "kelvin_voigt",
                 "--try-options", "series", "--screening", "64", "--starts", "2", "--no-ensemble", "--quiet",
                 "--workers", "1", "--out", str(out)]) == 0
    printed = capsys.readouterr()
    assert "tried: series: named with --try-options" in printed.out + printed.err
    with open(out / "comparison.csv") as handle:
        rows = {row["model"]: row for row in csv.DictReader(handle)}
    assert rows["kelvin_voigt+series"]["recommended"] == "True"
    fitted = json.loads((out / "params_kelvin_voigt+series.json").read_text())["parameters"]
    for name in ("k", "c", "series_compliance"):
        assert fitted[name] == pytest.approx(ZENER[name], rel=0.03), name


@pytest.mark.slow
def test_a_six_axis_fmus_axis_takes_a_compliance_in_series_in_both_fmus(tmp_path):
    # z the standard linear solid
    assert_six_axis_z_is_the_forward_model(get_model("kelvin_voigt+series"), ZENER, tmp_path, stop_s=0.5,
                                           amplitude_m=2.0e-3, hz=5.0)


@pytest.mark.parametrize("name", ["asymmetric_bouc_wen+series", "spencer+series", "proposed+series"])
@pytest.mark.parametrize("compliance", [0.03, 1.0])
def test_a_soft_spring_steps_within_the_fits_substep_budget(name, compliance):
    # a spring far softer than the device: the device barely moves and F tends to x / compliance;
    # each step's first trial takes the device's own slope, so no trial runs the device off (a
    # guess that assumed the device held its force overshot 1500-fold and failed the step)
    from identification.fitting.objectives import FIT_MAX_SUBSTEPS
    from identification.forward.population import simulate_population_held
    base = name.split("+")[0]
    model = get_model(name)
    t, x, v = sine(1e-3, stop=0.6)
    force = simulate_population_held([model.check(dict(defaults(base), series_compliance=compliance))], t, x, v,
                                     max_substeps=FIT_MAX_SUBSTEPS, model=model)[0]
    assert np.all(np.isfinite(force))
    np.testing.assert_allclose(force, x / compliance, rtol=0, atol=0.1 * np.max(np.abs(x)) / compliance)


def test_the_rigs_displacement_zero_comes_off_x_before_the_spring():
    t, x, v = sine(1e-3, stop=0.3)
    shifted = simulate("kelvin_voigt+series+rig", dict(ZENER, rig_displacement_zero=0.4, rig_force_zero=0.0),
                       t, x, v)
    np.testing.assert_allclose(shifted, simulate("kelvin_voigt+series", ZENER, t, x - 0.4, v), rtol=0, atol=1e-9)


def test_a_start_away_from_zero_is_in_equilibrium_with_the_spring():
    # a Kelvin-Voigt device with a preload on the spring at x0 = 1 mm, at rest: u + c (k u + preload)
    # = x0, so F = (k x0 + preload) / (1 + c k) from the first sample on, whatever the compliance
    params = dict(ZENER, preload=50.0)
    t = np.arange(0.0, 0.05, 1e-3)
    x, v = np.full(t.size, 1.0), np.zeros(t.size)
    for compliance in (1e-9, 2e-3, 0.1):
        want = (params["k"] * 1.0 + params["preload"]) / (1.0 + compliance * params["k"])
        got = simulate("kelvin_voigt+series", dict(params, series_compliance=compliance), t, x, v)
        np.testing.assert_allclose(got, want, rtol=1e-9)


def test_a_start_holding_a_force_deflects_the_spring_by_it():
    from identification.forward.population import simulate_population_held
    model = get_model("single_bouc_wen+series")
    params = dict(defaults("single_bouc_wen"), series_compliance=1e-3)
    t = np.arange(0.0, 0.02, 1e-3)
    held = simulate_population_held([model.check(params)], t, np.zeros(t.size), np.zeros(t.size), model=model,
                                    rest_force_N=123.0)[0]
    np.testing.assert_allclose(held, 123.0, rtol=1e-9)
