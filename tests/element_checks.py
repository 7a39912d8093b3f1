"""Checks every option element's tests make alike: a model's FMU against its forward model on a
sine, and the fit's exact Jacobian against central differences of the forward model."""
from __future__ import annotations

import shutil

import numpy as np
import pytest

from fmu_src.parameter_files import save_parameters


def sine_inputs(t, amplitude_m=2.5e-3, hz=3.0):
    """fmpy's input table of a sine of ``amplitude_m`` [m] at ``hz``: x [m], v = dx/dt [m/s]."""
    w = 2 * np.pi * hz
    signals = np.zeros(t.size, dtype=[("time", float), ("x", float), ("v", float)])
    signals["time"], signals["x"], signals["v"] = t, amplitude_m * np.sin(w * t), amplitude_m * w * np.cos(w * t)
    return signals


def assert_fmu_is_the_forward_model(kind: str, model, params: dict, folder, stop_s: float = 0.8):
    """The FMU of ``model`` with ``params`` (``kind``: pythonfmu, native2, native3) on a 3 Hz,
    2.5 mm sine at 1 ms steps gives the forward model's force to 1e-12 of its peak; returns that
    force [N] (a C compiler missing: the test skips)."""
    import build_fmu
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu
    from identification.forward.population import simulate_population_held
    if kind != "pythonfmu" and shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    file = save_parameters(folder / "params.json", params, model.name)
    fmu = (build_fmu.build_fmu(file, folder, model=model.name) if kind == "pythonfmu"
           else build_fmu.build_native_fmu(file, folder, model=model.name, fmi_version=int(kind[-1])).path)
    if kind != "native3":                # fmpy's validation reads FMI 2 model descriptions
        assert validate_fmu(str(fmu)) == []
    t = np.arange(0.0, stop_s, 1e-3)
    signals = sine_inputs(t)
    result = simulate_fmu(str(fmu), stop_time=t[-1], step_size=1e-3, output_interval=1e-3, input=signals,
                          output=["F"])
    want = simulate_population_held([model.check(params)], t, signals["x"] * 1e3, signals["v"] * 1e3, model=model)[0]
    np.testing.assert_allclose(result["F"], want[:len(result)], rtol=0, atol=1e-12 * np.max(np.abs(want)))
    return want


def assert_sensitivities_are_central_differences(model, row, points, step, tolerance=1e-5):
    """The fit's exact Jacobian (``population_sensitivities``) of ``model`` at the parameter row
    ``row`` (1 x d) over ``points`` equals central differences of the forward model, each column
    within ``tolerance`` of its largest entry; ``step(j, value)`` is column j's difference step."""
    from identification.forward.parameter_jacobian import population_sensitivities
    from identification.forward.population import simulate_population_at
    forces, sensitivities = population_sensitivities(row, np.eye(row.shape[1])[None], points, model=model)
    np.testing.assert_array_equal(forces[0], simulate_population_at(row, points, model=model)[0])
    for j in range(row.shape[1]):
        h = step(j, row[0, j])
        up, down = row.copy(), row.copy()
        up[0, j] += h
        down[0, j] -= h
        central = (simulate_population_at(up, points, model=model)[0]
                   - simulate_population_at(down, points, model=model)[0]) / (2 * h)
        scale = np.max(np.abs(central)) + 1e-9
        assert np.max(np.abs(central - sensitivities[0, :, j])) <= tolerance * scale, model.parameter_names[j]


def assert_six_axis_z_is_the_forward_model(model, params: dict, folder, stop_s: float = 0.8, amplitude_m=2.5e-3,
                                           hz=3.0):
    """Both six-axis FMUs (pythonfmu, native), ``model`` with ``params`` on z and the illustrative
    set's other axes, on a sine of z alone give the one-axis forward model's force Fz to 1e-12 of
    its peak (a C compiler missing: the test skips)."""
    import json

    import build_fmu
    from fmpy import simulate_fmu
    from conftest import DATA
    from identification.forward.population import simulate_population_held
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    document = json.loads((DATA / "params_six_axis_illustrative.json").read_text())
    document["axes"]["z"] = {"model": model.identifier, "parameters": params}
    file = folder / "six.json"
    file.write_text(json.dumps(document))
    t = np.arange(0.0, stop_s, 1e-3)
    names = ["dx", "vx", "dy", "vy", "dz", "vz", "rx", "wx", "ry", "wy", "rz", "wz"]
    signals = np.zeros(t.size, dtype=[("time", float)] + [(name, float) for name in names])
    w = 2 * np.pi * hz
    signals["time"], signals["dz"], signals["vz"] = t, amplitude_m * np.sin(w * t), amplitude_m * w * np.cos(w * t)
    want = simulate_population_held([model.check(params)], t, signals["dz"] * 1e3, signals["vz"] * 1e3, model=model)[0]
    for fmu in (build_fmu.build_fmu(file, folder / "python", model="six_axis"),
                build_fmu.build_native_fmu(file, folder / "native", model="six_axis").path):
        got = simulate_fmu(str(fmu), stop_time=t[-1], step_size=1e-3, output_interval=1e-3, input=signals,
                           output=["Fz"])["Fz"]
        np.testing.assert_allclose(got, want[:len(got)], rtol=0, atol=1e-12 * np.max(np.abs(want)))
