"""The native FMUs' directional derivatives (fmi2GetDirectionalDerivative, fmi3GetDirectionalDerivative,
fmi3GetAdjointDerivative): against central differences of the FMU's own outputs and states'
derivatives (model exchange) and of its output under the co-simulation input convention (the
displacement jump carried by the dashpots), the adjoint against the transposed Jacobian, never a
non-finite value over 10 000 random points per model (the switches included), the
``<ModelStructure>`` dependencies against the Jacobian's structural zeros, and the errors a host
gets for variables that cannot be differentiated. Every model and the six-axis FMU, FMI 2 and 3.

Units at this interface are the FMU's: m, m/s, N (rad, rad/s, N.m on rotational axes).
"""
from __future__ import annotations

import ctypes

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Model, FMU2Slave
from fmpy.fmi3 import FMU3Model, FMU3Slave

from fmu_harness import logging_callbacks
from fmu_src.model.registry import MODELS

FMUS = (*MODELS, "six_axis")
VERSIONS = (2, 3)
RELATIVE = 1e-6           # the target for central differences of the FMU's outputs
CS_STEP = 1e-6
"""The co-simulation differences' step, relative to a known's nominal size."""
POINTS = 12
FINITE_POINTS = 10_000


@pytest.fixture(scope="module")
def fmus(native_model_fmus, native_model_fmi3_fmus):
    return {2: native_model_fmus, 3: native_model_fmi3_fmus}


class Opened:
    """One initialised instance of a native FMU through fmpy's low-level API, model exchange
    ("me", in continuous-time mode) or co-simulation ("cs"), that keeps its log messages."""

    def __init__(self, path, interface: str, exit_initialization: bool = True):
        self.description = d = read_model_description(str(path))
        self.fmi3 = d.fmiVersion == "3.0"
        self.interface = interface
        self.messages: list[str] = []
        kind = {(False, "me"): FMU2Model, (False, "cs"): FMU2Slave, (True, "me"): FMU3Model, (True, "cs"): FMU3Slave}
        identifier = (d.modelExchange if interface == "me" else d.coSimulation).modelIdentifier
        self.fmu = kind[self.fmi3, interface](guid=d.guid, unzipDirectory=extract(str(path)),
                                              modelIdentifier=identifier, instanceName="derivatives")
        if self.fmi3:
            self.fmu.instantiate(loggingOn=True, logMessage=lambda env, status, category, message:
                                 self.messages.append(message.decode()))
            self.fmu.enterInitializationMode(startTime=0.0)
        else:
            self._callbacks = logging_callbacks(lambda status, category, message: self.messages.append(message))
            self.fmu.instantiate(callbacks=self._callbacks, loggingOn=True)
            self.fmu.setupExperiment(startTime=0.0)
            self.fmu.enterInitializationMode()
        if exit_initialization:
            self.fmu.exitInitializationMode()
            if interface == "me":
                self.fmu.enterContinuousTimeMode()
        self.derivatives = [v for v in d.modelVariables if v.derivative is not None]
        self.states = [v.derivative for v in self.derivatives]
        self.inputs = [v for v in d.modelVariables if v.causality == "input"]
        self.outputs = [v for v in d.modelVariables if v.causality == "output"]
        self.indicators = d.numberOfEventIndicators
        self.time = 0.0

    # ---- values
    def set_inputs(self, values) -> None:
        (self.fmu.setFloat64 if self.fmi3 else self.fmu.setReal)([v.valueReference for v in self.inputs], list(values))

    def get(self, variables) -> np.ndarray:
        return np.array((self.fmu.getFloat64 if self.fmi3 else self.fmu.getReal)([v.valueReference for v in variables]))

    def set_states(self, values) -> None:
        self.fmu.setContinuousStates((ctypes.c_double * len(values))(*values), len(values))

    def event_indicators(self) -> np.ndarray:
        if not self.indicators:
            return np.zeros(0)
        values = (ctypes.c_double * self.indicators)()
        self.fmu.getEventIndicators(values, self.indicators)
        return np.array(values)

    def step(self, h: float) -> None:
        self.fmu.doStep(self.time, h)
        self.time += h

    # ---- derivatives
    def directional(self, unknowns, knowns, seed) -> np.ndarray:
        return np.array(self.fmu.getDirectionalDerivative([v.valueReference for v in unknowns],
                                                          [v.valueReference for v in knowns], list(seed)))

    def adjoint(self, unknowns, knowns, seed) -> np.ndarray:
        return np.array(self.fmu.getAdjointDerivative([v.valueReference for v in unknowns],
                                                      [v.valueReference for v in knowns], list(seed), len(knowns)))

    def jacobian(self, unknowns, knowns) -> np.ndarray:
        """Column by column, as a host builds it (Reference-FMUs' examples/jacobian.c)."""
        return np.column_stack([self.directional(unknowns, [k], [1.0]) for k in knowns])

    def free(self) -> None:
        self.fmu.terminate()
        self.fmu.freeInstance()


def rotational(variable) -> bool:
    return (variable.unit or "").startswith("rad") or (variable.unit or "") == "N.m"


def nominal(variable) -> float:
    """A variable's size: states their declared nominal; displacements 1 mm (0.01 rad);
    velocities a 1 Hz motion of that; outputs and rates are compared row by row."""
    if variable.nominal is not None:
        return float(variable.nominal)
    travel = 1e-2 if rotational(variable) else 1e-3
    return travel * 2.0 * np.pi if (variable.unit or "").endswith("/s") else travel


def random_inputs(opened: Opened, rng) -> list[float]:
    return [nominal(v) * rng.uniform(-2.0, 2.0) for v in opened.inputs]


def assert_rows_agree(got: np.ndarray, want: np.ndarray, scales: np.ndarray, what: str) -> None:
    """Each row of two Jacobians, their columns scaled by the knowns' sizes, within RELATIVE of the
    row's largest scaled entry (a central difference's rounding is relative to its row's terms)."""
    scaled_got, scaled_want = got * scales, want * scales
    for i in range(got.shape[0]):
        size = np.max(np.abs(scaled_want[i]))
        if size == 0.0:
            assert np.all(scaled_got[i] == 0.0), f"{what}: row {i} {got[i]} where differences give 0"
            continue
        error = np.max(np.abs(scaled_got[i] - scaled_want[i])) / size
        assert error <= RELATIVE, f"{what}: row {i}: {got[i]} against {want[i]} (relative {error:.2e})"


# ---------------------------------------------------------------------------- model exchange
@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("name", FMUS)
def test_model_exchange_jacobian_equals_central_differences(fmus, name, version):
    """d(F, der(states))/d(states, x, v) against central differences of getReal/getDerivatives, at
    random states and inputs; a column whose difference crosses a switch (an event indicator
    changing sign within the stencil) is left out, and most are kept."""
    opened = Opened(fmus[version][name], "me")
    rng = np.random.default_rng(7)
    unknowns = opened.outputs + opened.derivatives
    knowns = opened.states + opened.inputs
    scales = np.array([nominal(k) for k in knowns])
    compared = skipped = 0
    for _ in range(POINTS):
        states = [nominal(s) * rng.uniform(-0.5, 0.5) for s in opened.states]
        inputs = random_inputs(opened, rng)
        point = np.array(states + inputs)

        def values(at):
            opened.set_states(list(at[:len(states)]))
            opened.set_inputs(at[len(states):])
            return np.concatenate([opened.get(opened.outputs), opened.get(opened.derivatives)]), \
                np.sign(opened.event_indicators())

        _, signs = values(point)
        jacobian = opened.jacobian(unknowns, knowns)
        difference = np.zeros_like(jacobian)
        keep = np.ones(len(knowns), dtype=bool)
        for j in range(len(knowns)):
            h = 1e-6 * max(abs(point[j]), scales[j])
            up, up_signs = values(point + h * np.eye(len(knowns))[j])
            down, down_signs = values(point - h * np.eye(len(knowns))[j])
            difference[:, j] = (up - down) / (2.0 * h)
            keep[j] = np.array_equal(up_signs, signs) and np.array_equal(down_signs, signs)
        values(point)
        assert np.all(np.isfinite(jacobian))
        assert_rows_agree(jacobian[:, keep], difference[:, keep], scales[keep], f"{name} FMI {version}")
        compared += keep.sum()
        skipped += (~keep).sum()
    assert compared >= 0.9 * (compared + skipped), (compared, skipped)
    opened.free()


# ---------------------------------------------------------------------------- co-simulation
def is_velocity(variable) -> bool:
    return (variable.unit or "").endswith("/s")


def run_sine(opened: Opened, steps: int, h: float = 1e-3) -> np.ndarray:
    """``steps`` communication steps more of a 5 Hz sine of twice the nominal travel on every axis;
    returns the inputs of the last step."""
    for _ in range(steps):
        phase = 10.0 * np.pi * opened.time
        inputs = np.array([2.0 * 10.0 * np.pi * nominal(v) / (2.0 * np.pi) * np.cos(phase) if is_velocity(v)
                           else 2.0 * nominal(v) * np.sin(phase) for v in opened.inputs])
        opened.set_inputs(inputs)
        opened.step(h)
    return inputs


def step_end(opened: Opened, inputs: np.ndarray, h: float = 1e-3) -> np.ndarray:
    """``inputs`` with each displacement moved to where a step of ``h`` from them ended, x + v*h (the
    inputs are each axis's displacement, then its velocity)."""
    ended = inputs.copy()
    for j, v in enumerate(opened.inputs):
        if not is_velocity(v):
            ended[j] = inputs[j] + h * inputs[j + 1]
    return ended


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("name", FMUS)
def test_co_simulation_dF_dx_dF_dv_are_those_of_the_output_the_fmu_returns(fmus, name, version):
    """In co-simulation, dF/d(x, v) at the communication point, where the output is the committed
    state taken through the displacement jump to the x set: against differences of the output itself
    (x set at +-h). At jumps of a few hundredths of a millimetre central differences; at no jump (x
    where the step ended, up to rounding) the output is not differentiable in x where the motion
    could reverse, and dF/dx is the one-sided derivative in the direction of the velocity set
    (second-order one-sided differences that way)."""
    opened = Opened(fmus[version][name], "cs")
    rng = np.random.default_rng(3)
    scales = np.array([nominal(v) for v in opened.inputs])
    for point in range(POINTS):
        at_end = step_end(opened, run_sine(opened, 7))
        no_jump = point % 2 == 0
        inputs = np.array([value + rng.uniform(-0.5, 0.5) * nominal(v) if is_velocity(v) else
                           value if no_jump else value + 0.02 * nominal(v) * rng.uniform(-1.0, 1.0)
                           for value, v in zip(at_end, opened.inputs)])
        opened.set_inputs(inputs)
        jacobian = opened.jacobian(opened.outputs, opened.inputs)
        difference = np.zeros_like(jacobian)

        def output(j, step):
            opened.set_inputs(inputs + step * np.eye(len(inputs))[j])
            return opened.get(opened.outputs)
        for j, v in enumerate(opened.inputs):
            h = CS_STEP * scales[j]
            if no_jump and not is_velocity(v):
                h *= 1.0 if inputs[j + 1] >= 0.0 else -1.0
                difference[:, j] = (-3.0 * output(j, 0.0) + 4.0 * output(j, h) - output(j, 2.0 * h)) / (2.0 * h)
            else:
                difference[:, j] = (output(j, h) - output(j, -h)) / (2.0 * h)
        opened.set_inputs(inputs)
        assert_rows_agree(jacobian, difference, scales, f"{name} FMI {version} co-simulation point {point}")
    opened.free()


def test_at_no_jump_the_derivative_is_the_one_sided_one_of_the_motion(fmus):
    """Where x is where the last step ended, the proposed model's dF/dx differs by side (moving on,
    or reversing, which the dashpots' jump would start): the FMU gives the side of the velocity set,
    whatever the rounding of x (exactly there, or 1e-16 m either side)."""
    opened = Opened(fmus[2]["proposed"], "cs")
    at_end = step_end(opened, run_sine(opened, 20))
    x = opened.inputs[0]
    h = 1e-9
    for velocity in (at_end[1], -at_end[1]):
        side = 1.0 if velocity > 0.0 else -1.0
        given = []
        for rounding in (0.0, 1e-16, -1e-16):
            inputs = np.array([at_end[0] + rounding, velocity])
            opened.set_inputs(inputs)
            given.append(opened.jacobian(opened.outputs, [x])[0, 0])
        forces = []
        for step in (0.0, side * h, 2.0 * side * h, -side * h, -2.0 * side * h):
            opened.set_inputs([at_end[0] + step, velocity])
            forces.append(opened.get(opened.outputs)[0])
        onward = (-3.0 * forces[0] + 4.0 * forces[1] - forces[2]) / (2.0 * side * h)
        back = (-3.0 * forces[0] + 4.0 * forces[3] - forces[4]) / (-2.0 * side * h)
        assert abs(onward - back) > 1e-3 * abs(onward)          # the two sides differ here
        for value in given:
            assert abs(value - onward) <= 1e-5 * abs(onward), (velocity, given, onward, back)
    opened.free()


# ---------------------------------------------------------------------------- adjoint
@pytest.mark.parametrize("interface", ["me", "cs"])
@pytest.mark.parametrize("name", FMUS)
def test_the_adjoint_is_the_transposed_jacobian(fmus, name, interface):
    opened = Opened(fmus[3][name], interface)
    rng = np.random.default_rng(11)
    unknowns = opened.outputs + (opened.derivatives if interface == "me" else [])
    knowns = (opened.states if interface == "me" else []) + opened.inputs
    for _ in range(5):
        if interface == "me":
            opened.set_states([nominal(s) * rng.uniform(-0.5, 0.5) for s in opened.states])
        else:
            run_sine(opened, 5)
        opened.set_inputs(random_inputs(opened, rng) if interface == "me" else opened.get(opened.inputs))
        jacobian = opened.jacobian(unknowns, knowns)
        rows = np.vstack([opened.adjoint(unknowns, knowns, np.eye(len(unknowns))[i]) for i in range(len(unknowns))])
        size = np.max(np.abs(jacobian))
        assert np.max(np.abs(rows - jacobian)) <= 1e-12 * size
        seed = rng.uniform(-1.0, 1.0, len(unknowns))
        assert np.allclose(opened.adjoint(unknowns, knowns, seed), jacobian.T @ seed, rtol=1e-12, atol=1e-12 * size)
    opened.free()


# ---------------------------------------------------------------------------- always finite
@pytest.mark.parametrize("name", FMUS)
def test_never_a_non_finite_derivative_over_10000_points_switches_included(fmus, name):
    """Random states and inputs (model exchange), random steps and jumps (co-simulation), a third
    of the state elements, the velocities and the jumps exactly 0 (the switches: |z|^n at z = 0, a
    block's relative velocity 0, abs at 0, a jump of 0); every derivative is OK and finite."""
    rng = np.random.default_rng(5)
    me = Opened(fmus[2][name], "me")
    unknowns, knowns = me.outputs + me.derivatives, me.states + me.inputs
    for _ in range(FINITE_POINTS // 2):
        states = [0.0 if rng.random() < 0.33 else nominal(s) * rng.uniform(-3.0, 3.0) for s in me.states]
        inputs = [0.0 if rng.random() < 0.33 else value for value in random_inputs(me, rng)]
        me.set_states(states)
        me.set_inputs(inputs)
        result = me.directional(unknowns, knowns, rng.uniform(-1.0, 1.0, len(knowns)))
        assert np.all(np.isfinite(result)), (states, inputs, result)
    me.free()
    cs = Opened(fmus[3][name], "cs")
    moving = np.array([is_velocity(v) for v in cs.inputs])
    inputs = np.zeros(len(cs.inputs))
    for k in range(FINITE_POINTS // 2):
        for j, v in enumerate(cs.inputs):
            if moving[j]:
                inputs[j] = 0.0 if rng.random() < 0.33 else nominal(v) * rng.uniform(-3.0, 3.0)
            elif rng.random() < 0.5:    # else no jump: x stays where the last step left the state
                inputs[j] = np.clip(inputs[j] + 0.05 * nominal(v) * rng.uniform(-1.0, 1.0), -3.0 * nominal(v),
                                    3.0 * nominal(v))
        cs.set_inputs(inputs)
        result = cs.directional(cs.outputs, cs.inputs, rng.uniform(-1.0, 1.0, len(cs.inputs)))
        assert np.all(np.isfinite(result)), (inputs, result)
        if k % 2:
            cs.step(1e-3)
            inputs = step_end(cs, inputs)      # the next point jumps from where this step ended, or not
    cs.free()


# ---------------------------------------------------------------------------- model structure
@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("name", FMUS)
def test_model_structure_lists_exactly_the_knowns_the_derivatives_depend_on(fmus, name, version):
    """Each output's and state derivative's dependencies: a known not listed has a derivative of
    exactly 0 at every point (model exchange, and for the outputs co-simulation too); a listed one
    is nonzero somewhere (an output's input in model exchange or in co-simulation)."""
    me, cs = Opened(fmus[version][name], "me"), Opened(fmus[version][name], "cs")
    description = me.description
    knowns = me.states + me.inputs
    listed = {u.variable.name: {v.name for v in u.dependencies} for u in description.outputs + description.derivatives}
    rows = me.outputs + me.derivatives
    assert set(listed) == {v.name for v in rows}
    rng = np.random.default_rng(13)
    seen_me = np.zeros((len(rows), len(knowns)), dtype=bool)
    seen_cs = np.zeros((len(me.outputs), len(me.inputs)), dtype=bool)
    for _ in range(10):
        me.set_states([nominal(s) * rng.uniform(-0.5, 0.5) for s in me.states])
        me.set_inputs(random_inputs(me, rng))
        seen_me |= me.jacobian(rows, knowns) != 0.0
        run_sine(cs, 3)
        cs.set_inputs(cs.get(cs.inputs) + np.array([nominal(v) * rng.uniform(-0.1, 0.1) for v in cs.inputs]))
        seen_cs |= cs.jacobian(cs.outputs, cs.inputs) != 0.0
    for i, row in enumerate(rows):
        declared = np.array([k.name in listed[row.name] for k in knowns])
        nonzero = seen_me[i].copy()
        if i < len(me.outputs):
            nonzero[len(me.states):] |= seen_cs[i]
        assert np.array_equal(declared, nonzero), (row.name, [k.name for k in np.array(knowns)[declared != nonzero]])
    me.free()
    cs.free()


# ---------------------------------------------------------------------------- errors
@pytest.mark.parametrize("version", VERSIONS)
def test_what_cannot_be_differentiated_is_an_error_naming_it(fmus, version):
    cs = Opened(fmus[version]["proposed"], "cs")
    parameter = next(v for v in cs.description.modelVariables if v.causality == "parameter")
    state = cs.states[0]
    for unknowns, knowns, words in (
            ([cs.inputs[0]], cs.inputs, f"{cs.inputs[0].name} (value reference {cs.inputs[0].valueReference}) "
                                        "cannot be an unknown: in co-simulation the unknowns are the outputs"),
            (cs.outputs, [parameter], f"{parameter.name} (value reference {parameter.valueReference}) cannot be a "
                                      "known: in co-simulation the knowns are the inputs"),
            (cs.outputs, [state], f"{state.name} (value reference {state.valueReference}) cannot be a known")):
        with pytest.raises(FMICallException):
            cs.directional(unknowns, knowns, [1.0] * len(knowns))
        assert any(words in message for message in cs.messages), (words, cs.messages[-3:])
    with pytest.raises(FMICallException):
        cs.fmu.getDirectionalDerivative([cs.outputs[0].valueReference], [10_000], [1.0])
    assert any("the known value reference 10000 does not exist" in message for message in cs.messages)
    cs.free()
    me = Opened(fmus[version]["proposed"], "me")
    me.fmu.setReal([next(v.valueReference for v in me.description.modelVariables if v.name == "c1")], [-1.0]) \
        if version == 2 else me.fmu.setFloat64([next(v.valueReference for v in me.description.modelVariables
                                                    if v.name == "c1")], [-1.0])
    with pytest.raises(FMICallException):
        me.directional(me.outputs, me.inputs, [1.0, 1.0])
    assert any("the derivatives cannot be computed: the parameters are invalid" in message for message in me.messages)
    me.free()


def test_fmi3_seed_and_sensitivity_counts_are_checked(fmus):
    me = Opened(fmus[3]["proposed"], "me")
    unknowns = (ctypes.c_uint32 * 1)(me.outputs[0].valueReference)
    knowns = (ctypes.c_uint32 * 2)(*(v.valueReference for v in me.inputs))
    seed, sensitivity = (ctypes.c_double * 2)(1.0, 1.0), (ctypes.c_double * 1)()
    for function in (me.fmu.fmi3GetDirectionalDerivative, me.fmu.fmi3GetAdjointDerivative):
        with pytest.raises(FMICallException):
            function(me.fmu.component, unknowns, 1, knowns, 2, seed, 1, sensitivity, 1)
    assert sum("nSeed = 1 and nSensitivity = 1 must be" in message for message in me.messages) == 2
    me.free()


@pytest.mark.parametrize("version", VERSIONS)
def test_in_initialization_mode_the_derivatives_are_refused_with_a_reason(fmus, version):
    """The state is set at the exit of initialization mode; before it there is nothing to differentiate."""
    opened = Opened(fmus[version]["proposed"], "cs", exit_initialization=False)
    with pytest.raises(FMICallException):
        opened.directional(opened.outputs, opened.inputs[:1], [1.0])
    assert any("available after the exit of initialization mode" in message for message in opened.messages)
    opened.fmu.exitInitializationMode()
    assert np.isfinite(opened.directional(opened.outputs, opened.inputs[:1], [1.0])[0])
    opened.free()
