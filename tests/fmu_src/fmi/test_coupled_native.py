"""Coupled groups in the native six-axis FMU (FMI 2 and 3): the same forces as the pythonfmu FMU and
the coupled kernels, model exchange's derivatives as the kernels', its directional derivatives
against central differences and its ModelStructure against the Jacobian's zeros (the tests of
``test_fmu_directional_derivatives`` on the coupled FMU), FMU state, and the refusals."""
import math

import numpy as np
import pytest

import build_fmu
from fmu_src.fmi import fmu_inputs
import test_fmu_directional_derivatives as derivatives
from fmu_harness import BushingFmu
from fmu_src.fmi.axes import SIX_AXES
from fmu_src.parameter_files import read_six_axis
from test_coupled_six_axis import PORTS, STEP_S, assert_state_round_trip, plane_path, run_fmu, run_group

# the whole module builds the coupled six-axis FMU's native twins (FMI 2 and 3): the slow tier
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def coupled(coupled_six_axis_fmus):
    """The six-axis set with a spherical (the proposed model on x, y, z) and a conical group (Berg on
    rx, ry), and its native FMUs, FMI 2 and 3, and pythonfmu FMU."""
    fmus = coupled_six_axis_fmus
    return {"file": fmus["file"], 2: fmus["fmi2"], 3: fmus["fmi3"], "pythonfmu": fmus["pythonfmu"]}


t = np.arange(0.0, 0.3 + STEP_S / 2, STEP_S)


def test_the_native_groups_give_the_coupled_kernels_forces_as_the_pythonfmu_fmu_does(coupled):
    six = read_six_axis(coupled["file"])
    xy = plane_path(t)
    z = 0.5 * np.sin(2 * math.pi * 4.1 * t)
    tilt = 0.01 * plane_path(t, 1.0)
    paths = {"x": xy[:, 0], "y": xy[:, 1], "z": z, "rx": tilt[:, 0], "ry": tilt[:, 1],
             "rz": 0.02 * np.sin(2 * math.pi * 2.0 * t)}
    native, python = run_fmu(coupled[2], paths), run_fmu(coupled["pythonfmu"], paths)
    for name in native:
        assert np.max(np.abs(native[name] - python[name])) <= 1e-12 * max(1.0, np.max(np.abs(python[name]))), name
    expected = run_group(six.axes["x"].model, six.axes["x"].parameters, np.column_stack([xy, z]))
    assert np.max(np.abs(np.column_stack([native["Fx"], native["Fy"], native["Fz"]]) - expected)) \
        <= 1e-12 * np.max(np.abs(expected))
    tilted = run_group(six.axes["rx"].model, six.axes["rx"].parameters, tilt, rotational=True)
    assert np.max(np.abs(np.column_stack([native["Mx"], native["My"]]) - tilted[:, :2] * 1e-3)) \
        <= 1e-12 * np.max(np.abs(tilted * 1e-3))


def test_model_exchange_gives_the_coupled_kernels_rates(coupled):
    six = read_six_axis(coupled["file"])
    opened = derivatives.Opened(coupled[2], "me")
    try:
        rng = np.random.default_rng(2)
        states = [derivatives.nominal(s) * rng.uniform(-0.5, 0.5) for s in opened.states]
        inputs = derivatives.random_inputs(opened, rng)
        opened.set_states(states)
        opened.set_inputs(inputs)
        rates = dict(zip((v.name for v in opened.derivatives), opened.get(opened.derivatives)))
        model = six.axes["x"].model
        kernels, m = model.coupled, model.constants(six.axes["x"].parameters)
        names = {v.name: value for v, value in zip(opened.states, states)}
        port = {v.name: value for v, value in zip(opened.inputs, inputs)}
        flat = [0.0] * kernels.size
        for i, spec in enumerate(kernels.states):
            for c, axis in enumerate("xyz"):
                unit, scale = SIX_AXES[c].state_port(spec.unit)
                flat[3 * i + c] = names[f"{axis}.{spec.name}"] / scale
        x = tuple(port[f"d{axis}"] * 1000.0 for axis in "xyz")
        v = tuple(port[f"v{axis}"] * 1000.0 for axis in "xyz")
        expected = kernels.derivatives(m, tuple(flat), x, v)
        for i, spec in enumerate(kernels.states):
            for c, axis in enumerate("xyz"):
                unit, scale = SIX_AXES[c].state_port(spec.unit)
                got = rates[f"der({axis}.{spec.name})"]
                assert got == pytest.approx(expected[3 * i + c] * scale, rel=1e-12, abs=1e-12 * abs(scale)), \
                    (axis, spec.name)
    finally:
        opened.free()


@pytest.fixture(scope="module")
def fmus(coupled):
    return {2: {"coupled": coupled[2]}, 3: {"coupled": coupled[3]}}


@pytest.mark.parametrize("version", derivatives.VERSIONS)
def test_model_exchange_jacobian_equals_central_differences(fmus, version):
    derivatives.test_model_exchange_jacobian_equals_central_differences(fmus, "coupled", version)


@pytest.mark.parametrize("version", derivatives.VERSIONS)
def test_co_simulation_jacobian_equals_differences_of_the_output(fmus, version, monkeypatch):
    # a smaller step than one axis's: the coupled friction's stiffness after a reversal depends on the
    # travel's direction (R = F_max*d/|d| - F_s), which turns on the scale of the travel since the
    # reversal (|d| ~ 5e-5 rad after a step near a turning point), so a difference over 1e-8 rad
    # already differs by 2e-4; over 1e-11 rad the second-order one-sided difference is exact to 1e-9
    monkeypatch.setattr(derivatives, "CS_STEP", 1e-9)
    derivatives.test_co_simulation_dF_dx_dF_dv_are_those_of_the_output_the_fmu_returns(fmus, "coupled", version)


@pytest.mark.parametrize("interface", ["me", "cs"])
def test_the_adjoint_is_the_transposed_jacobian(fmus, interface):
    derivatives.test_the_adjoint_is_the_transposed_jacobian(fmus, "coupled", interface)


@pytest.mark.parametrize("version", derivatives.VERSIONS)
def test_model_structure_lists_exactly_the_knowns_the_derivatives_depend_on(fmus, version):
    derivatives.test_model_structure_lists_exactly_the_knowns_the_derivatives_depend_on(fmus, "coupled", version)


@pytest.mark.slow
def test_never_a_non_finite_derivative(fmus):
    derivatives.test_never_a_non_finite_derivative_over_10000_points_switches_included(fmus, "coupled")


def test_a_groups_state_travels_with_the_native_fmu_state_and_a_mismatch_is_refused(coupled):
    assert_state_round_trip(coupled[2])
    fmu = BushingFmu(coupled[2], initial_inputs={name: 0.0 for name in PORTS})
    try:
        assert fmu.do_step(STEP_S) == "ok"
        fmu.set("z.k0", 1000.0)
        assert fmu.do_step(STEP_S) == "discard"
        errors = " ".join(fmu.messages_with("error"))
        assert "the spherical group (x, y, z): x.k0 = 2393.28, z.k0 = 1000.0 [N/mm] differ" in errors
    finally:
        fmu.free()


SANITIZED_RUN = r'''
import sys, zipfile, numpy as np
sys.path[0:0] = sys.argv[2:]     # this test's folder and tests/ (its helpers)
import test_fmu_directional_derivatives as derivatives
path = sys.argv[1]
cs = derivatives.Opened(path, "cs")
derivatives.run_sine(cs, 200)
cs.jacobian(cs.outputs, cs.inputs)
saved = cs.fmu.getFMUstate()
derivatives.run_sine(cs, 20)
cs.fmu.setFMUstate(saved)
data = cs.fmu.serializeFMUstate(saved)
cs.fmu.setFMUstate(cs.fmu.deSerializeFMUstate(data))
refs = {v.name: v.valueReference for v in cs.description.modelVariables}
cs.fmu.setReal([refs["y.k0"]], [1.0])                 # the group's axes apart: refused, nothing lost
try:
    cs.step(1e-3)
except Exception:
    pass
cs.fmu.setReal([refs["y.k0"]], [cs.fmu.getReal([refs["x.k0"]])[0]])
cs.fmu.setReal([refs["dy"]], [float("nan")])         # a NaN input: refused
try:
    cs.step(1e-3)
except Exception:
    pass
cs.fmu.setReal([refs["dy"]], [2.0])                  # millimetres as metres: refused
try:
    cs.step(1e-3)
except Exception:
    pass
cs.free()
me = derivatives.Opened(path, "me")
rng = np.random.default_rng(1)
for _ in range(50):
    me.set_states([derivatives.nominal(s) * rng.uniform(-1.0, 1.0) for s in me.states])
    me.set_inputs(derivatives.random_inputs(me, rng))
    me.get(me.derivatives), me.event_indicators(), me.jacobian(me.outputs + me.derivatives, me.states + me.inputs)
me.free()
print("all checks passed")
'''


@pytest.mark.slow
def test_a_sanitizer_build_of_the_coupled_groups_survives_runs_refusals_and_state(coupled, tmp_path):
    """The coupled native FMU compiled with AddressSanitizer and UBSan, driven from Python (libasan
    preloaded): co-simulation, directional derivatives, FMU state and its serialization, a group
    set apart, a NaN input, a 2 m jump, model exchange's rates, indicators and Jacobian."""
    import shutil
    import subprocess
    import sys
    import zipfile
    from pathlib import Path
    from fmu_src.fmi.native.build import FLAGS, WARNINGS, write_sources
    from test_native_fmu import sanitizers_work
    if shutil.which("gcc") is None or not sanitizers_work(tmp_path):
        pytest.skip("gcc here cannot build and run with -fsanitize=address,undefined (libasan, libubsan)")
    identifier, _, axes, document = fmu_inputs.fmu_axes(coupled["file"], "six_axis")
    write_sources(tmp_path / "sources", axes, identifier, 2, fmu_inputs.groups_of(document))
    sanitize = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer", "-g"]
    library = tmp_path / f"{identifier}.so"
    subprocess.run(["gcc", *WARNINGS, *[f for f in FLAGS if not f.startswith("-O")], "-O1", *sanitize, "-shared",
                    "-I", str(tmp_path / "sources"), "-o", str(library), str(tmp_path / "sources" / f"{identifier}.c"),
                    "-lm"], check=True)
    sanitized = tmp_path / f"{identifier}.fmu"
    with zipfile.ZipFile(coupled[2]) as source, zipfile.ZipFile(sanitized, "w") as target:
        for item in source.infolist():
            data = library.read_bytes() if item.filename.endswith(f"linux64/{identifier}.so") else source.read(item)
            target.writestr(item, data)
    libasan = subprocess.run(["gcc", "-print-file-name=libasan.so"], capture_output=True, text=True).stdout.strip()
    environment = {"PATH": "/usr/bin:/bin", "LD_PRELOAD": libasan, "PYTHONPATH": str(Path(build_fmu.__file__).parent),
                   "ASAN_OPTIONS": "detect_leaks=0:abort_on_error=0", "UBSAN_OPTIONS": "print_stacktrace=1"}
    result = subprocess.run([sys.executable, "-c", SANITIZED_RUN, str(sanitized),
                             str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[2])],
                            capture_output=True, text=True, timeout=600, env=environment)
    assert result.returncode == 0, result.stderr[-4000:]
    assert "all checks passed" in result.stdout and "runtime error" not in result.stderr
