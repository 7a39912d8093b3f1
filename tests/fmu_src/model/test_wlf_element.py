"""The temperature laws (``wlf`` and ``arrhenius``, fmu_src/model/options/wlf.py, arrhenius.py),
against what they are by their definitions: at the reference temperature the model without the law bit for bit; at any other the
independent textbook bushing of tests/references/thermal_rubber.py (WLF-shifted dashpots and
Maxwell element, exponentially scaled stiffnesses and slider level) to rounding, the temperature
set by a test's conditions or by the set; an FMU whose temperature changes between steps; the
fit's exact Jacobian; the roles its units give; refusals."""
from __future__ import annotations

import math
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from fmu_src.model.parameter_specs import ParameterError, ParameterSpec
from fmu_src.model.registry import get_model
from element_checks import assert_fmu_is_the_forward_model, assert_sensitivities_are_central_differences
from example_parameter_files import defaults
from identification.forward.population import CommunicationPoints, simulate_population_at

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "references"))
import thermal_rubber  # noqa: E402

THERMAL = "kelvin_voigt+maxwell+iwan1+wlf"
LAW = dict(temperature=296.15, temperature_ref=296.15, wlf_c1=4.0, wlf_c2=200.0, elastic_per_K=-0.004,
           friction_per_K=-0.006)


def sine_points(dt=1e-3, stop=1.0, amplitude=1.5, hz=4.0, conditions=()):
    """A sine as straight pieces between its points (secant velocities), the dashpot reading the
    sine's own velocity at each point."""
    t = np.arange(0.0, stop, dt)
    x = amplitude * np.sin(2 * np.pi * hz * t)
    v = amplitude * 2 * np.pi * hz * np.cos(2 * np.pi * hz * t)
    secant = np.append(np.diff(x) / np.diff(t), 0.0)
    return t, x, v, CommunicationPoints(t, x, secant, np.arange(t.size), v, conditions=conditions)


@pytest.mark.parametrize("base, options", [("kelvin_voigt", "maxwell+iwan1"), ("proposed", ""),
                                           ("asymmetric_bouc_wen", "band"), ("berg", "maxwell+rig")])
def test_at_the_reference_temperature_the_model_is_the_model_without_the_law_bit_for_bit(base, options):
    without = get_model("+".join(filter(None, (base, options))))
    law = get_model("+".join(filter(None, (base, options, "wlf"))))
    values = defaults(base)
    for name in without.parameter_names:
        values.setdefault(name, {"maxwell_k": 80.0, "maxwell_c": 0.8, "iwan_k": 50.0, "iwan_f": 20.0,
                                 "rig_displacement_zero": 0.1, "rig_force_zero": 5.0}.get(name, 0.0))
    if options == "band":
        values.update(band_k=300.0, band_gap=0.2, band_depth=0.3, band_f=40.0, band_ratio_pos=1.5,
                      band_ratio_neg=1.2, band_travel=2.0)
    t, x, _, points = sine_points(hz=3.0, amplitude=2.0)
    plain = simulate_population_at([without.check(values)], points, model=without)[0]
    lawful = simulate_population_at([law.check({**values, **LAW})], points, model=law)[0]
    assert np.all(np.isfinite(plain))
    np.testing.assert_array_equal(lawful, plain)


@pytest.mark.parametrize("temperature_K", [253.15, 353.15])
def test_the_arrhenius_law_is_the_model_at_the_textbook_shift(temperature_K):
    """a_T = exp(E_a/R (1/T - 1/T_ref)) on every dashpot, the same coefficients on the rest, against
    the model without the law at the parameters shifted here; at the reference, bit for bit."""
    plain, law = get_model("kelvin_voigt+maxwell+iwan1"), get_model("kelvin_voigt+maxwell+iwan1+arrhenius")
    base = {k: v for k, v in thermal_rubber.project_parameters().items()
            if k not in ("temperature", "temperature_ref", "wlf_c1", "wlf_c2", "elastic_per_K", "friction_per_K")}
    arrhenius = dict(temperature_ref=296.15, arrhenius_K=12000.0, elastic_per_K=-0.004, friction_per_K=-0.006)
    points = sine_points()[3]
    at_reference = simulate_population_at([law.check({**base, **arrhenius, "temperature": 296.15})], points, model=law)
    np.testing.assert_array_equal(at_reference, simulate_population_at([plain.check(base)], points, model=plain))
    d = temperature_K - 296.15
    a_T, e, g = math.exp(12000.0 * (1 / temperature_K - 1 / 296.15)), math.exp(-0.004 * d), math.exp(-0.006 * d)
    shifted = dict(base, k=base["k"] * e, c=base["c"] * a_T, maxwell_k=base["maxwell_k"] * e,
                   maxwell_c=base["maxwell_c"] * a_T, iwan_k=base["iwan_k"] * e, iwan_f=base["iwan_f"] * g)
    want = simulate_population_at([plain.check(shifted)], points, model=plain)[0]
    got = simulate_population_at([law.check({**base, **arrhenius, "temperature": temperature_K})], points, model=law)[0]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.max(np.abs(want)))


def test_a_model_takes_one_temperature_law():
    with pytest.raises(ParameterError, match="wlf and arrhenius: a model takes one law on its parameters"):
        get_model("kelvin_voigt+wlf+arrhenius")


@pytest.mark.parametrize("temperature_K", [253.15, 296.15, 333.15, 353.15])
def test_the_law_is_the_textbook_bushing_at_its_temperature(temperature_K):
    model = get_model(THERMAL)
    t, x, v, points = sine_points()
    want = thermal_rubber.force(thermal_rubber.TRUTH, temperature_K, t, x, v)
    by_set = simulate_population_at([model.check(thermal_rubber.project_parameters(temperature_K=temperature_K))],
                                    points, model=model)[0]
    np.testing.assert_allclose(by_set, want, rtol=0, atol=1e-12 * np.max(np.abs(want)))
    # a test's own temperature (its conditions) sets the set's, whatever the set says
    conditioned = sine_points(conditions=(("temperature_K", temperature_K),))[3]
    by_test = simulate_population_at([model.check(thermal_rubber.project_parameters(temperature_K=200.0))],
                                     conditioned, model=model)[0]
    np.testing.assert_array_equal(by_test, by_set)


def test_cold_is_stiffer_and_lossier_than_warm():
    """The truth's shift: the Maxwell time constant 10 ms at 23 degC is 10^(4*43/157) = 12.5
    times longer at -20 degC; the loop's peak force grows with the cold."""
    assert thermal_rubber.shift(thermal_rubber.TRUTH, 253.15) == pytest.approx(10 ** (4 * 43 / 157), rel=1e-12)
    model = get_model(THERMAL)
    peaks = [np.max(np.abs(simulate_population_at(
        [model.check(thermal_rubber.project_parameters(temperature_K=T))], sine_points()[3], model=model)[0]))
        for T in (253.15, 296.15, 353.15)]
    assert peaks[0] > peaks[1] > peaks[2]


def test_the_roles_come_from_the_units_unless_a_module_says_otherwise():
    assert ParameterSpec("c", "N.s/mm", "").temperature_role == "viscous"
    assert ParameterSpec("k", "N/mm", "").temperature_role == "elastic"
    assert ParameterSpec("k3", "N/mm^3", "").temperature_role == "elastic"
    assert ParameterSpec("f", "N", "").temperature_role == "friction"
    assert ParameterSpec("x", "mm", "").temperature_role == "none"
    assert ParameterSpec("beta", "N^(1-n)/mm", "").temperature_role == "none"
    roles = {spec.name: spec.temperature_role for spec in get_model("kelvin_voigt+backbone5+rig+wlf").specs}
    assert roles["preload"] == roles["rig_force_zero"] == roles["rig_displacement_zero"] == "none"
    assert roles["backbone_F1"] == "elastic" and roles["c"] == "viscous"
    with pytest.raises(ValueError, match="temperature role 'hot'"):
        ParameterSpec("k", "N/mm", "", temperature="hot")


def test_refusals_name_the_value_its_unit_and_what_is_allowed():
    model = get_model(THERMAL)
    good = thermal_rubber.project_parameters()
    with pytest.raises(ParameterError, match=r"wlf_c2 \+ temperature - temperature_ref = -10.0 K must be > 0"):
        model.check({**good, "temperature": 180.0, "temperature_ref": 390.0, "wlf_c2": 200.0})
    with pytest.raises(ParameterError, match=r"temperature = 0.0 \[K\] must be in \[173.15, 473.15\]"):
        model.check({**good, "temperature": 0.0})
    with pytest.raises(ParameterError, match=r"temperature_ref = 600.0 \[K\]"):
        model.check({**good, "temperature_ref": 600.0})
    with pytest.raises(ParameterError, match=r"wlf_c2 = 0.0 \[K\] must be > 0"):
        model.check({**good, "wlf_c2": 0.0})
    with pytest.raises(Exception, match="give one law"):
        from fmu_src.model.derived_source import law_wrapper_source
        from fmu_src.model.options import ELEMENTS, Options
        law_wrapper_source(get_model("kelvin_voigt"), _TwoLaws(Options.parse(["wlf"]), ELEMENTS["wlf"]))


class _TwoLaws:
    """Options that hold the law twice (no token can say so): the generator refuses them."""

    def __init__(self, options, law):
        self.elements, self.chosen, self.replaces_static_spring = ((law, 0), (law, 0)), options.chosen, False


def test_the_fits_exact_jacobian_is_central_differences_and_the_conditioned_temperature_moves_nothing():
    from identification.forward.parameter_jacobian import population_sensitivities
    model = get_model(THERMAL)
    row = np.array([model.values(model.check(thermal_rubber.project_parameters(temperature_K=263.15)))])
    points = sine_points(stop=0.5)[3]
    steps = {"temperature": 1e-2, "temperature_ref": 1e-2, "wlf_c1": 1e-3, "wlf_c2": 1e-2}
    assert_sensitivities_are_central_differences(
        model, row, points, lambda j, value: steps.get(model.parameter_names[j], 1e-6 * max(abs(value), 1.0)),
        tolerance=1e-5)
    conditioned = sine_points(stop=0.5, conditions=(("temperature_K", 263.15),))[3]
    _, sensitivity = population_sensitivities(row, np.eye(row.shape[1])[None], conditioned, model=model)
    j = model.parameter_names.index("temperature")
    assert np.all(sensitivity[0, :, j] == 0.0) and np.any(sensitivity[0, :, j + 1] != 0.0)


@pytest.mark.parametrize("kind", ["pythonfmu", "native2", "native3"])
def test_the_fmus_are_the_forward_model_at_a_cold_temperature(kind, tmp_path):
    model = get_model(THERMAL)
    assert_fmu_is_the_forward_model(kind, model, thermal_rubber.project_parameters(temperature_K=253.15), tmp_path)


@pytest.mark.parametrize("kind", ["pythonfmu", "native2"])
def test_an_fmus_temperature_set_between_steps_is_the_textbook_bushing_whose_temperature_changed(kind, tmp_path):
    """The temperature, a tunable parameter, set from -20 degC to 60 degC after 0.3 s: the
    states carry over, the constants follow (a dashpot of 0 so that the force is the path's and
    the states', whatever velocity a host reads it at)."""
    import build_fmu
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmu_src.parameter_files import save_parameters
    if kind != "pythonfmu" and shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    model = get_model(THERMAL)
    truth = {**thermal_rubber.TRUTH, "c": 0.0}
    params = {**thermal_rubber.project_parameters(truth, temperature_K=253.15)}
    file = save_parameters(tmp_path / "params.json", params, model.name)
    fmu = str(build_fmu.build_fmu(file, tmp_path, model=model.name) if kind == "pythonfmu"
              else build_fmu.build_native_fmu(file, tmp_path, model=model.name, fmi_version=2).path)
    description = read_model_description(fmu)
    ref = {v.name: v.valueReference for v in description.modelVariables}
    slave = FMU2Slave(guid=description.guid, unzipDirectory=extract(fmu),
                      modelIdentifier=description.coSimulation.modelIdentifier, instanceName="wlf")
    t, x, _, _ = sine_points(dt=1e-3, stop=0.8, amplitude=1.0, hz=3.0)
    secant = np.diff(x) / np.diff(t)
    temperature = np.where(t > 0.3 + 1e-9, 333.15, 253.15)
    got = np.empty(t.size)
    slave.instantiate()
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        got[0] = slave.getReal([ref["F"]])[0]
        for k in range(t.size - 1):
            if temperature[k + 1] != temperature[k]:
                slave.setReal([ref["temperature"]], [float(temperature[k + 1])])
            slave.setReal([ref["x"], ref["v"]], [x[k] * 1e-3, secant[k] * 1e-3])
            slave.doStep(t[k], t[k + 1] - t[k])
            got[k + 1] = slave.getReal([ref["F"]])[0]
    finally:
        slave.terminate()
        slave.freeInstance()
    want = thermal_rubber.force(truth, temperature, t, x, np.zeros(t.size))
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.max(np.abs(want)))
    assert np.max(np.abs(want[t > 0.35])) < 0.8 * np.max(np.abs(want[t < 0.3]))
