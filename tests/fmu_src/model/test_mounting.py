"""Every axis mounts its model with an offset and a preload, as MSC Adams' BUSHING does:
F = model(x - offset) + preload (definition.MOUNTING_SPECS), in the pythonfmu and the native
FMUs, one axis and six, and in the identification's simulate and predict. 0 and 0 give the model's forces as
its kernels compute them, bit for bit."""
import math

import numpy as np
import pytest

from conftest import DATA
from fmu_harness import BushingFmu, kernel_forces
from fmu_src.fmi.axes import SIX_AXES
from fmu_src.model.registry import MODELS, get_model
from fmu_src.model.integration import DEFAULT_MAX_SUBSTEPS
from fmu_src.parameter_files import read_parameter_set, read_six_axis
from identification.forward.simulate import simulate

STEP_S = 1e-3
t = np.arange(0.0, 0.3 + STEP_S / 2, STEP_S)
PATH_MM = 1.5 * np.sin(2 * math.pi * 7 * t) + 0.4 * np.sin(2 * math.pi * 23 * t + 0.3)
OFFSET_MM, PRELOAD_N = 0.75, -180.0


def run_fmu(fmu_path, x_mm, start_values=None, prefix="", unit=1e-3):
    """The output after every step of the displacement ``x_mm`` (kernel units: mm, or rad with
    ``unit`` 1) on one axis (``prefix``: the six-axis FMU's axis, its ports named by ``ports``)."""
    axis = next((a for a in SIX_AXES if a.prefix == prefix), None)
    x, v, out = (axis.displacement, axis.velocity, axis.output) if axis else ("x", "v", "F")
    inputs = {x: x_mm[0] * unit, v: 0.0}
    if axis:
        inputs = {name: 0.0 for a in SIX_AXES for name in (a.displacement, a.velocity)} | inputs
    fmu = BushingFmu(fmu_path, start_values=start_values or {}, initial_inputs=inputs)
    forces = []
    try:
        for k in range(len(x_mm) - 1):
            fmu.set(x, x_mm[k] * unit)
            fmu.set(v, (x_mm[k + 1] - x_mm[k]) / STEP_S * unit)
            assert fmu.do_step(STEP_S) == "ok"
            forces.append(fmu.get(out))
    finally:
        fmu.free()
    return np.array(forces)


def run_kernels(model, params, x_mm):
    """The model's force after every step, its kernels in plain Python (relaxed at x_mm[0]), fed
    as the FMU feeds them."""
    return kernel_forces(model, params, x_mm, STEP_S)


def mounting_of(model, offset, preload):
    """Start values of the mounting (a Kelvin-Voigt model's preload is its own parameter)."""
    return {"offset": offset, "preload": preload}


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("kind", ["pythonfmu", "native"])
def test_the_mounting_shifts_the_model_and_adds_the_preload(name, kind, pythonfmu_model_fmus, native_model_fmus):
    fmu = (pythonfmu_model_fmus if kind == "pythonfmu" else native_model_fmus)[name]
    model = get_model(name)
    params = read_parameter_set(DATA / model.default_file).parameters
    plain = run_fmu(fmu, PATH_MM)
    mounted = run_fmu(fmu, PATH_MM + OFFSET_MM, mounting_of(model, OFFSET_MM, PRELOAD_N + params.get("preload", 0.0)))
    # the offset is subtracted in the kernel's units: x + offset - offset is x to rounding
    assert np.max(np.abs(mounted - PRELOAD_N - plain)) <= 1e-12 * np.max(np.abs(plain))
    # 0 and 0: the kernels' forces, bit for bit (the pythonfmu FMU runs them; the C is translated
    # from them, compiled without contraction)
    assert np.array_equal(plain, run_kernels(model, params, PATH_MM))


def test_a_changed_offset_moves_the_model_as_a_displacement_jump(native_model_fmus, pythonfmu_model_fmus):
    # F after the change is the model's at x - offset, the state carried through the jump the dashpots take
    outputs = []
    for fmu_path in (pythonfmu_model_fmus["proposed"], native_model_fmus["proposed"]):
        fmu = BushingFmu(fmu_path, initial_inputs={"x": 0.001, "v": 0.0})
        try:
            assert fmu.do_step(STEP_S) == "ok"
            before = fmu.get("F")
            fmu.set("offset", 0.5)
            outputs.append((before, fmu.get("F")))
        finally:
            fmu.free()
    model = get_model("proposed")
    m = model.constants(read_parameter_set(DATA / model.default_file).parameters)
    state = model.initial_state(m, 1.0)
    state, _, _ = model.step(m, state, 1.0, 1.0, 0.0, STEP_S, DEFAULT_MAX_SUBSTEPS)
    jumped, status = model.jump(m, state, -0.5)
    expected = model.force(m, jumped, 0.5, 0.0)
    for before, after in outputs:
        assert after == pytest.approx(expected, rel=1e-12) and abs(after) < abs(before)


@pytest.mark.parametrize("kind", ["pythonfmu", "native"])
def test_every_axis_of_the_six_axis_fmu_takes_its_mounting(kind, pythonfmu_model_fmus, native_model_fmus):
    fmu = (pythonfmu_model_fmus if kind == "pythonfmu" else native_model_fmus)["six_axis"]
    six = read_six_axis(DATA / "params_six_axis_illustrative.json")
    for axis in SIX_AXES:
        unit = 1.0 if axis.rotational else 1e-3        # port per kernel unit: rad, or m per mm
        scale = 1e-3 if axis.rotational else 1.0       # port per kernel force: N.m per N.mm, or N
        path = PATH_MM * (0.01 if axis.rotational else 1.0)
        offset = OFFSET_MM * (0.01 if axis.rotational else 1.0)
        own = six.axes[axis.name].parameters.get("preload", 0.0)
        plain = run_fmu(fmu, path, prefix=axis.prefix, unit=unit)
        mounted = run_fmu(fmu, path + offset, {f"{axis.prefix}offset": offset, f"{axis.prefix}preload": 1000 + own},
                          prefix=axis.prefix, unit=unit)
        assert np.max(np.abs(mounted - 1000 * scale - plain)) <= 1e-12 * np.max(np.abs(plain)), axis.name


@pytest.mark.parametrize("name", ["proposed", "berg"])
def test_simulate_takes_the_mounting_of_a_parameter_set(name):
    model = get_model(name)
    params = read_parameter_set(DATA / model.default_file).parameters
    plain = simulate(params, t, PATH_MM, model=name)
    mounted = simulate(dict(params, offset=OFFSET_MM, preload=PRELOAD_N), t, PATH_MM + OFFSET_MM, model=name)
    assert np.max(np.abs(mounted - PRELOAD_N - plain)) <= 1e-12 * np.max(np.abs(plain))
    assert np.array_equal(simulate(dict(params, offset=0.0, preload=0.0), t, PATH_MM, model=name), plain)


def test_predict_takes_each_members_mounting():
    from identification.analysis.predict import predict
    params = read_parameter_set(DATA / "params_table5_combined.json").parameters
    plain = simulate(params, t, PATH_MM)
    members = [dict(params, offset=OFFSET_MM, preload=PRELOAD_N), dict(params, offset=0.0, preload=0.0)]
    prediction = predict(members, t, PATH_MM + OFFSET_MM)
    assert np.max(np.abs(prediction.force_N - PRELOAD_N - plain)) <= 1e-12 * np.max(np.abs(plain))
    # the second member, unmounted, sees the path OFFSET_MM further out: the band holds both
    assert np.array_equal(np.minimum(prediction.force_N, simulate(params, t, PATH_MM + OFFSET_MM)), prediction.lower_N)


def test_a_mounting_that_is_not_a_finite_number_is_refused_by_name():
    from fmu_src.model.parameter_specs import ParameterError
    with pytest.raises(ParameterError, match=r"offset = nan \[mm\] must be a finite number"):
        get_model("proposed").check(dict(read_parameter_set(DATA / "params_table5_combined.json").parameters,
                                         offset=math.nan))
    with pytest.raises(ParameterError, match="unknown parameter names \\['preload2'\\]"):
        get_model("kelvin_voigt").check({"k": 1.0, "c": 1.0, "preload": 0.0, "preload2": 1.0})
