"""The generated tangents (fmu_src/kernels/tangents.py) of every registered model's force and derivatives:
the value bit for bit the kernel's, the directional derivative equal to complex-step
differentiation of the plain kernel (central differences where the kernel cannot run on complex
numbers), finite on the switches, refusals named, and the generated source translatable to C."""
from __future__ import annotations

import math
import random

import pytest

from fmu_src.fmi.fmu_inputs import default_parameter_file
from fmu_src.model import integration
from fmu_src.model.registry import MODELS, get_model
from fmu_src.kernels.python_to_c import DOUBLE, INT, Translation
from fmu_src.parameter_files import load_parameters
from complex_step import Cs, STEP, bits, flat, on_complex_numbers, shifted
from fmu_src.kernels.tangents import SLOPE_CAP, TangentError, tangent, tangent_pow_slope, tangent_source

KERNELS = ("force", "derivatives")
POINTS = 200
DERIVED = {
    # models with the stateful option elements, their values beside the base's defaults
    "single_bouc_wen+iwan3+band+rig": dict(iwan_k=600.0, iwan_f=900.0, band_gap=0.5, band_k=1000.0, band_depth=0.2,
                                           band_f=100.0, band_ratio_pos=4.0, band_ratio_neg=2.0, band_travel=2.0,
                                           rig_displacement_zero=0.1, rig_force_zero=20.0),
    "kelvin_voigt+band": dict(band_gap=0.0, band_k=800.0, band_depth=0.0, band_f=300.0, band_ratio_pos=3.0,
                              band_ratio_neg=1.0, band_travel=0.0),
}
NAMES = list(MODELS) + list(DERIVED)


def complex_step(kernel, m, state, x, v, d_state, d_x, d_v):
    """The directional derivative by complex step, or None if the kernel cannot run on complex numbers."""
    kernel = on_complex_numbers(kernel)
    try:
        out = kernel(m, tuple(Cs(complex(s, STEP * d)) for s, d in zip(state, d_state)),
                     Cs(complex(x, STEP * d_x)), Cs(complex(v, STEP * d_v)))
    except TypeError:
        return None
    return [complex(e).imag / STEP for e in flat(out)]


def central_difference(kernel, m, state, x, v, d_state, d_x, d_v, h):
    up = flat(kernel(m, shifted(state, d_state, h), x + h * d_x, v + h * d_v))
    down = flat(kernel(m, shifted(state, d_state, -h), x - h * d_x, v - h * d_v))
    return [(a - b) / (2.0 * h) for a, b in zip(up, down)]


# ---------------------------------------------------------------------------- points
def default_constants(name):
    model = get_model(name)
    if name in DERIVED:
        base = name.split("+")[0]
        parameters = dict(load_parameters(default_parameter_file(base), base), **DERIVED[name])
    else:
        parameters = load_parameters(default_parameter_file(name), name)
    return model, model.prepare(model.values(parameters))


def state_scales(model, m):
    """Each state element's typical magnitude: the largest over a 1 Hz, 2 mm sine (plus 1e-3)."""
    state, largest = model.initial_state(m, 0.0), None
    largest = [0.0] * len(state)
    h = 5e-3
    for k in range(200):
        t = k * h
        x = 2.0 * math.sin(2.0 * math.pi * t)
        v = 4.0 * math.pi * math.cos(2.0 * math.pi * t)
        state, _ = integration.advance(model, m, state, x, x, v, h)
        largest = [max(a, abs(s)) for a, s in zip(largest, state)]
    return [a + 1e-3 for a in largest]


def random_points(name, count, seed):
    model, m = default_constants(name)
    scales = state_scales(model, m)
    rng = random.Random(seed)
    points = []
    for _ in range(count):
        x = rng.uniform(-3.0, 3.0)
        v = rng.uniform(-60.0, 60.0)
        base = model.initial_state(m, x)
        state = tuple(s + rng.uniform(-1.0, 1.0) * scale for s, scale in zip(base, scales))
        d_state = tuple(rng.uniform(-1.0, 1.0) * scale for scale in scales)
        points.append((state, x, v, d_state, rng.uniform(-1.0, 1.0), rng.uniform(-20.0, 20.0)))
    return model, m, points


def near_switch(model, m, state, x, v, d_state, d_x, d_v, h):
    """Whether a central difference of step h might cross a switch (an event indicator's sign)."""
    here = flat(model.switches(m, state, x, v))
    for sign in (1.0, -1.0):
        there = flat(model.switches(m, shifted(state, d_state, sign * h), x + sign * h * d_x, v + sign * h * d_v))
        if any((a > 0.0) != (b > 0.0) or (a < 0.0) != (b < 0.0) for a, b in zip(here, there)):
            return True
    return any(abs(s) < 1e-9 for s in here)


def agree(got, want, tolerance):
    scale = max([abs(w) for w in want] + [0.0])
    return all(abs(g - w) <= tolerance * max(abs(w), 1e-6 * scale) or abs(g - w) <= 1e-300 for g, w in zip(got, want))


# ---------------------------------------------------------------------------- tests
@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("kernel_name", KERNELS)
def test_tangent_equals_complex_step_and_value_is_the_kernels_bit_for_bit(name, kernel_name):
    model, m, points = random_points(name, POINTS, seed=35)
    kernel = getattr(model, kernel_name)
    kernel_tangent = tangent(kernel)
    compared = 0
    for state, x, v, d_state, d_x, d_v in points:
        value, derivative = kernel_tangent(m, state, x, v, d_state, d_x, d_v)
        assert bits(value) == bits(kernel(m, state, x, v)), (name, kernel_name, state, x, v)
        assert all(math.isfinite(e) for e in flat(derivative))
        want = complex_step(kernel, m, state, x, v, d_state, d_x, d_v)
        if want is not None:
            assert agree(flat(derivative), want, 1e-9), (name, kernel_name, state, x, v, flat(derivative), want)
            compared += 1
            continue
        h = 1e-6 * max([abs(x), abs(v) * 1e-2, 1.0] + [abs(s) for s in flat(state)]) / max(
            [abs(d_x), abs(d_v) * 1e-2] + [abs(d) for d in flat(d_state)] + [1e-300])
        if near_switch(model, m, state, x, v, d_state, d_x, d_v, 10.0 * h):
            continue
        want = central_difference(kernel, m, state, x, v, d_state, d_x, d_v, h)
        assert agree(flat(derivative), want, 1e-6), (name, kernel_name, state, x, v, flat(derivative), want)
        compared += 1
    assert compared >= POINTS // 2


def switch_points(model, m):
    """Points exactly on the switches: everything at rest at 0 (u = z = v = 0), z = 0 with u != 0,
    u or v = 0 with z != 0, and the smallest subnormals either side of 0."""
    rng = random.Random(7)
    rest = model.initial_state(m, 0.0)
    points = [(rest, 0.0, 0.0)]
    for tiny in (0.0, -0.0, 5e-324, -5e-324, 1e-300):
        for _ in range(3):
            x, v = rng.uniform(-2.0, 2.0), rng.uniform(-30.0, 30.0)
            state = tuple(s + rng.uniform(-1.0, 1.0) for s in model.initial_state(m, x))
            points.append((tuple(tiny for _ in state), x, v))
            points.append((state, x, tiny))
            points.append((rest, tiny, tiny))
            for i in range(len(state)):
                points.append((tuple(tiny if j == i else s for j, s in enumerate(state)), x, v))
    return points


@pytest.mark.parametrize("name", NAMES)
def test_tangents_are_finite_exactly_on_the_switches(name):
    model, m = default_constants(name)
    for kernel_name in KERNELS:
        kernel = getattr(model, kernel_name)
        kernel_tangent = tangent(kernel)
        for state, x, v in switch_points(model, m):
            size = len(state)
            directions = [(tuple(1.0 if j == i else 0.0 for j in range(size)), 0.0, 0.0) for i in range(size)]
            directions += [(tuple(0.0 for _ in range(size)), 1.0, 0.0), (tuple(0.0 for _ in range(size)), 0.0, 1.0),
                           (tuple(1.0 for _ in range(size)), 1.0, 1.0)]
            for d_state, d_x, d_v in directions:
                value, derivative = kernel_tangent(m, state, x, v, d_state, d_x, d_v)
                assert bits(value) == bits(kernel(m, state, x, v))
                assert all(math.isfinite(e) for e in flat(derivative)), (name, kernel_name, state, x, v, d_state)


def test_the_stated_one_sided_values():
    # d(a**b)/da = b*tangent_pow_slope(a, b): 0 at a = 0 for b > 1, 1 for b = 1, 0 for b < 1 (infinite
    # one-sided value), clamped near 0
    assert tangent_pow_slope(0.0, 2.0) == 0.0
    assert tangent_pow_slope(0.0, 1.0) == 1.0
    assert tangent_pow_slope(0.0, 0.5) == 0.0
    assert tangent_pow_slope(5e-324, 0.1) == SLOPE_CAP
    assert tangent_pow_slope(4.0, 0.5) == 0.5
    # block_gain at z = 0 returns A: its derivative in z there is 0 (the branch taken)
    block = (1.0, 1.0, 1.0, 2.0, 0.5, 0.3, 0.5)
    gain = tangent(integration.block_gain, inactive=("blk",))
    assert gain(0.0, 1.0, block, 1.0, 0.0) == (2.0, 0.0)
    # abs at 0: the right-hand derivative
    assert tangent(_abs_kernel, inactive=())(0.0, 1.0) == (0.0, 1.0)
    assert tangent(_abs_kernel, inactive=())(-0.0, 1.0) == (0.0, 1.0)
    # min/max at a tie: the first argument's derivative
    assert tangent(_min_kernel, inactive=())(1.0, 1.0, 2.0, 3.0) == (1.0, 2.0)


def _abs_kernel(a):
    return abs(a)


def _min_kernel(a, b):
    return min(a, b)


def _modulo(a, b):
    return a % b


def _method(a):
    return a.conjugate()


def _or_as_number(a, b):
    return a or b


def _local_helper(a):
    return a * 2.0


def _helper_in_conditional(a):
    return _local_helper(a) if a > 0.0 else a


@pytest.mark.parametrize("function, words", [
    (_modulo, "operator Mod"), (_method, "call of a.conjugate"), (_or_as_number, "and/or"),
    (_helper_in_conditional, "inside a conditional expression"),
])
def test_what_cannot_be_differentiated_is_refused_naming_function_and_line(function, words):
    with pytest.raises(TangentError) as refusal:
        tangent(function, inactive=())
    message = str(refusal.value)
    assert f"{function.__module__}.{function.__name__}, line " in message and words in message
    line = int(message.split(", line ")[1].split(":")[0])
    assert line == function.__code__.co_firstlineno + 1


@pytest.mark.parametrize("name", NAMES)
def test_the_generated_tangents_translate_to_c(name):
    def kind(value):
        return tuple(kind(e) for e in value) if isinstance(value, tuple) else DOUBLE if isinstance(value, float) else INT
    model, m = default_constants(name)
    state = tuple(float(s) for s in model.initial_state(m, 0.5))
    for kernel_name in KERNELS:
        translation = Translation(prefix="bw")
        translation.function(tangent(getattr(model, kernel_name)),
                             (kind(m), kind(state), DOUBLE, DOUBLE, kind(state), DOUBLE, DOUBLE))
        assert f"{kernel_name}_tangent" in translation.source()
    assert "def derivatives_tangent(m, state, x, v, d_state, d_x, d_v)" in tangent_source(model.derivatives)


def _math_helper(a, pair):
    first, second = pair
    return (math.exp(-a * first) * math.sqrt(second), min(a * a, second) ** 1.5)


def _math_kernel(m, state, x, v):
    scale = m[0]
    e, p = _math_helper(x, state)
    total = 0.0
    for i in range(3):
        total += scale * math.sin(v * i) + math.cos(x) * math.log(abs(state[1]) + 1.0)
    if v > 0.0:
        total = total + max(e, p) / (1.0 + x * x)
    else:
        total -= abs(v) ** state[0] - e
    return (total, e * p, -p if x < 0.0 else p * v)


def test_math_functions_loops_and_helpers_against_central_differences():
    rng = random.Random(3)
    kernel_tangent = tangent(_math_kernel)
    for _ in range(300):
        state = (rng.uniform(0.2, 2.0), rng.uniform(0.2, 2.0))
        x, v = rng.uniform(-1.0, 1.0), rng.uniform(-2.0, 2.0)
        d_state, d_x, d_v = (rng.uniform(-1, 1), rng.uniform(-1, 1)), rng.uniform(-1, 1), rng.uniform(-1, 1)
        value, derivative = kernel_tangent((0.7,), state, x, v, d_state, d_x, d_v)
        assert bits(value) == bits(_math_kernel((0.7,), state, x, v))
        h = 1e-6


        # away from the kernel's switches: v = 0, x = 0, and min's tie x*x = state[1]
        if min(abs(v), abs(x), abs(x * x - state[1])) < 1e-4:
            continue
        want = central_difference(_math_kernel, (0.7,), state, x, v, d_state, d_x, d_v, h)

        assert agree(flat(derivative), want, 1e-6), (state, x, v, flat(derivative), want)


@pytest.mark.parametrize("name", NAMES)
def test_jump_tangent_equals_complex_step(name):
    """The tangent of ``jump`` in the jump (the state constant), which the native FMU's
    co-simulation dF/dx takes through the displacement jump: the state after the jump bit for bit
    the kernel's, its derivative against complex step (jumps up to 0.3 mm, the walk along xi
    included)."""
    model, m, points = random_points(name, POINTS, seed=36)
    jump_tangent = tangent(model.jump, inactive=("m", "state"))
    compared = 0
    for state, x, *_ in points:
        jump = 0.1 * x
        value, derivative = jump_tangent(m, state, jump, 1.0)
        assert bits(value) == bits(model.jump(m, state, jump))
        if value[1] != integration.OK:
            continue
        stepped = on_complex_numbers(model.jump)(m, state, Cs(complex(jump, STEP)))
        want = [complex(e).imag / STEP for e in flat(stepped[0])]
        got = flat(derivative[0]) if isinstance(derivative[0], tuple) else [derivative[0]] * len(want)
        assert all(math.isfinite(g) for g in got)
        assert agree(got, want, 1e-9), (name, state, jump, got, want)
        compared += 1
    assert compared >= POINTS // 2
