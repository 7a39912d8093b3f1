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
from fmu_src.fmi import fmu_inputs
from conftest import paper_force, paper_parameters
from fmu_src.model.registry import MODELS
from identification.measured.signals import Random, Sine, Step, sample_times
from model_exchange import simulate_model_exchange
from fmu_harness import simulate_with_fmpy
from test_six_axis_fmu import axis_signals, run_with_fmpy

FMUS = (*MODELS, "six_axis")
MM = 1e-3


@pytest.fixture(scope="module")
def native_fmus(native_model_fmus):
    """Each model's native FMU (FMI 2.0) with its default parameters (conftest)."""
    return native_model_fmus


@pytest.fixture(scope="module")
def pythonfmu_fmus(pythonfmu_model_fmus):
    """Each model's pythonfmu FMU with the same parameters (conftest)."""
    return pythonfmu_model_fmus


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
    extra = [v for v in native.modelVariables if v.name not in shared]     # model exchange's, numbered after
    derivatives = [v for v in extra if v.name.startswith("der(") and v.derivative is not None]
    indicators = [v for v in extra if v.name.startswith("event.") or ".event." in v.name]
    assert len(derivatives) == native.numberOfContinuousStates and len(indicators) == native.numberOfEventIndicators
    assert [v.causality for v in extra if v not in derivatives + indicators] == ["independent"]   # time
    assert len(extra) == len(derivatives) + len(indicators) + 1
    assert all(v.valueReference > max(p.valueReference for p in python.modelVariables) for v in extra)


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


def assert_six_axis_outputs_equal(fmu, reference_fmu, duration_s):
    """Every output of two six-axis FMUs through fmpy, a different sine on each axis: to 1e-12 of its peak."""
    t = np.arange(0.0, duration_s, 1e-3)
    signals = axis_signals(t)
    outputs, reference = run_with_fmpy(fmu, t, signals), run_with_fmpy(reference_fmu, t, signals)
    for output, values in reference.items():
        assert np.max(np.abs(outputs[output] - values)) <= 1e-12 * np.max(np.abs(values)), output


def test_six_axis_co_simulation_equals_the_pythonfmu_fmu(native_fmus, pythonfmu_fmus):
    assert_six_axis_outputs_equal(native_fmus["six_axis"], pythonfmu_fmus["six_axis"], 0.4)


def sine_functions(amplitude_mm, frequency_hz):
    omega = 2 * np.pi * frequency_hz
    return (lambda t: amplitude_mm * np.sin(omega * t)), (lambda t: amplitude_mm * omega * np.cos(omega * t))


def ramp_functions(amplitude_mm, rise_s):
    return (lambda t: amplitude_mm * np.clip(t / rise_s, 0.0, 1.0)), (lambda t: amplitude_mm / rise_s * (t < rise_s))


@pytest.mark.parametrize("case, functions, duration_s", [
    pytest.param("sine 2 mm 10 Hz", sine_functions(2.0, 10.0), 0.5, marks=pytest.mark.slow),
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


MINGW_GCC, MINGW_OBJDUMP = "x86_64-w64-mingw32-gcc", "x86_64-w64-mingw32-objdump"
WINE = shutil.which("wine64") or ("/usr/lib/wine/wine64" if Path("/usr/lib/wine/wine64").exists() else None)


def extracted_binary(fmu, platform, tmp_path):
    import zipfile
    with zipfile.ZipFile(fmu) as archive:
        names = [n for n in archive.namelist() if n.startswith(f"binaries/{platform}/")]
        if not names:
            pytest.skip(f"the FMU has no {platform} binary (build_fmu.py builds it where mingw-w64 is installed: "
                        "apt-get install gcc-mingw-w64-x86-64)")
        archive.extractall(tmp_path)
    return tmp_path / names[0]


@pytest.mark.skipif(shutil.which(MINGW_OBJDUMP) is None,
                    reason="needs mingw-w64's objdump (Debian: apt-get install gcc-mingw-w64-x86-64)")
def test_the_win64_dll_is_pe32_plus_exports_fmi2_and_imports_no_python(native_fmu_path, tmp_path):
    dll = extracted_binary(native_fmu_path, "win64", tmp_path)
    headers = subprocess.run([MINGW_OBJDUMP, "-p", str(dll)], capture_output=True, text=True, check=True).stdout
    assert "Magic\t\t\t020b" in headers                      # PE32+ (64 bit)
    imports = [line.split(":", 1)[1].strip() for line in headers.splitlines() if "DLL Name:" in line]
    assert imports and not any("python" in name.lower() for name in imports), imports
    for function in ("fmi2Instantiate", "fmi2DoStep", "fmi2GetDerivatives", "fmi2SerializeFMUstate"):
        assert f"] {function}\n" in headers + "\n", function


@pytest.mark.slow
@pytest.mark.skipif(shutil.which(MINGW_GCC) is None or WINE is None or shutil.which("gcc") is None,
                    reason="needs gcc, mingw-w64 and wine (Debian: apt-get install gcc-mingw-w64-x86-64 wine64)")
def test_the_win64_dll_under_wine_gives_the_forces_of_linux64(native_fmu_path, tmp_path):
    from test_c_host import HOST_SOURCE
    path = native_fmu_path
    description = read_model_description(str(path))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    dll, so = extracted_binary(path, "win64", tmp_path), extracted_binary(path, "linux64", tmp_path)
    subprocess.run([MINGW_GCC, "-O1", "-o", str(tmp_path / "host.exe"), str(HOST_SOURCE)], check=True)
    subprocess.run(["gcc", "-O1", "-o", str(tmp_path / "host"), str(HOST_SOURCE), "-ldl", "-lm"], check=True)
    arguments = [description.guid, "file:///", str(refs["x"]), str(refs["v"]), str(refs["F"]), "300", "0.001"]
    windows = subprocess.run([WINE, str(tmp_path / "host.exe"), "-", str(dll), *arguments], capture_output=True,
                             text=True, timeout=300, env={"WINEDEBUG": "-all", "HOME": str(Path.home()),
                                                          "PATH": "/usr/bin:/bin"})
    linux = subprocess.run([str(tmp_path / "host"), "-", str(so), *arguments], capture_output=True, text=True,
                           timeout=60)
    assert windows.returncode == 0 and linux.returncode == 0, windows.stderr[-2000:]
    forces = [np.array([float(line.split()[1]) for line in run.stdout.splitlines()]) for run in (windows, linux)]
    assert forces[0].size == forces[1].size == 300
    # two C libraries' sin, cos and pow may differ in the last bit: 1e-12 of the peak force
    assert np.max(np.abs(forces[0] - forces[1])) <= 1e-12 * np.max(np.abs(forces[1]))


@pytest.fixture(scope="module")
def native_fmi3_fmus(native_model_fmi3_fmus):
    """Each model's native FMU as FMI 3.0 (conftest)."""
    return native_model_fmi3_fmus


@pytest.mark.parametrize("name", FMUS)
def test_fmi3_fmu_validates_and_declares_the_fmi2_fmus_variables(native_fmus, native_fmi3_fmus, name):
    assert validate_fmu(str(native_fmi3_fmus[name])) == []
    fmi3, fmi2 = (read_model_description(str(fmus[name])) for fmus in (native_fmi3_fmus, native_fmus))
    assert fmi3.fmiVersion == "3.0" and not fmi3.coSimulation.needsExecutionTool
    assert [(v.name, v.valueReference, v.causality, v.unit) for v in fmi3.modelVariables] == \
        [(v.name, v.valueReference, v.causality, v.unit) for v in fmi2.modelVariables]
    assert fmi3.numberOfEventIndicators == fmi2.numberOfEventIndicators


@pytest.mark.parametrize("signal", ["sine", "jumps"])
@pytest.mark.parametrize("name", MODELS)
def test_fmi3_co_simulation_equals_fmi2(native_fmus, native_fmi3_fmus, name, signal):
    t = sample_times(0.4, 1000.0)
    x, v = SIGNALS[signal](t)
    fmi2 = simulate_with_fmpy(native_fmus[name], t, x, v)
    fmi3 = simulate_with_fmpy(native_fmi3_fmus[name], t, x, v)
    assert np.max(np.abs(fmi3 - fmi2)) <= 1e-12 * np.max(np.abs(fmi2))


def test_fmi3_six_axis_co_simulation_equals_fmi2(native_fmus, native_fmi3_fmus):
    assert_six_axis_outputs_equal(native_fmi3_fmus["six_axis"], native_fmus["six_axis"], 0.3)


def test_fmi3_model_exchange_equals_fmi2s_and_follows_radau(native_fmus, native_fmi3_fmus):
    displacement, velocity = sine_functions(2.0, 10.0)
    t = sample_times(0.12, 1000.0)      # through the first reversal of both blocks
    runs = [simulate_model_exchange(fmus["proposed"], t, lambda s: displacement(s) * MM,
                                    lambda s: float(velocity(s)) * MM) for fmus in (native_fmus, native_fmi3_fmus)]
    np.testing.assert_array_equal(runs[1].force_N, runs[0].force_N)      # the same C, the same integrator
    assert (runs[1].events, runs[1].steps) == (runs[0].events, runs[0].steps)
    reference = paper_force(paper_parameters("table5"), t, displacement, velocity, rtol=1e-10, atol=1e-10)
    assert np.max(np.abs(runs[1].force_N - reference)) <= 1e-3 * np.max(np.abs(reference))


def test_fmi3_state_is_saved_restored_and_serialized_bit_for_bit(native_fmi3_fmus):
    from fmpy import extract
    from fmpy.fmi3 import FMU3Slave
    path = native_fmi3_fmus["proposed"]
    description = read_model_description(str(path))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    fmu = FMU3Slave(guid=description.guid, unzipDirectory=extract(str(path)),
                    modelIdentifier=description.coSimulation.modelIdentifier, instanceName="fmi3")
    fmu.instantiate()
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    t = np.arange(0.0, 0.1, 1e-3)
    x, v = Sine(2.0, 10.0).signals(t)

    def drive(first, count):
        forces = []
        for k in range(first, first + count):
            fmu.setFloat64([refs["x"], refs["v"]], [x[k] * MM, v[k] * MM])
            fmu.doStep(currentCommunicationPoint=t[k], communicationStepSize=1e-3)
            forces.append(fmu.getFloat64([refs["F"], refs["z1"], refs["w"]]))
        return forces

    drive(0, 40)
    saved = fmu.getFMUState()
    serialized = fmu.serializeFMUState(saved)
    first = drive(40, 40)
    fmu.setFMUState(saved)
    assert drive(40, 40) == first
    fmu.setFMUState(fmu.deserializeFMUState(serialized))
    assert drive(40, 40) == first
    fmu.freeFMUState(saved)
    fmu.terminate()
    fmu.freeInstance()


def sanitizers_work(tmp_path) -> bool:
    probe = tmp_path / "probe.c"
    probe.write_text("int main(void) { return 0; }\n")
    result = subprocess.run(["gcc", "-fsanitize=address,undefined", "-o", str(tmp_path / "probe"), str(probe)],
                            capture_output=True)
    return result.returncode == 0 and subprocess.run([str(tmp_path / "probe")], capture_output=True).returncode == 0


@pytest.mark.skipif(shutil.which("gcc") is None, reason="needs gcc")
def test_a_sanitizer_build_survives_bad_inputs_state_restores_and_1000_instances(tmp_path):
    from fmu_src.fmi.native.build import FLAGS, WARNINGS, write_sources
    from test_c_host import HOST_SOURCE
    if not sanitizers_work(tmp_path):
        pytest.skip("gcc here cannot build and run with -fsanitize=address,undefined (libasan, libubsan)")
    identifier, _, axes, _ = fmu_inputs.fmu_axes()
    generated = write_sources(tmp_path / "sources", axes, identifier, 2)
    sanitize = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer", "-g"]
    library = tmp_path / f"{identifier}.so"
    subprocess.run(["gcc", *WARNINGS, *[f for f in FLAGS if not f.startswith("-O")], "-O1", *sanitize, "-shared", "-I",
                    str(tmp_path / "sources"), "-o", str(library), str(tmp_path / "sources" / f"{identifier}.c"), "-lm"],
                   check=True)
    master = tmp_path / "native_checks"
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", *sanitize, "-I", str(tmp_path / "sources"), "-o",
                    str(master), str(HOST_SOURCE.with_name("native_checks.c")), "-ldl", "-lm"], check=True)
    refs = {v.name: v.value_reference for v in __import__("fmu_src.fmi.native.generate", fromlist=["all_variables"])
            .all_variables(axes)}
    result = subprocess.run([str(master), str(library), generated.token, str(refs["x"]), str(refs["v"]),
                             str(refs["F"]), str(refs["c1"])], capture_output=True, text=True, timeout=300,
                            env={"PATH": "/usr/bin:/bin", "ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0",
                                 "UBSAN_OPTIONS": "print_stacktrace=1"})
    assert result.returncode == 0, result.stderr[-4000:]
    assert "all checks passed" in result.stdout and "runtime error" not in result.stderr


@pytest.mark.slow
def test_a_fresh_environment_with_fmpy_and_without_pythonfmu_runs_the_native_fmu(native_fmus, tmp_path):
    import venv
    from fmpy import __version__ as fmpy_version
    environment = tmp_path / "venv"
    venv.EnvBuilder(with_pip=True).create(environment)
    python = environment / "bin" / "python"
    installed = subprocess.run([str(python), "-m", "pip", "install", "-q", f"fmpy=={fmpy_version}"],
                               capture_output=True, text=True, timeout=900)
    assert installed.returncode == 0, installed.stderr[-3000:]
    script = ("import importlib.util, sys, numpy as np\n"
              "from fmpy import simulate_fmu\n"
              "assert importlib.util.find_spec('pythonfmu') is None, 'pythonfmu is installed'\n"
              "t = np.arange(0, 0.201, 1e-3)\n"
              "table = np.array(list(zip(t, 2e-3*np.sin(20*np.pi*t), 2e-3*20*np.pi*np.cos(20*np.pi*t))),\n"
              "                 dtype=[('time', float), ('x', float), ('v', float)])\n"
              "result = simulate_fmu(sys.argv[1], stop_time=0.2, step_size=1e-3, input=table, output=['F'])\n"
              "print('peak', np.max(np.abs(result['F'])))\n")
    run = subprocess.run([str(python), "-c", script, str(native_fmus["proposed"])], capture_output=True, text=True,
                         timeout=300, cwd=tmp_path)
    assert run.returncode == 0, run.stderr[-3000:]
    t = sample_times(0.2, 1000.0)
    x, v = Sine(2.0, 10.0).signals(t)
    here = simulate_with_fmpy(native_fmus["proposed"], t, x, v)
    assert float(run.stdout.split()[-1]) == pytest.approx(np.max(np.abs(here)), rel=1e-9)


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("cmake") is None or shutil.which("cc") is None, reason="needs cmake and a C compiler")
@pytest.mark.parametrize("fmi_version", [2, 3])
def test_any_tool_can_build_the_binary_from_the_fmus_sources(native_fmus, native_fmi3_fmus, fmi_version, tmp_path):
    # What a user on macOS or ARM does: fmpy compiles sources/ as the modelDescription (FMI 2) or
    # buildDescription.xml (FMI 3) lists them, with its own CMake project and no flags of ours.
    import zipfile
    from fmpy.build import build_platform_binary
    path = (native_fmus if fmi_version == 2 else native_fmi3_fmus)["proposed"]
    unzipped = tmp_path / "unzipped"
    with zipfile.ZipFile(path) as archive:
        archive.extractall(unzipped)
    shutil.rmtree(unzipped / "binaries")
    (tmp_path / "build").mkdir()
    build_platform_binary(unzipped, tmp_path / "build")
    rebuilt = tmp_path / "rebuilt.fmu"
    with zipfile.ZipFile(rebuilt, "w") as archive:
        for file in unzipped.rglob("*"):
            archive.write(file, file.relative_to(unzipped).as_posix())
    t = sample_times(0.3, 1000.0)
    x, v = SIGNALS["jumps"](t)
    original, own = simulate_with_fmpy(path, t, x, v), simulate_with_fmpy(rebuilt, t, x, v)
    assert np.max(np.abs(own - original)) <= 1e-12 * np.max(np.abs(original))
