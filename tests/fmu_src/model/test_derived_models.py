"""Options any model takes (fmu_src.model.derived): a measured backbone, travel limits, the rig's
offsets. Each against what it is by its definition, typed here or taken from scipy: the backbone
scipy's PchipInterpolator, the limits a contact force written out with numpy, the rig's offsets a
shift of the base model's input and output; neutral options leave every model bit for bit; the
paths (plain Python, numba, C, the tangents, both FMUs) agree on a derived model as on any."""
from __future__ import annotations

import shutil

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from conftest import DATA
from fmu_src.model.derived import split_name
from fmu_src.model.options import Options
from fmu_src.model.parameter_specs import ParameterError
from fmu_src.model.registry import MODELS, get_model
from fmu_src.parameter_files import read_parameter_set, save_parameters
from identification.measured.signals import Random, sample_times
from element_checks import assert_sensitivities_are_central_differences
from example_parameter_files import BACKBONE, LIMITS, defaults
from example_parameter_files import derived_parameter_file as derived_parameter_file_in
from python_core import simulate_python_core

T = sample_times(0.3, 1000.0)
X, V = Random(2.0, 0.3, seed=5).signals(T)
X = X + 0.01 * np.sin(2 * np.pi * 50 * T)        # a displacement jump at every step, as the FMU may see

NO_LIMITS = dict(LIMITS, limit_k_pos=0.0, limit_k_neg=0.0, limit_c_pos=0.0, limit_c_neg=0.0)


def test_a_derived_model_is_named_by_its_base_and_options_either_way():
    model = get_model("proposed+rig+limits")
    assert model.name == "proposed+limits+rig" and model.identifier == "BoucWenBushing_Limits_Rig"
    assert get_model("BoucWenBushing_Limits_Rig") is model
    assert get_model("hydraulic_free_decoupler+backbone7").identifier == "HydraulicFreeDecoupler_Backbone7"
    assert split_name("HydraulicFreeDecoupler_Backbone7") == ("HydraulicFreeDecoupler", Options.parse(["backbone7"]))
    assert model.base is MODELS["proposed"] and model.options == Options.parse(["rig", "limits"])
    with pytest.raises(ParameterError, match="unknown model option 'stops'.*limits"):
        get_model("proposed+stops")
    with pytest.raises(ParameterError, match="backbone1: the count must be 2 to 32"):
        get_model("proposed+backbone1")


@pytest.mark.parametrize("base", list(MODELS))
def test_neutral_options_leave_every_model_bit_for_bit(base):
    # limits without stiffness or damping, a Maxwell element without a spring, the rig's zeros at 0:
    # the same floats as the base
    params = defaults(base)
    derived = get_model(f"{base}+limits+maxwell+rig")
    neutral = dict(params, **NO_LIMITS, maxwell_k=0.0, maxwell_c=1.0, rig_displacement_zero=0.0, rig_force_zero=0.0)
    np.testing.assert_array_equal(simulate_python_core(neutral, T, X, V, model=derived.name),
                                  simulate_python_core(params, T, X, V, model=base))


@pytest.mark.parametrize("base", ["single_bouc_wen", "berg", "kelvin_voigt"])
def test_a_straight_backbone_is_the_static_spring_it_replaces(base):
    # a linear static spring k0*x (Kelvin-Voigt's k) as a two-knot backbone through 0
    params = defaults(base)
    model = get_model(base)
    spring = model.static_spring[0]
    derived = get_model(f"{base}+backbone2")
    replaced = {name: value for name, value in params.items() if name not in model.static_spring}
    if "k3" in params:      # the cubic stays out of the comparison: a straight backbone has none
        params = dict(params, k3=0.0)
    replaced.update(backbone_x1=-1.0, backbone_x2=1.0, backbone_F1=-params[spring], backbone_F2=params[spring])
    got = simulate_python_core(replaced, T, X, V, model=derived.name)
    want = simulate_python_core(params, T, X, V, model=base)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.max(np.abs(want)))


def kelvin_voigt_with(options: str, **values) -> tuple:
    """A Kelvin-Voigt bushing with no spring or dashpot of its own and ``options``: the options'
    force alone (``force`` of the model at rest, for displacement u and velocity v)."""
    model = get_model(f"kelvin_voigt+{options}")
    own = {name: 0.0 for name in ("k", "c", "preload") if name in model.parameter_names}
    params = model.check(dict(own, **values))
    constants = model.constants(params)
    return model, constants


def test_the_backbone_is_scipys_monotone_cubic_and_straight_beyond_its_end_knots():
    x = np.array([-4.0, -2.5, -1.0, 0.0, 1.5, 2.0, 5.0])
    force = np.array([-3000.0, -400.0, -150.0, 0.0, 200.0, 900.0, 5200.0])     # a void closing, a bump stop
    values = {f"backbone_x{i + 1}": float(a) for i, a in enumerate(x)}
    values.update({f"backbone_F{i + 1}": float(f) for i, f in enumerate(force)})
    model, constants = kelvin_voigt_with("backbone7", **values)
    state = model.initial_state(constants, 0.0)
    reference = PchipInterpolator(x, force)
    slope = reference.derivative()
    u = np.linspace(-7.0, 8.0, 601)
    got = np.array([model.force(constants, state, a, 0.0) for a in u])
    want = np.where(u < x[0], force[0] + slope(x[0]) * (u - x[0]),
                    np.where(u > x[-1], force[-1] + slope(x[-1]) * (u - x[-1]), reference(np.clip(u, x[0], x[-1]))))
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-9)
    assert np.all(np.diff(got) >= 0.0)      # monotone data, monotone curve


def softplus(z):
    return np.logaddexp(0.0, z)


def typed_limit(u, v, gap, k, exponent, c, depth, width):
    """One side's contact force, written out: penetration d = width*softplus((u - gap)/width), then
    k*d^e plus the damping c*v ramped in by 3s^2 - 2s^3, s = d/depth clipped to [0, 1]."""
    d = width * softplus((u - gap) / width)
    s = np.clip(d / depth, 0.0, 1.0)
    return k * d ** exponent + c * s * s * (3.0 - 2.0 * s) * v


def test_the_travel_limits_are_the_contact_force_on_each_side():
    model, constants = kelvin_voigt_with("limits", **LIMITS)
    state = model.initial_state(constants, 0.0)
    p = LIMITS
    for u in np.linspace(-3.0, 3.0, 121):
        for v in (-40.0, 0.0, 25.0):
            want = (typed_limit(u, v, p["limit_gap_pos"], p["limit_k_pos"], p["limit_exponent_pos"], p["limit_c_pos"],
                                p["limit_depth_pos"], p["limit_width"])
                    - typed_limit(-u, -v, p["limit_gap_neg"], p["limit_k_neg"], p["limit_exponent_neg"],
                                  p["limit_c_neg"], p["limit_depth_neg"], p["limit_width"]))
            assert model.force(constants, state, u, v) == pytest.approx(want, rel=1e-12, abs=1e-9)
    # inside both gaps, more than 37 widths from either corner: nothing (the softplus is 0 there)
    narrow, narrow_constants = kelvin_voigt_with("limits", **dict(LIMITS, limit_width=0.01))
    assert narrow.force(narrow_constants, state, 0.2, 30.0) == 0.0
    # the corners are the switches a model-exchange host locates
    assert model.switches(constants, state, 0.7, 1.0) == pytest.approx((0.7 - 1.0, 0.7 + 0.5))


def test_the_maxwell_element_relaxes_exactly_as_its_equation_says():
    # a ramp x = v*t from rest: df/dt = k*v - (k/c)*f gives f = c*v*(1 - exp(-k*t/c)), exactly
    model, constants = kelvin_voigt_with("maxwell", maxwell_k=300.0, maxwell_c=3.0)
    assert [s.name for s in model.states] == ["maxwell_f"]
    t = np.arange(0.0, 0.05, 1e-3)
    v = 12.0
    forces = simulate_python_core(model.check(dict(k=0.0, c=0.0, preload=0.0, maxwell_k=300.0, maxwell_c=3.0)),
                                  t, v * t, np.full(t.size, v), model=model.name)
    np.testing.assert_allclose(forces, 3.0 * v * (1.0 - np.exp(-100.0 * t)), rtol=1e-12, atol=1e-10)
    # its rate for model exchange, and a jump loads its spring at once
    assert model.derivatives(constants, (5.0,), 0.0, 2.0) == pytest.approx((300.0 * 2.0 - 100.0 * 5.0,))
    assert model.jump(constants, (5.0,), 0.01) == ((5.0 + 3.0,), 0)


def test_hard_limits_engage_at_their_gaps():
    model, constants = kelvin_voigt_with("limits", **dict(LIMITS, limit_width=0.0, limit_c_pos=0.0, limit_c_neg=0.0))
    state = model.initial_state(constants, 0.0)
    assert model.force(constants, state, 0.99, 0.0) == 0.0 and model.force(constants, state, -0.49, 0.0) == 0.0
    assert model.force(constants, state, 1.5, 0.0) == pytest.approx(300.0 * 0.5 ** 2)
    assert model.force(constants, state, -1.5, 0.0) == pytest.approx(-500.0 * 1.0 ** 1.5)


@pytest.mark.parametrize("base", ["single_bouc_wen", "asymmetric_bouc_wen", "hydraulic"])
def test_the_rig_offsets_shift_the_base_models_input_and_output(base):
    params = defaults(base)
    derived = get_model(f"{base}+rig")
    shifted = dict(params, rig_displacement_zero=0.4, rig_force_zero=-35.0)
    got = simulate_python_core(shifted, T, X, V, model=derived.name)
    want = simulate_python_core(params, T, X - 0.4, V, model=base) - 35.0
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.max(np.abs(want)))


@pytest.mark.parametrize("bad, message", [
    (dict(backbone_x2=-3.5), r"backbone_x2 - backbone_x1 = -0.5 mm must be > 0 \(the backbone's knots must increase\)"),
    (dict(backbone_F3=-300.0), r"backbone_F3 - backbone_F2 = -100.0 N must be >= 0 \(a backbone is monotone"),
    (dict(limit_gap_pos=-1.0), r"limit_gap_pos = -1.0 \[mm\] must be >= 0"),
    (dict(limit_exponent_neg=0.5), r"limit_exponent_neg = 0.5 \[1\] must be >= 1"),
    (dict(limit_width=-0.1), r"limit_width = -0.1 \[mm\] must be >= 0"),
    (dict(limit_k_pos=-5.0), r"limit_k_pos = -5.0 \[N/mm\^e\] must be >= 0"),
])
def test_bad_backbones_and_limits_are_refused_with_value_unit_and_range(bad, message):
    model = get_model("kelvin_voigt+backbone4+limits")
    params = dict(c=1.0, preload=0.0, **BACKBONE, **LIMITS)
    model.check(params)
    with pytest.raises(ParameterError, match=message):
        model.check(dict(params, **bad))


@pytest.mark.parametrize("base", ["single_bouc_wen", "asymmetric_bouc_wen"])
def test_the_compiled_derived_model_equals_its_python_kernels_bitwise(base):
    from identification.forward.population import simulate_population_held
    derived = get_model(f"{base}+backbone4+limits+rig")
    params = {name: value for name, value in defaults(base).items() if name not in get_model(base).static_spring}
    params.update(BACKBONE, **LIMITS, rig_displacement_zero=0.1, rig_force_zero=20.0)
    compiled = simulate_population_held([derived.check(params)], T, X, V, model=derived)[0]
    np.testing.assert_array_equal(compiled, simulate_python_core(params, T, X, V, model=derived.name))


@pytest.mark.slow
@pytest.mark.parametrize("base", list(MODELS))
def test_every_derived_model_compiles_equal_to_its_python_kernels(base):
    test_the_compiled_derived_model_equals_its_python_kernels_bitwise(base)


@pytest.mark.parametrize("base", ["single_bouc_wen", "berg"])
def test_the_derived_kernels_tangents_are_their_complex_step_derivatives(base):
    from fmu_src.kernels.tangents import tangent
    from complex_step import Cs, STEP, flat, on_complex_numbers
    derived = get_model(f"{base}+backbone4+limits+rig")
    params = {name: value for name, value in defaults(base).items() if name not in get_model(base).static_spring}
    params.update(BACKBONE, **LIMITS, rig_displacement_zero=0.1, rig_force_zero=20.0)
    m = derived.constants(derived.check(params))
    force_tangent = tangent(derived.force)
    rng = np.random.default_rng(8)
    for _ in range(60):
        x, v = float(rng.uniform(-4.0, 4.0)), float(rng.uniform(-50.0, 50.0))
        state = tuple(float(s) for s in np.asarray(derived.initial_state(m, x)) + rng.normal(0.0, 0.3, len(derived.states)))
        d_state = tuple(float(d) for d in rng.normal(0.0, 1.0, len(state)))
        d_x, d_v = float(rng.normal()), float(rng.normal())
        value, derivative = force_tangent(m, state, x, v, d_state, d_x, d_v)
        assert value == derived.force(m, state, x, v)
        stepped = on_complex_numbers(derived.force)(m, tuple(Cs(complex(s, STEP * d)) for s, d in zip(state, d_state)),
                                                    Cs(complex(x, STEP * d_x)), Cs(complex(v, STEP * d_v)))
        want = complex(stepped).imag / STEP
        assert derivative == pytest.approx(want, rel=1e-9, abs=1e-9 * max(1.0, abs(want)))


@pytest.fixture(scope="module")
def derived_parameter_file(tmp_path_factory):
    return derived_parameter_file_in(tmp_path_factory.mktemp("derived"))


@pytest.mark.parametrize("kind", ["pythonfmu", "native2", "native3"])
def test_both_fmus_of_a_derived_model_equal_its_forward_model(kind, derived_parameter_file, tmp_path):
    import subprocess
    import sys
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu
    from conftest import REPO
    from identification.forward.population import simulate_population_held
    if kind != "pythonfmu" and shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    extra = {"pythonfmu": [], "native2": ["--native"], "native3": ["--native", "--fmi-version", "3"]}[kind]
    run = subprocess.run([sys.executable, str(REPO / "build_fmu.py"), "--params", str(derived_parameter_file),
                          "--out", str(tmp_path), *extra], capture_output=True, text=True, cwd=REPO, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    path = tmp_path / "SingleBoucWenBushing_Backbone4_Limits_Maxwell.fmu"
    assert validate_fmu(str(path)) == []
    t = np.arange(0.0, 0.6, 1e-3)
    w = 2 * np.pi * 3.0
    signals = np.zeros(t.size, dtype=[("time", float), ("x", float), ("v", float)])
    signals["time"], signals["x"], signals["v"] = t, 3.5e-3 * np.sin(w * t), 3.5e-3 * w * np.cos(w * t)
    result = simulate_fmu(str(path), stop_time=t[-1], step_size=1e-3, output_interval=1e-3, input=signals, output=["F"])
    parameters = read_parameter_set(derived_parameter_file)
    want = simulate_population_held([parameters.parameters], t, signals["x"] * 1e3, signals["v"] * 1e3,
                                    model=parameters.model)[0]
    np.testing.assert_allclose(result["F"], want[:len(result)], rtol=0, atol=1e-12 * np.max(np.abs(want)))
    # a knot set between steps that is not increasing, a negative gap: the step refused, the reason logged
    # (the harness is FMI 2's; the FMI 3 FMU's checks are the same generated tables)
    from fmu_harness import BushingFmu
    for name, value, fragments in () if kind == "native3" else (("backbone_x2", -3.5, ["backbone_x2 - backbone_x1 = -0.5", "must be > 0"]),
                                   ("limit_gap_pos", -1.0, ["limit_gap_pos = -1.0 [mm]", "must be >= 0"])):
        fmu = BushingFmu(path)
        assert fmu.step(1e-4, 0.0, 1e-3) == "ok"
        fmu.set(name, value)
        assert fmu.do_step(1e-3) == "discard"
        assert any(all(f in message for f in fragments) for message in fmu.messages_with("error")), \
            fmu.messages_with("error")
        fmu.free()


@pytest.mark.slow
@pytest.mark.parametrize("base", ["single_bouc_wen", "asymmetric_bouc_wen", "hydraulic_free_decoupler"])
def test_the_fits_exact_jacobian_of_a_derived_model_equals_central_differences(base):
    # every parameter a direction (33 for the free plate: more than one module carries, so in chunks)
    from identification.forward.population import CommunicationPoints
    derived = get_model(f"{base}+backbone4+limits+rig")
    params = {name: value for name, value in defaults(base).items() if name not in get_model(base).static_spring}
    params.update(BACKBONE, **LIMITS, rig_displacement_zero=0.1, rig_force_zero=20.0)
    t = sample_times(0.2, 1000.0)
    x, v = Random(2.0, 0.3, seed=5).signals(t)
    row = np.array([derived.values(derived.check(params))])
    assert_sensitivities_are_central_differences(derived, row, CommunicationPoints(t, x, v, np.arange(t.size), v),
                                                 lambda j, value: 1e-6 * max(1.0, abs(value)))


@pytest.mark.slow
def test_a_six_axis_fmus_axis_takes_a_derived_model_in_both_fmus(tmp_path):
    # a jounce bump stop on z: a Kelvin-Voigt axis with a limit on its positive side only
    import json
    import subprocess
    import sys
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu
    from conftest import REPO
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    document = json.loads((DATA / "params_six_axis_illustrative.json").read_text())
    document["axes"]["z"] = {"model": "KelvinVoigtBushing_Limits", "parameters": dict(
        k=300.0, c=1.0, preload=0.0, **dict(LIMITS, limit_gap_pos=2.0, limit_gap_neg=100.0, limit_k_neg=0.0))}
    params = tmp_path / "six.json"
    params.write_text(json.dumps(document))
    forces = []
    for kind, extra in (("python", []), ("native", ["--native"])):
        out = tmp_path / kind
        run = subprocess.run([sys.executable, str(REPO / "build_fmu.py"), "--model", "six_axis", "--params",
                              str(params), "--out", str(out), *extra], capture_output=True, text=True, cwd=REPO,
                             timeout=600)
        assert run.returncode == 0, run.stderr[-2000:]
        path = out / "SixAxisBushing.fmu"
        assert validate_fmu(str(path)) == []
        t = np.arange(0.0, 0.5, 1e-3)
        names = ["dx", "vx", "dy", "vy", "dz", "vz", "rx", "wx", "ry", "wy", "rz", "wz"]
        signals = np.zeros(t.size, dtype=[("time", float)] + [(name, float) for name in names])
        w = 2 * np.pi * 2.0
        signals["time"], signals["dz"], signals["vz"] = t, 4e-3 * np.sin(w * t), 4e-3 * w * np.cos(w * t)
        forces.append(simulate_fmu(str(path), stop_time=t[-1], step_size=1e-3, output_interval=1e-3,
                                   input=signals, output=["Fz"])["Fz"])
    # 4 mm into a stop at 2 mm: k*x + the stop's 300 N/mm^2 * 2^2 more at the peak, the same in both FMUs
    np.testing.assert_array_equal(forces[0], forces[1])
    assert np.max(forces[0]) > 300.0 * 4.0 + 300.0 * 2.0 ** 2 * 0.9
