"""The baseline models (Kelvin-Voigt, single Bouc-Wen, Spencer) against their own equations.

References are independent of the project's core: analytic forces for Kelvin-Voigt, and
scipy's Radau on each baseline's equations as its authors write them (Spencer's convention
with gamma on the |u| term), on the same continuous piecewise-linear input.
"""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from fmu_src.model.registry import MODELS, get_model
from fmu_src.model.parameter_specs import ParameterError
from fmu_src.parameter_files import load_parameters, read_parameter_set, save_parameters
from identification.forward.population import simulate_model_held
from identification.measured.signals import Sine, Step, sample_times
from identification.fitting.search_space import SearchSpace, _rescale_block

SPENCER = {"c0": 4.0, "k0": 150.0, "c1": 250.0, "k1": 900.0, "x0": 0.2, "alpha": 1.0, "A": 1800.0,
           "beta": -4.0, "gamma": 11.0, "n": 0.7}
BOUC_WEN = {"c0": 3.0, "k0": 700.0, "alpha": 1.0, "A": 2500.0, "beta": 9.0, "gamma": -2.0, "n": 0.6}


def secant_input(protocol, duration, rate=1000.0):
    """Samples of a protocol with the secant velocity: a continuous piecewise-linear input."""
    t = sample_times(duration, rate)
    x, _ = protocol.signals(t)
    v = np.append(np.diff(x) / np.diff(t), 0.0)
    return t, x, v


def signed_power(z, n):
    return math.copysign(abs(z) ** n, z)


def radau_forces(rhs, output, state, t, x, v):
    """Restart Radau (rtol 1e-10) at every sample; the force after each interval."""
    forces = [output(state, x[0], v[0])]
    for k in range(t.size - 1):
        h = t[k + 1] - t[k]
        solution = solve_ivp(rhs, (0.0, h), state, method="Radau", args=(x[k], v[k]), rtol=1e-10, atol=1e-10)
        assert solution.success
        state = solution.y[:, -1]
        forces.append(output(state, x[k] + v[k] * h, v[k]))
    return np.array(forces)


def spencer_y_dot(p, state, x_now, v_now):
    y, z = state
    return (p["alpha"] * z + p["c0"] * v_now + p["k0"] * (x_now - y)) / (p["c0"] + p["c1"])


def spencer_rhs(p, state, x_now, v_now):
    """Spencer et al. (1997): dy/dt = [alpha*z + c0*dx/dt + k0*(x - y)]/(c0 + c1),
    dz/dt = -gamma*|u|*z*|z|^(n-1) - beta*u*|z|^n + A*u, u = dx/dt - dy/dt."""
    y, z = state
    dy = spencer_y_dot(p, state, x_now, v_now)
    u = v_now - dy
    dz = -p["gamma"] * abs(u) * signed_power(z, p["n"]) - p["beta"] * u * abs(z) ** p["n"] + p["A"] * u
    return [dy, dz]


def bouc_wen_rhs(p, state, x_now, v_now):
    """Single Bouc-Wen: dz/dt = A*u - beta*|u|*z*|z|^(n-1) - gamma*u*|z|^n with u = dx/dt (the
    paper's eq. 1 convention)."""
    z = state[0]
    return [p["A"] * v_now - p["beta"] * abs(v_now) * signed_power(z, p["n"]) - p["gamma"] * v_now * abs(z) ** p["n"]]


def spencer_reference(p, t, x, v):
    """Spencer's equations (:func:`spencer_rhs`), F = c1*dy/dt + k1*(x - x0)."""
    def output(state, x_now, v_now):
        return p["c1"] * spencer_y_dot(p, state, x_now, v_now) + p["k1"] * (x_now - p["x0"])

    return radau_forces(lambda time, state, x_start, v_now: spencer_rhs(p, state, x_start + v_now * time, v_now),
                        output, np.array([x[0], 0.0]), t, x, v)


def bouc_wen_reference(p, t, x, v):
    """The single Bouc-Wen element (:func:`bouc_wen_rhs`), F = c0*dx/dt + k0*x + alpha*z."""
    def output(state, x_now, v_now):
        return p["c0"] * v_now + p["k0"] * x_now + p["alpha"] * state[0]

    return radau_forces(lambda time, state, x_start, v_now: bouc_wen_rhs(p, state, x_start + v_now * time, v_now),
                        output, np.array([0.0]), t, x, v)


@pytest.mark.parametrize("protocol, duration", [(Sine(2.0, 10.0), 0.3), (Step(2.0, 0.1, 0.4), 0.4)])
def test_spencer_matches_radau_on_spencers_own_equations(protocol, duration):
    t, x, v = secant_input(protocol, duration)
    expected = spencer_reference(SPENCER, t, x, v)
    predicted = simulate_model_held("spencer", SPENCER, t, x, v)
    assert np.max(np.abs(predicted - expected)) < 1e-3 * np.max(np.abs(expected))


def test_spencer_beta_and_gamma_are_not_interchangeable():
    # Guards the convention swap: with beta and gamma exchanged the loop is visibly different.
    t, x, v = secant_input(Sine(2.0, 10.0), 0.3)
    params = dict(SPENCER, beta=3.0)
    swapped = dict(params, beta=params["gamma"], gamma=params["beta"])
    expected = spencer_reference(params, t, x, v)
    assert np.max(np.abs(simulate_model_held("spencer", params, t, x, v) - expected)) < 1e-3 * np.max(np.abs(expected))
    assert np.max(np.abs(simulate_model_held("spencer", swapped, t, x, v) - expected)) > 0.05 * np.max(np.abs(expected))


def test_single_bouc_wen_matches_radau_on_its_equations():
    t, x, v = secant_input(Sine(2.0, 10.0), 0.3)
    expected = bouc_wen_reference(BOUC_WEN, t, x, v)
    predicted = simulate_model_held("single_bouc_wen", BOUC_WEN, t, x, v)
    assert np.max(np.abs(predicted - expected)) < 1e-3 * np.max(np.abs(expected))


def test_single_bouc_wen_starts_with_its_spring_force_at_an_offset():
    # F = k0*x at rest with z = 0: the grounded spring carries the initial displacement.
    t = sample_times(0.1, 1000.0)
    x = np.full_like(t, 1.5)
    forces = simulate_model_held("single_bouc_wen", BOUC_WEN, t, x, np.zeros_like(t))
    assert forces == pytest.approx(BOUC_WEN["k0"] * 1.5, rel=1e-9)


def test_kelvin_voigt_is_exactly_linear():
    p = {"k": 1234.5, "c": 6.78, "preload": -42.0}
    t, x, v = secant_input(Sine(2.0, 10.0), 0.5)
    v = Sine(2.0, 10.0).signals(t)[1]  # a jump at every sample: still F = k*x + c*v
    assert simulate_model_held("kelvin_voigt", p, t, x, v)[1:] == pytest.approx(
        p["k"] * (x[:-1] + v[:-1] * 1e-3) + p["c"] * v[:-1] + p["preload"], rel=1e-9, abs=1e-6)


def test_kelvin_voigts_linear_fit_is_numpys_least_squares_and_stays_in_its_ranges():
    # BushingModel.linear: F = k*x + c*v by least squares; a force whose best c is negative gets c = 0
    from identification.fitting.fit import linear_solution
    from identification.measured.measurements import Measurement
    t, x, v = secant_input(Sine(2.0, 10.0), 0.5)
    noise = np.random.default_rng(0).normal(0.0, 5.0, t.size)
    for k, c in ((1234.5, 6.78), (900.0, -0.5)):
        force = k * x + c * v + noise
        solved = linear_solution(get_model("kelvin_voigt"), [Measurement(t, x, force, v)])
        (k_ls, c_ls), *_ = np.linalg.lstsq(np.column_stack([x, v]), force, rcond=None)
        if c > 0:
            assert (solved["k"], solved["c"]) == pytest.approx((k_ls, c_ls), rel=1e-10)
        else:
            k_alone = float(x @ force / (x @ x))        # the best k with c held at its bound 0
            assert 0.0 <= solved["c"] < 1e-9 and solved["k"] == pytest.approx(k_alone, rel=1e-9)
        assert solved["preload"] == 0.0


@pytest.mark.parametrize("model, params, block", [("single_bouc_wen", BOUC_WEN, ""), ("spencer", SPENCER, "")])
def test_the_alpha_redundancy_holds_for_the_baselines(model, params, block):
    t, x, v = secant_input(Sine(2.0, 10.0), 0.3)
    scaled = _rescale_block(params, block, 3.7)
    assert scaled["alpha"] != params["alpha"]
    np.testing.assert_allclose(simulate_model_held(model, scaled, t, x, v), simulate_model_held(model, params, t, x, v),
                               rtol=1e-8, atol=1e-8 * np.max(np.abs(simulate_model_held(model, params, t, x, v))))


@pytest.mark.parametrize("model, params", [("single_bouc_wen", BOUC_WEN), ("spencer", dict(SPENCER, x0=0.0))])
def test_search_space_round_trip_for_the_baselines(model, params):
    space = SearchSpace(800.0, 5.0, 3000.0, 0.001, model=model)
    theta = space.to_coordinates(params)
    back = dict(zip(get_model(model).parameter_names, space.to_model_parameters(theta)[0]))
    assert back == pytest.approx(params, rel=1e-12)
    assert space.inside(theta)[0]


@pytest.mark.parametrize("model", ["spencer", "single_bouc_wen", "kelvin_voigt"])
@pytest.mark.parametrize("suffix", [".json", ".ssv"])
def test_baseline_parameter_files_round_trip_and_name_their_model(tmp_path, model, suffix):
    params = {"spencer": SPENCER, "single_bouc_wen": BOUC_WEN, "kelvin_voigt": {"k": 1.0, "c": 2.0, "preload": 3.0}}[model]
    path = save_parameters(tmp_path / f"p{suffix}", params, model)
    parameter_set = read_parameter_set(path)
    assert parameter_set.model is MODELS[model] and parameter_set.parameters == params
    if suffix == ".ssv":
        from fmpy.ssp.ssd import read_ssv
        assert {p.name: float(p.value) for p in read_ssv(str(path)).parameters} == params
    with pytest.raises(ParameterError, match="not proposed"):
        load_parameters(path, model="proposed")


def test_invalid_baseline_parameters_name_the_value_and_the_rule():
    errors, _ = get_model("spencer").validate(dict(SPENCER, c1=0.0))
    assert any("c1 = 0.0" in e and "> 0" in e for e in errors)
    with pytest.raises(ParameterError, match="unknown parameter names \\['k2'\\]"):
        get_model("kelvin_voigt").check({"k": 1.0, "c": 1.0, "preload": 0.0, "k2": 1.0})
    with pytest.raises(ParameterError, match="unknown model 'maxwell'"):
        get_model("maxwell")
