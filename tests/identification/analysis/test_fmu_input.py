"""A measurement into the FMU (identification.fmu_input): the FMU reproduces the fit's forward model
on the friction-damper file it was fitted to, and warns, once, when its inputs keep jumping.

The fit (data/params_fit_brfd_sine_0.5Hz_1in.json) read data/brfd/sine_0.5Hz30lbtension1amplitude.csv.gz,
whose velocity column is not the derivative of its (quantised) displacement. The first
SLICE samples (two cycles of the 0.5 Hz sine) keep the test short.
"""
import math

import numpy as np
import pytest
from fmpy import simulate_fmu

from conftest import DATA
from fmu_harness import BushingFmu
from fmu_src.parameter_files import load_parameters
from identification import load_measurement, predict, simulate
from identification.analysis.fmu_input import fmu_input, simulate_measurement, table_step
from identification.forward.input_path import prepare_input
from identification.measured.measurements import Measurement
from identification.fitting.objectives import nrmse

PARAMS = DATA / "params_fit_brfd_sine_0.5Hz_1in.json"
MEASUREMENT = DATA / "brfd" / "sine_0.5Hz30lbtension1amplitude.csv.gz"
SLICE = 4000
FORCE_TOLERANCE = 1e-10
"""max |FMU - forward model| / max |forward model| on the same path (measured 1.1e-13 for both FMUs,
2026-12: the same kernels, differing by the m <-> mm conversions of the ports only)."""
JUMP_FRAGMENT = "is probably not the time derivative of the sampled x"


@pytest.fixture(scope="module")
def measurement():
    m = load_measurement(MEASUREMENT)
    return Measurement(m.time_s[:SLICE], m.displacement_mm[:SLICE], m.force_N[:SLICE], m.velocity_mm_s[:SLICE],
                       source=m.source)


@pytest.fixture(scope="module")
def fitted():
    return load_parameters(PARAMS)


@pytest.fixture(scope="module")
def forward(measurement):
    """identification.predict's force on the measurement: the fit's forward model."""
    return predict(PARAMS, measurement.time_s, measurement.displacement_mm, measurement.measured_velocity_mm_s).force_N


@pytest.fixture(params=["pythonfmu", "native"])
def bushing_fmu(request):
    if request.param == "native":
        import shutil
        if shutil.which("gcc") is None and shutil.which("cc") is None:
            pytest.skip("no C compiler for the native FMU")
        return request.getfixturevalue("native_fmu_path")
    return request.getfixturevalue("fmu_path")


def test_the_table_is_the_forward_models_continuous_path_in_si_units(measurement):
    table = fmu_input(measurement)
    driven = prepare_input(measurement.time_s, measurement.displacement_mm, measurement.measured_velocity_mm_s)
    assert table.dtype.names == ("time", "x", "v")
    # the slow sine's noise asks for no substeps (input_path.turning_rate): one row per sample
    assert driven.steps_per_sample == 1
    np.testing.assert_array_equal(table["time"], driven.time_s)
    np.testing.assert_array_equal(table["x"], driven.displacement_mm / 1000.0)
    # v is the secant of each step: x_j + v_j*h_j lands on x_(j+1) (no jump), to rounding
    h = np.diff(table["time"])
    assert np.max(np.abs(table["x"][:-1] + table["v"][:-1] * h - table["x"][1:])) < 1e-15
    assert table["v"][-1] == table["v"][-2]
    # every sample of the measurement is a row, at its time and displacement
    np.testing.assert_array_equal(table["time"][driven.output_index], measurement.time_s)
    np.testing.assert_allclose(table["x"][driven.output_index], measurement.displacement_mm / 1000.0, rtol=1e-15)


def test_the_table_names_a_six_axis_fmus_inputs(measurement):
    short = (measurement.time_s[:50], measurement.displacement_mm[:50])
    assert fmu_input(short, axis="y").dtype.names == ("time", "dy", "vy")
    rotation = fmu_input(short, axis="rz")
    assert rotation.dtype.names == ("time", "rz", "wz")
    np.testing.assert_array_equal(rotation["rz"][[0, -1]], short[1][[0, -1]])   # rad stay rad


def test_the_fmu_driven_by_the_helper_reproduces_the_fit(bushing_fmu, measurement, fitted, forward):
    force = simulate_measurement(bushing_fmu, measurement, start_values=fitted)
    assert np.max(np.abs(force - forward)) <= FORCE_TOLERANCE * np.max(np.abs(forward))
    fit_nrmse, fmu_nrmse = nrmse(forward, measurement.force_N), nrmse(force, measurement.force_N)
    assert abs(fmu_nrmse / fit_nrmse - 1.0) < 0.01
    # the same on the whole file would be the fit's own figure (0.218 in the parameter file)
    assert 0.2 < fit_nrmse < 0.3


def test_the_output_after_the_step_differs_by_the_viscous_feedthrough_only(bushing_fmu, measurement, fitted,
                                                                           forward):
    """Read right after doStep (v of the step that ends at the sample), the force differs from the
    fit's by c0*c2/(c0 + c2) times the difference of the two velocities: 0.17 % of the peak here."""
    force = simulate_measurement(bushing_fmu, measurement, start_values=fitted, sample_velocity=False)
    driven = prepare_input(measurement.time_s, measurement.displacement_mm, measurement.measured_velocity_mm_s)
    step_velocity = driven.velocity_mm_s[np.maximum(driven.output_index - 1, 0)]
    step_velocity[0] = driven.velocity_mm_s[0]
    c0, c2 = fitted["c0"], fitted["c2"]
    feedthrough = c0 * c2 / (c0 + c2) * (step_velocity - driven.output_velocity_mm_s)
    np.testing.assert_allclose(force - forward, feedthrough, rtol=0, atol=1e-6 * np.max(np.abs(forward)))
    assert abs(nrmse(force, measurement.force_N) / nrmse(forward, measurement.force_N) - 1.0) < 0.01


def test_fmpys_simulate_fmu_with_the_table_gives_the_fits_nrmse(bushing_fmu, measurement, fitted, forward):
    table = fmu_input(measurement)
    result = simulate_fmu(str(bushing_fmu), input=table, start_values=fitted, start_time=table["time"][0],
                          stop_time=table["time"][-1], output_interval=table_step(table), output=["F"])
    force = np.interp(measurement.time_s, result["time"], result["F"])
    assert abs(nrmse(force, measurement.force_N) / nrmse(forward, measurement.force_N) - 1.0) < 0.01


def test_the_measured_velocity_fed_beside_the_displacement_does_not_reproduce_the_fit(bushing_fmu, measurement,
                                                                                    fitted, forward):
    """The reviewer's validation: the file's (time, x, v) straight into simulate_fmu."""
    table = np.rec.fromarrays([measurement.time_s, measurement.displacement_mm / 1000.0,
                               measurement.velocity_mm_s / 1000.0], names=["time", "x", "v"])
    interval = float(np.median(np.diff(measurement.time_s)))
    result = simulate_fmu(str(bushing_fmu), input=table, start_values=fitted, start_time=table["time"][0],
                          stop_time=table["time"][-1], output_interval=interval, output=["F"])
    force = np.interp(measurement.time_s, result["time"], result["F"])
    assert nrmse(force, measurement.force_N) / nrmse(forward, measurement.force_N) > 1.02   # 1.03 measured


def _run(fmu_path, fitted, x_m, v_m_s, time_s):
    fmu = BushingFmu(fmu_path, start_values=fitted, x0_m=x_m[0], v0_m_s=v_m_s[0])
    for k in range(len(time_s) - 1):
        assert fmu.step(x_m[k], v_m_s[k], time_s[k + 1] - time_s[k]) == "ok"
    messages = fmu.messages_with("warning")
    fmu.free()
    return [message for message in messages if JUMP_FRAGMENT in message]


def test_jumping_inputs_are_warned_about_once_and_alike_by_both_fmus(fmu_path, native_fmu_path, measurement,
                                                                    fitted):
    t = measurement.time_s[:400]
    x, v = measurement.displacement_mm[:400] / 1000.0, measurement.velocity_mm_s[:400] / 1000.0
    warnings = {}
    for name, path in (("pythonfmu", fmu_path), ("native", native_fmu_path)):
        warnings[name] = _run(path, fitted, x, v, t)
        assert len(warnings[name]) == 1, warnings[name]
        assert "identification.fmu_input" in warnings[name][0]
        assert "the displacement input x jumps in 31 of the last 50 steps" in warnings[name][0]
    assert warnings["pythonfmu"] == warnings["native"]


@pytest.mark.parametrize("inputs", ["helper", "sine_10Hz", "sine_30Hz"])
def test_consistent_inputs_raise_no_jump_warning(bushing_fmu, measurement, fitted, inputs):
    """The helper's table (no jumps) and a smooth x(t_k) with v = dx/dt(t_k), whose jumps x''*h^2/2
    count near the reversals only (at most 9 of 50 steps at 10 Hz, 24 at 30 Hz, 1 ms steps)."""
    if inputs == "helper":
        table = fmu_input((measurement.time_s[:400], measurement.displacement_mm[:400],
                           measurement.velocity_mm_s[:400]))
        t, x, v = table["time"], table["x"], table["v"]
    else:
        omega = 2.0 * math.pi * (10.0 if inputs == "sine_10Hz" else 30.0)
        t = np.arange(600) * 1e-3
        x, v = 2e-3 * np.sin(omega * t), 2e-3 * omega * np.cos(omega * t)
    assert _run(bushing_fmu, fitted, x, v, t) == []


def test_a_sampled_sine_through_the_helper_matches_simulate(bushing_fmu, fitted):
    """Without a measured velocity the path is the spline of the displacement, as in simulate."""
    t = np.arange(0.0, 0.5, 1e-3)
    x = 1.0 * np.sin(2 * np.pi * 2.0 * t)
    force = simulate_measurement(bushing_fmu, (t, x), start_values=PARAMS, step_size=2.5e-4)
    reference = simulate(PARAMS, t, x, steps_per_sample=4)
    assert np.max(np.abs(force - reference)) <= FORCE_TOLERANCE * np.max(np.abs(reference))


def test_a_six_axis_fmus_compiled_batch_counts_jumps_as_the_native_fmu_does(pythonfmu_model_fmus,
                                                                           native_model_fmus):
    """The six-axis FMU steps x and y (both the proposed model) in one compiled call, which counts
    their jumps itself: a velocity 30 % off dy/dt on axis y alone is warned about once, naming y,
    with the native FMU's words."""
    from fmu_src.fmi.axes import SIX_AXES
    t = np.arange(200) * 1e-3
    warnings = {}
    for name, path in (("pythonfmu", pythonfmu_model_fmus["six_axis"]), ("native", native_model_fmus["six_axis"])):
        fmu = BushingFmu(path, name, initial_inputs={})
        for k in range(t.size - 1):
            for number, axis in enumerate(SIX_AXES):
                omega, amplitude = 2.0 * math.pi * (5.0 + number), (1e-3 if number < 3 else 1e-2)
                fmu.set(axis.displacement, amplitude * math.sin(omega * t[k]))
                scale = 1.3 if axis.name == "y" else 1.0
                fmu.set(axis.velocity, scale * amplitude * omega * math.cos(omega * t[k]))
            assert fmu.do_step(1e-3) == "ok"
        warnings[name] = [message for message in fmu.messages_with("warning") if "jumps in" in message]
        fmu.free()
        assert len(warnings[name]) == 1, warnings[name]
        assert "the displacement input dy jumps in" in warnings[name][0]
    assert warnings["pythonfmu"] == warnings["native"]
