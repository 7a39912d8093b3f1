"""The models' derivative and switching kernels (what a host's integrator calls in model
exchange) against each model's equations typed independently in the tests."""
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from conftest import paper_equations, paper_parameters
from fmu_src.model.registry import MODELS
from test_baseline_models import BOUC_WEN, SPENCER, bouc_wen_rhs, spencer_rhs

REFERENCES = Path(__file__).resolve().parents[2] / "references"

def berg_rhs(p, s, x, v):
    """Berg's model: d/dt of the travel is v, the reversal force and direction hold between
    events, each Maxwell element df/dt = k*v - (k/c)*f."""
    return [v, 0.0, 0.0, p["k1"] * v - p["k1"] / p["c1"] * s[3], p["k2"] * v - p["k2"] / p["c2"] * s[4]]


def fractional_rhs(p, s, x, v):
    """The fractional model's realisation as its docstring states it: Maxwell elements of rates
    10^(-4 + j/2) 1/s, j = 0..18, stiffness b*sin(alpha*pi)/pi*r^alpha*ln(10)/2, and below them one
    of stiffness b*sin(alpha*pi)/pi*r_a^alpha/alpha, rate r_a*(1 - alpha)/alpha, r_a = 10^-4.25."""
    alpha, scale = p["alpha"], p["b"] * np.sin(p["alpha"] * np.pi) / np.pi
    rates = [10.0 ** (-4.0 + j / 2.0) for j in range(19)]
    stiffness = [scale * r ** alpha * np.log(10.0) / 2.0 for r in rates]
    lowest = 10.0 ** -4.25
    rates.append(lowest * (1.0 - alpha) / alpha)
    stiffness.append(scale * lowest ** alpha / alpha)
    return [v, 0.0, 0.0] + [k * v - r * f for k, r, f in zip(stiffness, rates, s[3:])]


def hydraulic_rhs(p, s, x, v):
    """The hydraulic mount, typed from its equations: P = kb*(x - y) - kc*y, the decoupler's
    u = gap*tanh(P/((kb + kc + kd)*gap)), dp = P - (kb + kc)*u; dy/dt = w,
    mf*dw/dt = dp - cf*w - ct*|w|*w, df1/dt = k1*v - (k1/c1)*f1."""
    y, w, f1 = s
    pressure = p["kb"] * (x - y) - p["kc"] * y
    u = p["gap"] * np.tanh(pressure / ((p["kb"] + p["kc"] + p["kd"]) * p["gap"])) if p["gap"] > 0.0 else 0.0
    drive = pressure - (p["kb"] + p["kc"]) * u
    return [w, (drive - p["cf"] * w - p["ct"] * abs(w) * w) / p["mf"], p["k1"] * v - p["k1"] / p["c1"] * f1]


FILLED_RUBBER = {"k0": 500.0, "k3": 10.0, "Ff_max": 60.0, "x2": 0.08}
HYDRAULIC = {"k0": 200.0, "c0": 0.05, "k1": 40.0, "c1": 0.4, "kb": 250.0, "kc": 25.0, "mf": 0.07, "cf": 1.3,
             "ct": 0.005, "gap": 0.1, "kd": 50.0}
"""data/params_hydraulic_mount.json's values: (kb + kc + kd)*gap = 32.5 N, so the states drawn below put
the chambers' pressure difference P both inside the decoupler's free travel and on its cage."""
FREE_PLATE = {"k0": 200.0, "k3": 20.0, "c0": 0.05, "k1": 40.0, "c1": 0.4, "kb": 250.0, "kc": 25.0, "mf": 0.07,
              "cf": 1.3, "ct": 0.005, "gap": 0.12, "width": 0.005, "kcage": 2000.0, "kd": 5.0}
"""data/params_hydraulic_free_decoupler.json's values."""
_spec = importlib.util.spec_from_file_location("free_decoupler_mount", REFERENCES / "free_decoupler_mount.py")
free_decoupler_mount = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(free_decoupler_mount)   # numpy and scipy only

_spec = importlib.util.spec_from_file_location("generate_references", REFERENCES / "generate_references.py")
references = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(references)   # numpy and scipy only
ASYMMETRIC = {"c0": 1.5, "k0": 400.0, "A": 3000.0, "zp": 1500.0, "zn": 1000.0, "n": 2.0, "gap": 0.3, "width": 0.05,
              "eps": 0.3, "delta": 0.2}
"""data/params_asymmetric_bouc_wen_illustrative.json's values: the states drawn below (e ~ N(0, 0.6 mm))
put the element inside its play, across its corners and loaded either way, z near and over its yield."""

CASES = {
    # model: (parameters, independent right-hand side(p, state, x, v), state scale)
    "proposed": (paper_parameters("table5"),
                 lambda p, s, x, v: paper_equations(0.0, s, p, lambda t: x, lambda t: v), (1.0, 500.0, 1.0, 50.0)),
    "spencer": (SPENCER, spencer_rhs, (1.0, 500.0)),
    "single_bouc_wen": (BOUC_WEN, bouc_wen_rhs, (500.0,)),
    "asymmetric_bouc_wen": (ASYMMETRIC, lambda p, s, x, v: references.asymmetric_rhs(0.0, s, p, lambda t: (x, v)),
                            (0.6, 0.5)),
    "berg": (dict(FILLED_RUBBER, k1=150.0, c1=15.0, k2=250.0, c2=0.5), berg_rhs, (1.0, 50.0, 1.0, 100.0, 100.0)),
    "fractional": (dict(FILLED_RUBBER, b=70.0, alpha=0.22), fractional_rhs, (1.0, 50.0, 1.0) + (100.0,) * 20),
    "hydraulic": (HYDRAULIC, hydraulic_rhs, (1.0, 100.0, 50.0)),
    # the free plate: tests/references/free_decoupler_mount.py's equations (its rounded cage typed
    # with numpy's logaddexp); the states put P inside the free travel (33.6 N), on the cage and
    # across its 0.005 mm engagement
    "hydraulic_free_decoupler": (FREE_PLATE, lambda p, s, x, v: free_decoupler_mount.rhs(
        0.0, s, p, lambda t: (x, v)), (0.3, 100.0, 50.0)),
}


@pytest.mark.parametrize("model", list(CASES))
def test_derivatives_are_the_models_equations(model):
    params, reference, scale = CASES[model]
    bushing = MODELS[model]
    constants = bushing.constants(bushing.check(params))
    rng = np.random.default_rng(3)
    for _ in range(200):
        state = tuple(float(value) for value in rng.normal(0.0, 1.0, len(scale)) * scale)
        x, v = float(rng.normal(0.0, 1.5)), float(rng.normal(0.0, 100.0))
        got = bushing.derivatives(constants, state, x, v)
        expected = reference(params, state, x, v)
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * np.max(np.abs(expected)))


def test_switches_are_the_blocks_relative_velocities_and_hysteretic_forces():
    p = paper_parameters("table5")
    bushing = MODELS["proposed"]
    constants = bushing.constants(p)
    state, x, v = (0.3, -120.0, 0.5, 15.0), 0.8, -40.0
    dy, _, dw, _ = paper_equations(0.0, state, p, lambda t: x, lambda t: v)
    np.testing.assert_allclose(bushing.switches(constants, state, x, v), (v - dy, state[1], v - dw, state[3]),
                               rtol=1e-14)
    assert MODELS["single_bouc_wen"].switches(MODELS["single_bouc_wen"].constants(BOUC_WEN), (7.0,), 0.1, -3.0) == (-3.0, 7.0)


def test_the_friction_models_switch_where_the_velocity_changes_sign_and_reverse_there():
    for name, params in (("berg", CASES["berg"][0]), ("fractional", CASES["fractional"][0])):
        bushing = MODELS[name]
        constants = bushing.constants(params)
        state = (0.4,) + (0.0,) * (len(bushing.states) - 1)
        state = (0.4, 0.0, 1.0) + state[3:]                        # moved up 0.4 mm from rest
        assert bushing.switches(constants, state, 0.4, -3.0) == (-3.0,)
        assert bushing.update(constants, state, 0.4, 2.0) == state     # still moving up: no change
        turned = bushing.update(constants, state, 0.4, -2.0)
        friction = params["Ff_max"] * 0.4 / (params["x2"] + 0.4)    # from rest, typed: Ff_max*x/(x2 + x)
        assert turned[:3] == (0.0, pytest.approx(friction, rel=1e-14), -1.0) and turned[3:] == state[3:]


def test_the_asymmetric_element_switches_where_the_velocity_the_force_and_the_plays_corners_change_sign():
    bushing = MODELS["asymmetric_bouc_wen"]
    constants = bushing.constants(ASYMMETRIC)
    e, q = 0.5, 0.4
    z = 3000.0 * float(references.asymmetric_play(ASYMMETRIC, e))
    assert bushing.switches(constants, (e, q), 0.7, -12.0) == pytest.approx((-12.0, z, 0.5 - 0.3, 0.5 + 0.3), rel=1e-14)
    assert bushing.update is None          # the state is continuous: an event changes only the branch


def test_the_hydraulic_model_has_no_switches():
    # the decoupler's tanh and the turbulent |w|*w are smooth enough (C1): nothing for a host to locate
    bushing = MODELS["hydraulic"]
    constants = bushing.constants(HYDRAULIC)
    assert bushing.switch_specs == () and bushing.update is None
    for state, x, v in (((0.0, 0.0, 0.0), 0.0, 0.0), ((0.3, -120.0, 15.0), 0.8, -40.0), ((-2.0, 50.0, -5.0), 1.5, 9.0)):
        assert bushing.switches(constants, state, x, v) == ()


def test_kelvin_voigt_has_no_state_to_integrate():
    bushing = MODELS["kelvin_voigt"]
    constants = bushing.constants({"k": 900.0, "c": 2.5, "preload": 0.0})
    assert bushing.derivatives(constants, (), 1.0, 2.0) == () and bushing.switches(constants, (), 1.0, 2.0) == ()
