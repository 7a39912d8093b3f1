"""Bad values: refused with a logged reason, no NaN force, nothing lost, no crash or hang."""
import math
import time

import numpy as np
import pytest

from fmu_harness import BushingFmu

MM = 1e-3
STEP = 1e-3


def run_steps(fmu, count, start=0):
    for k in range(start, start + count):
        t = k * STEP
        assert fmu.step(2 * MM * math.sin(20 * math.pi * t), 2 * MM * 20 * math.pi * math.cos(20 * math.pi * t),
                        STEP) == "ok"
    return fmu.get("F")


def undisturbed_force(fmu_path, count):
    fmu = BushingFmu(fmu_path)
    force = run_steps(fmu, count)
    fmu.free()
    return force


@pytest.mark.parametrize("name, value, fragments", [
    ("c1", 0.0, ["c1 = 0.0", "must be > 0"]),
    ("c1", -1.0, ["c1 = -1.0", "must be > 0"]),
    ("c0", -300.0, ["c0 + c2", "must be > 0"]),
    ("n1", 0.0, ["n1 = 0.0", "must be > 0"]),
    ("k2", -5.0, ["k2 = -5.0", "must be >= 0"]),
    ("A2", math.nan, ["A2 = nan", "finite"]),
    ("beta1", math.inf, ["beta1 = inf", "finite"]),
])
def test_invalid_parameter_refuses_the_step_and_nothing_is_lost(fmu_path, name, value, fragments):
    fmu = BushingFmu(fmu_path)
    run_steps(fmu, 20)
    states, force = fmu.states(), fmu.get("F")
    good = fmu.get(name)
    fmu.set(name, value)
    assert fmu.do_step(STEP) == "discard"
    errors = fmu.messages_with("error")
    assert any(all(fragment in message for fragment in fragments) for message in errors), errors
    assert fmu.states() == states
    assert math.isfinite(fmu.get("F")) and fmu.get("F") == force
    fmu.set(name, good)  # fixed: the run continues as if nothing had happened
    assert run_steps(fmu, 20, start=20) == undisturbed_force(fmu_path, 40)
    fmu.free()


@pytest.mark.parametrize("name, value", [("x", math.nan), ("v", math.inf), ("x", -math.inf)])
def test_non_finite_input_refuses_the_step_with_its_name(fmu_path, name, value):
    fmu = BushingFmu(fmu_path)
    run_steps(fmu, 10)
    force = fmu.get("F")
    fmu.set(name, value)
    assert fmu.do_step(STEP) == "discard"
    assert any(f"input {name} = {value}" in message for message in fmu.messages_with("error"))
    assert fmu.get("F") == force
    fmu.free()


@pytest.mark.parametrize("step", [0.0, -1e-3, math.nan])
def test_invalid_step_size_is_refused(fmu_path, step):
    fmu = BushingFmu(fmu_path)
    assert fmu.do_step(step) == "discard"
    assert any("step size" in message for message in fmu.messages_with("error"))
    fmu.free()


def test_overflowing_step_is_refused_not_a_nan_force(fmu_path):
    # Without alpha2 and with n2 = 1, z2 grows like exp(3.4/mm * x): a stroke of 2 m
    # (millimetres entered as metres) overflows.
    fmu = BushingFmu(fmu_path, start_values={"alpha2": 0.0, "n2": 1.0})
    run_steps(fmu, 10)
    states, force = fmu.states(), fmu.get("F")
    started = time.perf_counter()
    assert fmu.step(0.0, 2.0 / 0.4, 0.4) == "discard"
    assert time.perf_counter() - started < 10.0
    assert any("units" in message for message in fmu.messages_with("error"))
    assert fmu.states() == states  # the inputs changed, so F may; the state may not
    assert math.isfinite(fmu.get("F"))
    fmu.free()


def test_millimetres_entered_as_metres_are_refused_with_a_units_hint(fmu_path):
    # x jumps from 0 to 2 m: z2 follows dz2/dxi = A2 + 3.4/mm*|z2|^0.95 over 2000 mm at once.
    fmu = BushingFmu(fmu_path)
    run_steps(fmu, 10)
    states = fmu.states()
    assert fmu.step(2.0, 0.0, STEP) == "discard"
    assert any("units" in message and "metres" in message for message in fmu.messages_with("error"))
    assert any("x = 2.0 m exceeds" in message for message in fmu.messages_with("warning"))
    assert fmu.states() == states
    assert math.isfinite(fmu.get("F"))
    fmu.free()


def test_implausible_travel_is_warned_once(fmu_path):
    fmu = BushingFmu(fmu_path)
    for k in range(80):  # a ramp at 2 m/s to 0.16 m, beyond any bushing's travel
        assert fmu.step(k * 2e-3, 2.0, STEP) == "ok"
    warnings = [m for m in fmu.messages_with("warning") if "exceeds 0.1 m" in m]
    assert len(warnings) == 1 and "metres" in warnings[0]
    assert math.isfinite(fmu.get("F"))
    fmu.free()


@pytest.mark.parametrize("name, value, fragment", [
    ("A1", 0.5, "A1 >= 1"), ("beta2", -0.1, "beta2 >= 0"), ("gamma2", 1.0, "beta2 - gamma2 > 0")])
def test_paper_constraint_violation_is_accepted_with_a_warning(fmu_path, name, value, fragment):
    fmu = BushingFmu(fmu_path, start_values={name: value})
    assert fmu.step(0.0, 0.01, STEP) == "ok"
    assert any(fragment in message for message in fmu.messages_with("warning"))
    assert fmu.messages_with("error") == []
    fmu.free()


def test_messages_carry_a_category_the_model_description_declares(fmu_path):
    fmu = BushingFmu(fmu_path)
    fmu.set("c1", -1.0)
    fmu.do_step(STEP)
    declared = {category.name for category in fmu.description.logCategories}
    assert fmu.messages and all(category in declared for _, category, _ in fmu.messages)
    fmu.free()


def test_parameters_fixed_after_initialization_start_from_the_equilibrium(fmu_path):
    # Invalid at exitInitializationMode: no initial state can be computed then. Once fixed,
    # the first step starts from the relaxed equilibrium at x0, as if they had been valid.
    fmu = BushingFmu(fmu_path, start_values={"c1": -1.0}, x0_m=1.0 * MM)
    assert fmu.do_step(STEP) == "discard"
    fmu.set("c1", 1.485)
    assert fmu.do_step(STEP) == "ok"
    reference = BushingFmu(fmu_path, x0_m=1.0 * MM)
    assert reference.do_step(STEP) == "ok"
    assert fmu.states() == reference.states() and fmu.get("F") == reference.get("F")
    for instance in (fmu, reference):
        instance.free()
