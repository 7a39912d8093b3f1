"""An FMU's axis starts holding a force at rest when asked (definition.HELD_FORCE_SPEC,
``held_force``): a friction element stuck with its slider deflected, as a friction device holds
what the test before left in it. Both FMUs start there, the identification's simulate does the
same for a set that carries it, 0 is the relaxed start, and a coupled group refuses it.

The references are independent of the models' resting_state: the asymmetric element's deflection
is the root of its dead zone found by scipy's brentq, the single Bouc-Wen element's hysteretic
force the held force itself."""
import math

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from scipy.optimize import brentq

from conftest import DATA
from fmu_harness import BushingFmu, kernel_forces
from fmu_src.fmi.axes import SIX_AXES
from fmu_src.model.elements import dead_zone
from fmu_src.model.parameter_specs import ParameterError
from fmu_src.model.registry import MODELS, get_model
from fmu_src.parameter_files import read_parameter_set, read_six_axis, six_axis_document
from identification.forward.simulate import simulate

STEP_S = 1e-3
t = np.arange(0.0, 0.4 + STEP_S / 2, STEP_S)
PATH_MM = 1.5 * np.sin(2 * math.pi * 5 * t) * np.minimum(t / 0.1, 1.0)   # from rest at 0, growing to slips
HELD_N = {"asymmetric_bouc_wen": 700.0, "single_bouc_wen": -250.0}   # within each one's slide level
PRELOAD_N = 35.0


def defaults(name):
    return read_parameter_set(DATA / get_model(name).default_file).parameters


def holding_state(name, params, held):
    """The state at rest at 0 holding ``held`` [N], from the model's equations alone."""
    if name == "asymmetric_bouc_wen":       # k0*0 + A*D(e) = held, the element stuck (q = 1)
        p = params
        e = brentq(lambda e: p["A"] * dead_zone(e, p["gap"], p["width"]) - held, 0.0, 10.0, xtol=1e-15, rtol=1e-15)
        return (e, 1.0)
    return (held / params["alpha"],)        # single Bouc-Wen: F = c0*v + k0*x + alpha*z


def run_fmu(fmu_path, start_values):
    """The output right after initialisation, then after every step along PATH_MM."""
    fmu = BushingFmu(fmu_path, start_values=start_values, initial_inputs={"x": 0.0, "v": 0.0})
    try:
        forces = [fmu.get("F")]
        for k in range(len(PATH_MM) - 1):
            fmu.set("x", PATH_MM[k] * 1e-3)
            fmu.set("v", (PATH_MM[k + 1] - PATH_MM[k]) / STEP_S * 1e-3)
            assert fmu.do_step(STEP_S) == "ok"
            forces.append(fmu.get("F"))
        return np.array(forces), fmu.messages_with("error")
    finally:
        fmu.free()


def run_kernels(model, params, state):
    """The model's force at the start and after every step from ``state`` at 0, as the FMU is fed."""
    forces = kernel_forces(model, params, PATH_MM, STEP_S, state)
    return np.concatenate([[model.force(model.constants(params), state, 0.0, 0.0)], forces])


def test_only_a_model_that_can_hold_a_force_has_the_parameter():
    holding = {name for name in MODELS if "held_force" in get_model(name).fmu_units}
    assert holding == {"asymmetric_bouc_wen", "single_bouc_wen"}
    assert get_model("asymmetric_bouc_wen").fmu_units["held_force"] == "N"


@pytest.mark.parametrize("name", sorted(HELD_N))
@pytest.mark.parametrize("kind", ["pythonfmu", "native"])
def test_an_axis_starts_holding_its_force_and_moves_on_from_there(name, kind, pythonfmu_model_fmus,
                                                                   native_model_fmus):
    fmu = (pythonfmu_model_fmus if kind == "pythonfmu" else native_model_fmus)[name]
    model, params = get_model(name), defaults(name)
    held = HELD_N[name]
    forces, errors = run_fmu(fmu, {"held_force": held, "preload": PRELOAD_N})
    assert not errors
    # at rest at 0 the relaxed force is 0: the axis gives the held force and the preload
    assert forces[0] == pytest.approx(held + PRELOAD_N, rel=1e-12)
    reference = run_kernels(model, params, holding_state(name, params, held)) + PRELOAD_N
    assert np.max(np.abs(forces - reference)) <= 1e-9 * np.max(np.abs(reference))
    # the path slides the element: the start is forgotten and the loop is the relaxed start's
    relaxed, _ = run_fmu(fmu, {"preload": PRELOAD_N})
    assert abs(forces[1] - relaxed[1]) > 0.5 * abs(held)
    assert np.max(np.abs(forces[-50:] - relaxed[-50:])) < 0.05 * np.max(np.abs(relaxed))


@pytest.mark.parametrize("name", sorted(HELD_N))
def test_both_fmus_and_simulate_start_alike(name, pythonfmu_model_fmus, native_model_fmus):
    params = defaults(name)
    held = HELD_N[name]
    python, _ = run_fmu(pythonfmu_model_fmus[name], {"held_force": held})
    native, _ = run_fmu(native_model_fmus[name], {"held_force": held})
    assert np.max(np.abs(python - native)) <= 1e-12 * np.max(np.abs(python))
    # a set carrying held_force starts simulate where rest_force_N (the record's force at rest) would
    both = simulate(dict(params, held_force=held), t, PATH_MM, model=name)
    assert np.array_equal(both, simulate(params, t, PATH_MM, model=name, rest_force_N=held))
    # the first sample's force is the held force but for the dashpot's c0*v there (v of order 0.1 mm/s)
    assert both[0] == pytest.approx(held, rel=1e-5)


def test_zero_is_the_relaxed_start_bit_for_bit(native_model_fmus, pythonfmu_model_fmus):
    # held_force = 0 runs the kernels from initial_state (the relaxed start as it ever was): the
    # pythonfmu FMU runs them, the C is translated from them and compiled without contraction
    model, params = get_model("asymmetric_bouc_wen"), defaults("asymmetric_bouc_wen")
    relaxed = run_kernels(model, params, model.initial_state(model.constants(params), 0.0))
    for fmus in (pythonfmu_model_fmus, native_model_fmus):
        zero, _ = run_fmu(fmus["asymmetric_bouc_wen"], {"held_force": 0.0})
        assert np.array_equal(zero, relaxed)


@pytest.mark.parametrize("kind", ["pythonfmu", "native"])
def test_away_from_zero_the_held_force_adds_to_the_relaxed_force_and_the_preload(kind, pythonfmu_model_fmus,
                                                                                 native_model_fmus):
    # the asymmetric element relaxed at x0 gives k0*x0 (its slider centred, D(0) = 0); the FMU
    # starts at k0*x0 + held + preload, and so do simulate and predict of the same set
    from identification import predict
    fmu = (pythonfmu_model_fmus if kind == "pythonfmu" else native_model_fmus)["asymmetric_bouc_wen"]
    params, x0_mm, held = defaults("asymmetric_bouc_wen"), 0.4, -600.0
    start = BushingFmu(fmu, start_values={"held_force": held, "preload": PRELOAD_N},
                       initial_inputs={"x": x0_mm * 1e-3, "v": 0.0})
    try:
        expected = params["k0"] * x0_mm + held + PRELOAD_N
        assert start.get("F") == pytest.approx(expected, rel=1e-12)
    finally:
        start.free()
    path = x0_mm + PATH_MM
    values = dict(params, held_force=held, preload=PRELOAD_N)
    forces = simulate(values, t, path, model="asymmetric_bouc_wen")
    assert forces[0] == pytest.approx(expected, rel=1e-5)     # the dashpot's c0*v aside
    assert np.array_equal(predict(values, t, path, model="asymmetric_bouc_wen").force_N, forces)


def test_the_variable_is_fixed_read_at_the_start(pythonfmu_model_fmus, native_model_fmus):
    from fmpy import read_model_description
    for fmus in (pythonfmu_model_fmus, native_model_fmus):
        variables = {v.name: v for v in read_model_description(str(fmus["single_bouc_wen"])).modelVariables}
        assert variables["held_force"].variability == "fixed" and variables["held_force"].unit == "N"
        assert variables["preload"].variability == "tunable"


def test_a_coupled_group_refuses_a_held_force():
    six = read_six_axis(DATA / "params_six_axis_illustrative.json")
    single = dict(defaults("single_bouc_wen"), held_force=120.0)
    axes = {name: (one.model.name, one.parameters) for name, one in six.axes.items()}
    axes.update({axis: ("single_bouc_wen", single) for axis in ("x", "y")})
    with pytest.raises(ParameterError, match=r"x.held_force = 120.0 \[N\] must be 0 in a coupled group"):
        six_axis_document(axes, coupling="radial")
    # a group of a model without a coupled form (the asymmetric element) runs its axes alone: accepted
    asymmetric = dict(defaults("asymmetric_bouc_wen"), held_force=120.0)
    axes.update({axis: ("asymmetric_bouc_wen", asymmetric) for axis in ("x", "y")})
    assert six_axis_document(axes, coupling="radial")


@pytest.mark.slow
def test_a_coupled_groups_fmu_refuses_a_held_force_set_at_its_start(tmp_path):
    import build_fmu
    from fmu_src.parameter_files import save_six_axis
    six = read_six_axis(DATA / "params_six_axis_illustrative.json")
    axes = {name: (one.model.name, one.parameters) for name, one in six.axes.items()}
    axes.update({axis: ("single_bouc_wen", defaults("single_bouc_wen")) for axis in ("x", "y")})
    path = tmp_path / "six.json"
    save_six_axis(path, axes, coupling="radial")
    ports = {name: 0.0 for a in SIX_AXES for name in (a.displacement, a.velocity)}
    for fmu_path in (build_fmu.build_native_fmu(path, tmp_path / "native", model="six_axis").path,
                     build_fmu.build_fmu(path, tmp_path / "pythonfmu", model="six_axis")):
        fmu = BushingFmu(fmu_path, start_values={SIX_AXES[1].prefix + "held_force": 90.0}, initial_inputs=ports,
                         exit_initialization=False)
        try:
            try:       # the native FMU refuses the exit of initialization; the pythonfmu one its first step
                fmu.fmu.exitInitializationMode()
                assert fmu.do_step(STEP_S) != "ok"
            except FMICallException:
                pass
            assert any("y.held_force = 90.0 [N] must be 0 in a coupled group" in m for m in fmu.messages_with("error"))
        finally:
            fmu.free()


def test_a_model_with_options_starts_holding_its_force_in_both_fmus(tmp_path):
    # the derived model's resting_state (the options' forces at rest taken off what the base holds)
    # translated to C as the base's is: the axis gives its relaxed force at 0 plus the held force
    import build_fmu
    from example_parameter_files import derived_parameter_file
    path, name = derived_parameter_file(tmp_path), "single_bouc_wen+backbone4+limits+maxwell"
    outputs = []
    for fmu_path in (build_fmu.build_native_fmu(path, tmp_path / "native", model=name).path,
                     build_fmu.build_fmu(path, tmp_path / "pythonfmu", model=name)):
        relaxed, errors = run_fmu(fmu_path, {})
        held, more = run_fmu(fmu_path, {"held_force": 150.0})
        assert not errors and not more and relaxed[0] != 0.0
        assert held[0] == pytest.approx(relaxed[0] + 150.0, rel=1e-12)
        outputs.append(held)
    assert np.max(np.abs(outputs[0] - outputs[1])) <= 1e-12 * np.max(np.abs(outputs[1]))


@pytest.mark.parametrize("version", [2, 3])
def test_model_exchange_starts_holding_its_force_in_fmi_2_and_3(version, native_model_fmus, native_model_fmi3_fmus):
    # the host integrates the states itself: the FMU's start (its states at the exit of
    # initialization) holds the force; at rest at 0 the output stays at it, stuck
    from model_exchange import simulate_model_exchange
    fmu = (native_model_fmus if version == 2 else native_model_fmi3_fmus)["asymmetric_bouc_wen"]
    run = simulate_model_exchange(fmu, np.linspace(0.0, 0.05, 6), lambda s: 0.0, lambda s: 0.0,
                                  start_values={"held_force": 700.0})
    assert np.allclose(run.force_N, 700.0, rtol=1e-12, atol=0.0)
    # a push from there: the host's CVode on the FMU's derivatives against the co-simulation
    # FMU's own walk from the same start (two integrations of one model)
    push = simulate_model_exchange(fmu, np.array([0.0, 0.05]), lambda s: 0.02 * s, lambda s: 0.02,
                                   start_values={"held_force": 700.0})
    cosimulation = BushingFmu(native_model_fmus["asymmetric_bouc_wen"], start_values={"held_force": 700.0},
                              initial_inputs={"x": 0.0, "v": 0.02})
    try:
        for k in range(50):
            assert cosimulation.step(0.02 * k * 1e-3, 0.02, 1e-3) == "ok"
        walked = cosimulation.get("F")
    finally:
        cosimulation.free()
    assert abs(walked - 700.0) > 100.0       # 1 mm: the element takes up load beyond its start
    assert push.force_N[-1] == pytest.approx(walked, rel=1e-5)
