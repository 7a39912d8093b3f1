"""The model core against independent references: scipy's Radau, analytic cases."""
import math

import numpy as np
import pytest

from conftest import paper_eq5, paper_equations, paper_parameters, reference_force, reference_jump
from fmu_src.model.integration import StepError, advance, apply_displacement_jump
from fmu_src.models.proposed_model import MODEL as PROPOSED
from fmu_src.model.registry import MODELS
from fmu_src.model.parameter_specs import ParameterError
from identification.measured.signals import Random, Sine, Step, sample_times
from python_core import simulate_python_core


def radau_error(params, protocol, duration_s, rate_hz):
    """Largest force difference between the core and the Radau reference, over the peak force,
    for ``protocol`` sampled (one communication step per sample) at ``rate_hz``."""
    t = sample_times(duration_s, rate_hz)
    x, v = protocol.signals(t)
    reference = reference_force(params, t, x, v)
    return np.max(np.abs(simulate_python_core(params, t, x, v) - reference)) / np.max(np.abs(reference))


@pytest.mark.parametrize("table", ["table2", "table4", "table5"])
def test_sine_10Hz_2mm_matches_radau_for_every_paper_table(table):
    assert radau_error(paper_parameters(table), Sine(2.0, 10.0), 0.12, 1000.0) < 1e-3


def test_step_2mm_rise_0p4s_matches_radau():
    assert radau_error(paper_parameters("table5"), Step(2.0, 0.4), 1.0, 100.0) < 1e-4  # 10 ms steps


def test_stiff_parameter_set_c1_0p01_matches_radau_at_10ms_steps():
    # c1 = 0.01 makes the y-z1 mode ~5e5 1/s: 5000 time constants per 10 ms step.
    assert radau_error(dict(paper_parameters("table5"), c1=0.01), Sine(2.0, 10.0), 0.1, 100.0) < 2e-3


def test_large_amplitude_30Hz_3mm_matches_radau():
    # z2 grows almost exponentially with displacement here (peak force ~15 kN).
    assert radau_error(paper_parameters("table5"), Sine(3.0, 30.0), 0.05, 1000.0) < 1e-3


def test_without_hysteresis_steady_sine_converges_to_analytic_complex_stiffness():
    # alpha1 = alpha2 = 0 leaves a linear network: F = K(i*omega) X with
    # K = k0 (k1 + i w c1)/(k0 + k1 + i w c1) + c0 i w (k2 + i w c2)/(k2 + i w (c0 + c2)).
    # The input holds v at its sampled value over each interval, a first-order error in the
    # sample interval: the error must shrink ~4x when the sampling is 4x finer.
    params = dict(paper_parameters("table5"), alpha1=0.0, alpha2=0.0, k2=1000.0)
    frequency, amplitude = 10.0, 1.0
    w = 2 * np.pi * frequency
    p = params
    stiffness = (p["k0"] * (p["k1"] + 1j * w * p["c1"]) / (p["k0"] + p["k1"] + 1j * w * p["c1"])
                 + p["c0"] * 1j * w * (p["k2"] + 1j * w * p["c2"]) / (p["k2"] + 1j * w * (p["c0"] + p["c2"])))
    errors = []
    for rate in (4000.0, 16000.0):
        t = sample_times(3.0, rate)
        x, v = Sine(amplitude, frequency).signals(t)
        force = simulate_python_core(params, t, x, v)
        analytic = np.imag(stiffness * amplitude * np.exp(1j * w * t))
        last_period = t >= 3.0 - 1.0 / frequency  # transients (slowest: 0.26 s) have died out
        errors.append(np.max(np.abs(force[last_period] - analytic[last_period])) / np.max(np.abs(analytic)))
    assert errors[1] < 3e-4
    assert 3.0 < errors[0] / errors[1] < 5.0


def test_initial_state_is_relaxed_equilibrium_with_static_stiffness():
    params = paper_parameters("table5")
    x0 = 1.5
    constants = PROPOSED.constants(params)
    state = PROPOSED.initial_state(constants, x0)
    static_stiffness = params["k0"] * params["k1"] / (params["k0"] + params["k1"])
    assert PROPOSED.force(constants, state, x0, 0.0) == pytest.approx(static_stiffness * x0, rel=1e-12)
    assert paper_equations(0.0, state, params, lambda t: x0, lambda t: 0.0) == pytest.approx([0, 0, 0, 0], abs=1e-9)
    held, _ = advance(PROPOSED, constants, state, x0, x0, 0.0, 5.0)
    assert PROPOSED.force(constants, held, x0, 0.0) == pytest.approx(static_stiffness * x0, rel=1e-12)


def test_random_input_matches_radau():
    assert radau_error(paper_parameters("table5"), Random(peak_mm=2.0, duration_s=0.3, seed=3), 0.3, 1000.0) < 1e-3


def test_advance_reports_unbounded_growth_and_leaves_input_state():
    # Without the alpha2 feedback and with n2 = 1, dz2/dx = A2 + 3.4/mm * z2 grows like
    # exp(3.4/mm * x): a ramp to 2 m (metres entered where millimetres were meant) overflows.
    params = dict(paper_parameters("table5"), alpha2=0.0, n2=1.0)
    constants = PROPOSED.constants(params)
    state = PROPOSED.initial_state(constants, 0.0)
    with pytest.raises(StepError, match="units"):
        advance(PROPOSED, constants, state, 0.0, 0.0, 2000.0 / 0.4, 0.4)
    assert state == PROPOSED.initial_state(constants, 0.0)


def test_paper_tables_saturate_instead_of_overflowing_for_a_2m_stroke():
    # With alpha2 > 0 the growing gain of z2 also raises lam2, so u2 decays and z2 stays
    # finite: the model gives a (physically absurd) finite force, which the FMU flags.
    params = paper_parameters("table5")
    constants = PROPOSED.constants(params)
    state, _ = advance(PROPOSED, constants, PROPOSED.initial_state(constants, 0.0), 0.0, 0.0, 2000.0 / 0.4, 0.4)
    assert all(math.isfinite(value) for value in state)


def test_advance_refuses_instead_of_hanging_when_substeps_run_out():
    params = paper_parameters("table5")
    constants = PROPOSED.constants(params)
    with pytest.raises(StepError, match="substeps"):
        advance(PROPOSED, constants, PROPOSED.initial_state(constants, 0.0), 0.0, 0.0, 500.0, 0.01, max_substeps=3)


validate_parameters = MODELS["proposed"].validate


def test_table5_satisfies_the_paper_constraints_and_validates_cleanly():
    errors, warnings = validate_parameters(paper_parameters("table5"))
    assert errors == [] and warnings == []


@pytest.mark.parametrize("name, value, fragment", [
    ("c1", 0.0, "c1 = 0.0 [N.s/mm] must be > 0 (it divides eq. 3)"),
    ("c1", -1.0, "c1 = -1.0 [N.s/mm] must be > 0"),
    ("c0", -300.0, "c0 = -300.0 [N.s/mm] must be >= 0"),
    ("c2", -1.0, "c2 = -1.0 [N.s/mm] must be >= 0"),
    ("n2", -1.0, "n2 = -1.0 [1] must be > 0"),
    ("n1", 0.0, "n1 = 0.0 [1] must be > 0"),
    ("k0", -1.0, "k0 = -1.0 [N/mm] must be >= 0"),
    ("k1", -5.0, "k1 = -5.0 [N/mm] must be >= 0"),
    ("alpha2", -0.1, "alpha2 = -0.1 [1] must be >= 0"),
    ("A2", -2.0, "A2 = -2.0 [N/mm] must be >= 0"),
    ("A1", math.nan, "A1 = nan [N/mm] must be a finite number"),
])
def test_invalid_parameters_are_errors_naming_value_unit_and_range(name, value, fragment):
    params = dict(paper_parameters("table5"), **{name: value})
    errors, _ = validate_parameters(params)
    assert any(fragment in message for message in errors), errors
    with pytest.raises(ParameterError, match=name):
        MODELS["proposed"].check(params)


@pytest.mark.parametrize("change, fragment", [
    ({"A2": 0.5}, "A2 >= 1"),
    ({"beta1": -1.0}, "beta1 >= 0"),
    ({"gamma1": -13.0}, "beta1 + gamma1 > 0"),
    ({"gamma2": 1.0}, "beta2 - gamma2 > 0"),
])
def test_paper_constraint_violations_are_warnings_not_errors(change, fragment):
    errors, warnings = validate_parameters(dict(paper_parameters("table5"), **change))
    assert errors == []
    assert any(fragment in message for message in warnings), warnings


@pytest.mark.parametrize("jump_mm", [0.3, -0.8, 2.5])
def test_displacement_jump_is_the_limit_of_a_steep_ramp_of_the_papers_equations(jump_mm):
    # The reference is scipy's Radau on the paper's eqs. 1-4 over a 1 ns ramp (conftest), not
    # the model's jump kernel.
    params = paper_parameters("table5")
    constants = PROPOSED.constants(params)
    start, _ = advance(PROPOSED, constants, PROPOSED.initial_state(constants, 0.0), 0.0, 0.0, 50.0, 0.02)  # x = 1 mm
    jumped = apply_displacement_jump(PROPOSED, constants, start, jump_mm)
    reference = reference_jump(params, start, 1.0, jump_mm)
    y, z1, w, z2 = jumped
    assert abs(y - reference[0]) < 1e-5 * abs(jump_mm) and abs(w - reference[2]) < 1e-5 * abs(jump_mm)
    assert abs(z1 - reference[1]) < 1e-5 * max(abs(start[1]), 1.0)        # z1 does not jump
    z2_scale = max(abs(start[3]), abs(reference[3]))  # z2 may pass through zero on the way
    assert abs(z2 - reference[3]) < 3e-4 * z2_scale
    jump_force = PROPOSED.force(constants, jumped, 1.0 + jump_mm, 0.0)
    assert abs(jump_force - paper_eq5(params, reference, 1.0 + jump_mm, 0.0)) < 3e-4 * abs(jump_force)


@pytest.mark.parametrize("model, name, value, fragment", [
    ("spencer", "c0", -1.0, "c0 = -1.0 [N.s/mm] must be >= 0"),
    ("spencer", "alpha", -1.0, "alpha = -1.0 [1] must be >= 0"),
    ("single_bouc_wen", "A", -5.0, "A = -5.0 [N/mm] must be >= 0"),
    ("kelvin_voigt", "c", -1.0, "c = -1.0 [N.s/mm] must be >= 0"),
    ("kelvin_voigt", "k", -1.0, "k = -1.0 [N/mm] must be >= 0"),
])
def test_every_model_refuses_values_outside_their_documented_range(model, name, value, fragment):
    from conftest import DATA
    from fmu_src.parameter_files import load_parameters
    bushing = MODELS[model]
    params = dict(load_parameters(DATA / bushing.default_file, model), **{name: value})
    errors, _ = bushing.validate(params)
    assert any(fragment in message for message in errors), errors
