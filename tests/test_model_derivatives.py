"""The models' derivative and switching kernels (what a host's integrator calls in model
exchange) against each model's equations typed independently in the tests."""
import numpy as np
import pytest

from conftest import paper_equations, paper_parameters
from fmu_src.bushing_models import MODELS
from test_baseline_models import BOUC_WEN, SPENCER, bouc_wen_rhs, spencer_rhs

CASES = {
    # model: (parameters, independent right-hand side(p, state, x, v), state scale)
    "proposed": (paper_parameters("table5"),
                 lambda p, s, x, v: paper_equations(0.0, s, p, lambda t: x, lambda t: v), (1.0, 500.0, 1.0, 50.0)),
    "spencer": (SPENCER, spencer_rhs, (1.0, 500.0)),
    "single_bouc_wen": (BOUC_WEN, bouc_wen_rhs, (500.0,)),
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


def test_kelvin_voigt_has_no_state_to_integrate():
    bushing = MODELS["kelvin_voigt"]
    constants = bushing.constants({"k": 900.0, "c": 2.5, "preload": 0.0})
    assert bushing.derivatives(constants, (), 1.0, 2.0) == () and bushing.switches(constants, (), 1.0, 2.0) == ()
