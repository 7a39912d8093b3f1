"""The native FMU (``build_fmu.py --native``): C generated from the model definitions, no Python in
the host. Same interface as the pythonfmu FMU, the same forces in co-simulation, model exchange
against scipy's Radau on the paper's equations, and a host without Python."""
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

import build_fmu
from conftest import paper_force, paper_parameters
from fmu_src.bushing_models import MODELS
from identification.protocols import Random, Sine, Step, sample_times
from model_exchange import simulate_model_exchange
from test_fmu_numerics import simulate_with_fmpy
from test_six_axis_fmu import axis_signals, run_with_fmpy

FMUS = (*MODELS, "six_axis")
MM = 1e-3


@pytest.fixture(scope="module")
def native_fmus(tmp_path_factory):
    """Each model's native FMU (FMI 2.0) with its default parameters."""
    folder = tmp_path_factory.mktemp("native")
    return {name: build_fmu.build_native_fmu(out_dir=folder, model=name).path for name in FMUS}


@pytest.fixture(scope="module")
def pythonfmu_fmus(tmp_path_factory):
    """Each model's pythonfmu FMU with the same parameters."""
    folder = tmp_path_factory.mktemp("pythonfmu")
    return {name: build_fmu.build_fmu(out_dir=folder, model=name) for name in FMUS}


@pytest.mark.parametrize("name", FMUS)
def test_native_fmu_validates_needs_no_python_and_has_the_pythonfmu_fmus_interface(native_fmus, pythonfmu_fmus,
                                                                                   name):
    assert validate_fmu(str(native_fmus[name])) == []
    native = read_model_description(str(native_fmus[name]))
    python = read_model_description(str(pythonfmu_fmus[name]))
    assert not native.coSimulation.needsExecutionTool and not native.modelExchange.needsExecutionTool
    identifier = "SixAxisBushing" if name == "six_axis" else MODELS[name].identifier
    assert native.coSimulation.modelIdentifier == native.modelExchange.modelIdentifier == identifier
    assert native.coSimulation.canGetAndSetFMUstate and native.coSimulation.canSerializeFMUstate
    def declared(v):
        return v.valueReference, v.causality, v.variability, v.unit, v.start and float(v.start), v.description

    shared = {v.name: declared(v) for v in python.modelVariables}
    mine = {v.name: declared(v) for v in native.modelVariables if v.name in shared}
    assert mine == shared    # every variable of the pythonfmu FMU, the same in every attribute
    extra = [v for v in native.modelVariables if v.name not in shared]
    assert all(v.name.startswith("der(") and v.derivative is not None for v in extra)   # model exchange's
    assert len(extra) == native.numberOfContinuousStates


SIGNALS = {
    "sine": lambda t: Sine(2.0, 10.0).signals(t),
    "step": lambda t: Step(2.0, 0.4, 1.0).signals(t),
    "random": lambda t: Random(2.0, 1.0, seed=3).signals(t),
    # the master passes the instantaneous velocity: the displacement jumps at every step
    "jumps": lambda t: (Sine(2.0, 10.0).signals(t)[0] + 0.02 * np.sin(2 * np.pi * 45 * t), Sine(2.0, 10.0).signals(t)[1]),
}


@pytest.mark.parametrize("signal", SIGNALS)
@pytest.mark.parametrize("name", MODELS)
def test_co_simulation_equals_the_pythonfmu_fmu(native_fmus, pythonfmu_fmus, name, signal):
    t = sample_times(0.6, 1000.0)
    x, v = SIGNALS[signal](t)
    native = simulate_with_fmpy(native_fmus[name], t, x, v)
    python = simulate_with_fmpy(pythonfmu_fmus[name], t, x, v)
    assert np.max(np.abs(native - python)) <= 1e-12 * np.max(np.abs(python))   # measured: equal, bit for bit


def test_six_axis_co_simulation_equals_the_pythonfmu_fmu(native_fmus, pythonfmu_fmus):
    t = np.arange(0.0, 0.4, 1e-3)
    signals = axis_signals(t)
    native, python = run_with_fmpy(native_fmus["six_axis"], t, signals), run_with_fmpy(pythonfmu_fmus["six_axis"], t,
                                                                                       signals)
    for output, values in python.items():
        assert np.max(np.abs(native[output] - values)) <= 1e-12 * np.max(np.abs(values)), output


def sine_functions(amplitude_mm, frequency_hz):
    omega = 2 * np.pi * frequency_hz
    return (lambda t: amplitude_mm * np.sin(omega * t)), (lambda t: amplitude_mm * omega * np.cos(omega * t))


def ramp_functions(amplitude_mm, rise_s):
    return (lambda t: amplitude_mm * np.clip(t / rise_s, 0.0, 1.0)), (lambda t: amplitude_mm / rise_s * (t < rise_s))


@pytest.mark.parametrize("case, functions, duration_s", [
    ("sine 2 mm 10 Hz", sine_functions(2.0, 10.0), 0.5),
    ("step 2 mm, rise 0.4 s", ramp_functions(2.0, 0.4), 1.0),
])
def test_model_exchange_with_cvode_follows_radau_on_the_papers_equations(native_fmus, case, functions, duration_s,
                                                                         capsys):
    # The host integrates y, z1, w, z2 itself (CVode, BDF, rtol 1e-8, event indicators at the
    # blocks' switches); the reference is scipy's Radau on eqs. 1-5 as tests/conftest.py types them.
    displacement, velocity = functions
    t = sample_times(duration_s, 1000.0)
    run = simulate_model_exchange(native_fmus["proposed"], t, lambda s: displacement(s) * MM,
                                  lambda s: float(velocity(s)) * MM)
    reference = paper_force(paper_parameters("table5"), t, displacement, velocity, rtol=1e-10, atol=1e-10)
    error = np.max(np.abs(run.force_N - reference)) / np.max(np.abs(reference))
    with capsys.disabled():
        print(f"\n  model exchange, {case}: {error:.1e} of the peak force, {run.events} events, {run.steps} CVode steps")
    assert error <= 1e-3


@pytest.mark.skipif(shutil.which("readelf") is None, reason="needs readelf (binutils)")
@pytest.mark.parametrize("name", ["proposed", "six_axis"])
def test_the_binary_links_no_python(native_fmus, name, tmp_path):
    import zipfile
    with zipfile.ZipFile(native_fmus[name]) as archive:
        binary = next(n for n in archive.namelist() if n.startswith("binaries/linux64/"))
        archive.extract(binary, tmp_path)
        sources = sorted(n for n in archive.namelist() if n.startswith("sources/"))
    dynamic = subprocess.run(["readelf", "-d", str(tmp_path / binary)], capture_output=True, text=True,
                             check=True).stdout
    needed = [line.split("[")[1].rstrip("]") for line in dynamic.splitlines() if "(NEEDED)" in line]
    assert needed and not any("python" in library for library in needed), needed
    assert "sources/bushing_model.c" in sources and "sources/fmi2Functions.h" in sources


@pytest.mark.skipif(shutil.which("gcc") is None, reason="needs gcc to build the C host")
def test_a_c_host_without_python_runs_the_native_fmu(native_fmus, tmp_path):
    from fmpy import extract
    from python_core import simulate_python_core
    from test_c_host import HOST_SOURCE
    host = tmp_path / "fmi2_host"
    subprocess.run(["gcc", "-O1", "-o", str(host), str(HOST_SOURCE), "-ldl", "-lm"], check=True)
    path = native_fmus["proposed"]
    description = read_model_description(str(path))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    unzipped = Path(extract(str(path)))
    library = unzipped / "binaries" / "linux64" / f"{description.coSimulation.modelIdentifier}.so"
    steps, h = 200, 1e-3
    result = subprocess.run([str(host), "-", str(library), description.guid, (unzipped / "resources").as_uri(),
                             str(refs["x"]), str(refs["v"]), str(refs["F"]), str(steps), str(h)],
                            capture_output=True, text=True, timeout=60, env={"PATH": "/usr/bin:/bin"})
    assert result.returncode == 0, result.stderr
    assert "python in process: no" in result.stderr
    rows = np.array([[float(value) for value in line.split()] for line in result.stdout.splitlines()])
    t = np.arange(steps + 1) * h
    x, v = Sine(2.0, 10.0).signals(t)
    # the host makes its inputs with C's sin and cos in metres: they differ from numpy's in the last bit
    np.testing.assert_allclose(rows[:, 1], simulate_python_core(paper_parameters("table5"), t, x, v)[1:], rtol=1e-9,
                               atol=1e-6)
