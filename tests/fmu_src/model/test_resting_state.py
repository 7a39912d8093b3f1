"""The state at rest (issue 63): a model whose elements hold a force at rest starts a run holding
the force a record shows before it moves (``BushingModel.resting_state``, ``integration.start_state``),
not virgin at zero.

References: the force kernel at the state (the held force, exact where the model can hold it);
scipy's brentq for the dead zone's inverse; the element's own law for how much it can hold; the
plain-Python model stepped from that state for the compiled population (bit for bit)."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from fmu_src.fmi.fmu_inputs import default_parameter_file
from fmu_src.model.elements import dead_zone, inverse_dead_zone
from fmu_src.model.registry import MODELS, get_model
from fmu_src.parameter_files import load_parameters
from identification.forward.population import CommunicationPoints, simulate_population_at

HOLDING = ("asymmetric_bouc_wen", "single_bouc_wen", "asymmetric_bouc_wen+backbone5+limits+maxwell+rig",
           "single_bouc_wen+maxwell+rig")


NEUTRAL = {"limit_gap_pos": 1.0, "limit_gap_neg": 1.0, "limit_k_pos": 50.0, "limit_k_neg": 80.0,
           "limit_exponent_pos": 2.0, "limit_exponent_neg": 2.0, "limit_c_pos": 0.0, "limit_c_neg": 0.0,
           "limit_depth_pos": 1.0, "limit_depth_neg": 1.0, "limit_width": 0.1, "maxwell_k": 30.0, "maxwell_c": 0.5,
           "rig_displacement_zero": 0.2, "rig_force_zero": 35.0,
           **{f"backbone_x{i + 1}": x for i, x in enumerate((-2.0, -1.0, 0.0, 1.0, 2.0))},
           **{f"backbone_F{i + 1}": f for i, f in enumerate((-300.0, -100.0, 0.0, 120.0, 400.0))}}
"""The options' values of the derived models here: every option acting (a Maxwell force held at
rest is none), so that what the base holds is the rest less the options' forces."""


def typed(name):
    """(the model, its parameters: the base's default file and the options' values above)."""
    model = get_model(name)
    base = model.base or model
    params = dict(load_parameters(default_parameter_file(base.name), base.name))
    params.update({key: value for key, value in NEUTRAL.items() if key in model.parameter_names})
    return model, {key: params[key] for key in model.parameter_names}


def constants_of(name):
    model, params = typed(name)
    return model, model.constants(params)


@pytest.mark.parametrize("gap, width", [(0.3, 0.0), (0.3, 0.05), (0.0, 0.02), (2.0, 0.001)])
def test_the_dead_zones_inverse_is_its_root(gap, width):
    for d in (-3.0, -0.7, -1e-4, 1e-6, 0.4, 2.5):
        e = inverse_dead_zone(d, gap, width)
        if width > 0.0:
            reference = brentq(lambda y: dead_zone(y, gap, width) - d, -10.0, 10.0, xtol=1e-15, rtol=1e-15)
            assert e == pytest.approx(reference, abs=1e-12)
        assert dead_zone(e, gap, width) == pytest.approx(d, rel=1e-12, abs=1e-15)
    assert inverse_dead_zone(0.0, gap, width) == 0.0


@pytest.mark.parametrize("name", HOLDING)
def test_a_run_starts_holding_the_force_it_is_given(name):
    model, m = constants_of(name)
    for x0 in (0.0, 0.1):
        for held in (-150.0, -20.0, 0.0, 60.0, 150.0):     # within what each default set holds
            state = model.start_state(m, x0, held)
            assert model.force(m, state, x0, 0.0) == pytest.approx(held, rel=1e-9, abs=1e-9), (x0, held)


@pytest.mark.parametrize("name", HOLDING)
def test_nan_starts_relaxed_bit_for_bit(name):
    model, m = constants_of(name)
    assert model.start_state(m, 0.4, math.nan) == model.initial_state(m, 0.4)


def test_the_asymmetric_element_holds_at_most_its_yield_each_way():
    model, m = constants_of("asymmetric_bouc_wen")
    p = dict(load_parameters(default_parameter_file("asymmetric_bouc_wen"), "asymmetric_bouc_wen"))
    top, bottom = p["zp"] * (1.0 + p["eps"]), -p["zn"] * (1.0 + p["eps"])
    for held, expected in ((1e6, top), (-1e6, bottom)):
        state = model.start_state(m, 0.0, held)
        assert model.force(m, state, 0.0, 0.0) == pytest.approx(expected, rel=1e-12)
        assert state[1] == 1.0                      # stuck: the breakaway memory full


def test_the_single_element_holds_at_most_its_ultimate_force():
    model, m = constants_of("single_bouc_wen")
    c0, k0, alpha, A, beta, gamma, n = m
    ultimate = (A / (beta + gamma)) ** (1.0 / n)
    state = model.start_state(m, 0.0, 1e9)
    assert state[0] == pytest.approx(ultimate, rel=1e-12)


@pytest.mark.parametrize("name", [n for n, model in MODELS.items() if model.resting_state is None])
def test_a_model_that_holds_no_force_starts_relaxed_whatever_it_is_given(name):
    model = MODELS[name]
    m = model.constants(load_parameters(default_parameter_file(name), name))
    assert model.start_state(m, 0.2, 123.0) == model.initial_state(m, 0.2)


@pytest.mark.parametrize("name", HOLDING)
def test_the_compiled_population_from_rest_is_the_plain_model_bit_for_bit(name):
    model, params = typed(name)
    m = model.constants(params)
    t = np.arange(200) * 1e-3
    x = 0.5 * np.sin(2.0 * np.pi * 5.0 * t) + 0.1
    v = np.append(np.diff(x) / np.diff(t), 0.0)
    values = np.array([model.values(params)])
    compiled = simulate_population_at(values, CommunicationPoints(t, x, v, np.arange(t.size), v, -180.0),
                                      model=model)[0]
    state, state_x = model.start_state(m, x[0], -180.0), x[0]
    plain = [model.force(m, state, x[0], v[0])]
    for k in range(t.size - 1):
        h = t[k + 1] - t[k]
        state, _, status = model.step(m, state, state_x, x[k], v[k], h, 20000)
        assert status == 0
        state_x = x[k] + v[k] * h
        plain.append(model.force(m, state, state_x, v[k + 1]))
    assert np.array_equal(compiled, np.array(plain))
    assert model.force(m, model.start_state(m, x[0], -180.0), x[0], 0.0) == pytest.approx(-180.0)
