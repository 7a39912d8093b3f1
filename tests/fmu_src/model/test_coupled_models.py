"""The coupled (vector) form of every model with hysteresis (``definition.CoupledKernels``):
along any line it is the one-axis model, it turns with the path, and in the plane it follows the
equations typed independently in ``tests/references/generate_coupled_references.py`` (scipy's
Radau on the same straight pieces).

The kernels run in plain Python here, through the coupled step protocol
(``integration.step_coupled``) on a path sampled at 1 ms with the secant velocity, as a
co-simulation master feeds the FMU."""
import csv
import math
from pathlib import Path

import numpy as np
import pytest

from fmu_src.model.registry import MODELS, get_model
from fmu_src.model.elements import vector_friction_force
from fmu_src.model.integration import DEFAULT_MAX_SUBSTEPS, OK, vector_gain
from fmu_src.parameter_files import read_parameter_set
from python_core import run_coupled

REFERENCES = Path(__file__).resolve().parents[2] / "references"
DATA = Path(__file__).resolve().parents[3] / "data"
COUPLED = [name for name, model in MODELS.items() if model.coupled is not None]
STEP_S = 1e-3


def default_parameters(model):
    return read_parameter_set(DATA / model.default_file).parameters


def run_one_axis(model, params, xs):
    """The one-axis model's force at every sample after the first of ``xs`` [mm]."""
    m = model.constants(params)
    state, state_x, out = model.initial_state(m, xs[0]), xs[0], []
    for k in range(len(xs) - 1):
        v = (xs[k + 1] - xs[k]) / STEP_S
        state, _, status = model.step(m, state, state_x, xs[k], v, STEP_S, DEFAULT_MAX_SUBSTEPS)
        assert status == OK
        state_x = xs[k] + v * STEP_S
        out.append(model.force(m, state, state_x, v))
    return np.array(out)


def test_every_model_with_hysteresis_has_a_coupled_form_and_kelvin_voigt_none():
    assert set(COUPLED) == {"proposed", "spencer", "single_bouc_wen", "berg", "fractional"}
    assert get_model("kelvin_voigt").coupled is None


t = np.arange(0.0, 0.5 + STEP_S / 2, STEP_S)
LINE = 2.0 * np.sin(2 * math.pi * 10 * t) + 0.5 * np.sin(2 * math.pi * 3 * t) + 0.3 * (t > 0.25)


@pytest.mark.parametrize("name", COUPLED)
@pytest.mark.parametrize("angle", [0.0, 0.7, 2.0, -2.9])
def test_along_a_line_at_any_angle_the_coupled_model_is_the_one_axis_model(name, angle):
    # a sine with a displacement jump at 0.25 s (a reversal of the friction, a walk of the blocks)
    model = get_model(name)
    params = default_parameters(model)
    one_axis = run_one_axis(model, params, LINE)
    direction = np.array([math.cos(angle), math.sin(angle), 0.0])
    coupled = run_coupled(model, params, LINE[:, None] * direction[None, :])
    assert np.max(np.abs(coupled - one_axis[:, None] * direction[None, :])) <= 1e-12 * np.max(np.abs(one_axis))


PLANE = np.stack([2.0 * np.sin(2 * math.pi * 10 * t), 1.5 * np.sin(2 * math.pi * 7 * t + 1.0) - 1.5 * math.sin(1.0)],
                 axis=1)


@pytest.mark.parametrize("name", COUPLED)
@pytest.mark.parametrize("angle", [0.9, -2.4])
def test_rotating_a_plane_path_rotates_the_forces(name, angle):
    model = get_model(name)
    params = default_parameters(model)
    rotation = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    forces = run_coupled(model, params, PLANE)
    turned = run_coupled(model, params, PLANE @ rotation.T)
    assert np.max(np.abs(turned[:, :2] - forces[:, :2] @ rotation.T)) <= 1e-12 * np.max(np.abs(forces))
    assert np.all(turned[:, 2] == 0.0) and np.all(forces[:, 2] == 0.0)     # a plane path stays in its plane


def reference(name, path):
    with open(REFERENCES / f"coupled_{name}_{path}.csv") as handle:
        rows = np.array([[float(v) for v in row] for row in list(csv.reader(handle))[1:]])
    return rows[:, 1:3], rows[1:, 3:5]


PATHS = ["circle_0.5mm_9.7Hz", "circle_4mm_4.7Hz", "ellipse_2x0.8mm_9.7Hz", "random_3mm"]
REFERENCE_TOLERANCE = 1e-3
"""max |F - F_ref| over max |F_ref| on a path: the issue's target. Observed 2026-11-26: proposed
2.8e-4, Spencer 7.1e-5, single Bouc-Wen 2.9e-5, Berg and fractional 6.3e-12 (exact over a step but
for the reference's own tolerance)."""


@pytest.mark.parametrize("name", COUPLED)
@pytest.mark.parametrize("path", PATHS)
def test_in_the_plane_the_coupled_model_follows_the_reference_within_a_thousandth_of_the_peak(name, path):
    model = get_model(name)
    xy, expected = reference(name, path)
    forces = run_coupled(model, default_parameters(model), xy)
    assert np.max(np.abs(forces[:, :2] - expected)) <= REFERENCE_TOLERANCE * np.max(np.abs(expected))


def test_the_isotropic_block_is_eq_1_along_a_line_and_finite_at_zero():
    A, beta, gamma, n = 2333.745, 12.063, -7.48, 0.562
    for z, u in [(300.0, 2.0), (300.0, -2.0), (-300.0, 2.0), (-300.0, -2.0)]:
        bracket = A - (gamma + beta * math.copysign(1.0, u) * math.copysign(1.0, z)) * abs(z) ** n
        rate = vector_gain((0.6 * z, 0.8 * z, 0.0), (0.6 * u, 0.8 * u, 0.0), A, beta, gamma, n)
        assert rate == pytest.approx((0.6 * u * bracket, 0.8 * u * bracket, 0.0), rel=1e-13)
    assert vector_gain((0.0, 0.0, 0.0), (1.0, 2.0, 0.0), A, beta, gamma, n) == (A, 2 * A, 0.0)
    tiny = vector_gain((1e-300, 0.0, 0.0), (0.0, 1.0, 0.0), A, beta, gamma, 0.1)
    assert all(math.isfinite(c) for c in tiny)


def test_the_friction_in_the_plane_is_berg_along_a_line_and_heads_for_its_limit_along_the_travel():
    limit, half = 400.0, 0.3
    up = vector_friction_force(limit, half, (0.2, 0.0, 0.0), (-100.0, 0.0, 0.0))
    beta = -100.0 / limit
    assert up[0] == pytest.approx(-100.0 + 0.2 * (limit + 100.0) / (half * (1 - beta) + 0.2), rel=1e-14)
    assert vector_friction_force(limit, half, (0.0, 0.0, 0.0), (50.0, 20.0, 0.0)) == (50.0, 20.0, 0.0)
    far = vector_friction_force(limit, half, (0.0, 1e6, 0.0), (200.0, 0.0, 0.0))
    assert far == pytest.approx((0.0, limit, 0.0), abs=1e-3)


@pytest.mark.parametrize("name", COUPLED)
def test_the_coupled_kernels_are_in_the_kernel_language_of_the_c_translation_and_the_tangents(name):
    from fmu_src.kernels.python_to_c import DOUBLE, INT, Translation
    from fmu_src.kernels.tangents import tangent
    model = get_model(name)
    kernels, vector = model.coupled, (DOUBLE,) * 3
    translation = Translation(prefix="bw")
    constants = translation.function(model.prepare, ((DOUBLE,) * len(model.specs),)).return_type
    state = (DOUBLE,) * kernels.size
    assert translation.function(kernels.initial_state, (constants, vector)).return_type == state
    translation.function(kernels.step, (constants, state, vector, vector, vector, DOUBLE, INT))
    assert translation.function(kernels.force, (constants, state, vector, vector)).return_type == vector
    for kernel in (kernels.derivatives, kernels.switches) + ((kernels.update,) if kernels.update else ()):
        translation.function(kernel, (constants, state, vector, vector))
    tangent(kernels.force), tangent(kernels.derivatives), tangent(kernels.jump, inactive=("m", "state"))


@pytest.mark.slow
@pytest.mark.parametrize("name", COUPLED)
def test_the_compiled_coupled_step_is_the_python_step_bit_for_bit(name):
    from fmu_src.kernels.numba_binding import kernel_module
    model = get_model(name)
    module, kernels = kernel_module(model), model.coupled
    m = model.constants(default_parameters(model))
    path = np.column_stack([PLANE, np.zeros(len(PLANE))])
    state = compiled = kernels.initial_state(m, (0.0, 0.0, 0.0))
    state_x = (0.0, 0.0, 0.0)
    for k in range(len(path) - 1):
        x, v = tuple(path[k]), tuple((path[k + 1] - path[k]) / STEP_S)
        x = (x[0], x[1] + (1e-3 if k == 100 else 0.0), x[2])       # one displacement jump
        state, used, status = kernels.step(m, state, state_x, x, v, STEP_S, DEFAULT_MAX_SUBSTEPS)
        compiled, used_compiled, status_compiled = module.step_coupled(m, compiled, state_x, x, v, STEP_S,
                                                                       DEFAULT_MAX_SUBSTEPS)
        assert compiled == state and (used_compiled, status_compiled) == (used, status) == (used, OK)
        state_x = tuple(x[i] + v[i] * STEP_S for i in range(3))
