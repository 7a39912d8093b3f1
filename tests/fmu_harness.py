"""Drive one instance of a built bushing FMU through fmpy's low-level FMI 2.0 API.

Used by the tests to see statuses, log messages and FMU states that fmpy's
``simulate_fmu`` hides. Units at this interface are the FMU's: m, m/s, N.
"""
from __future__ import annotations

import re

import numpy as np
from fmpy import simulate_fmu
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
from fmpy.fmi2 import calloc, free

from fmu_src.model.integration import DEFAULT_MAX_SUBSTEPS, OK

STATUS_NAMES = ["ok", "warning", "discard", "error", "fatal", "pending"]


def logging_callbacks(log) -> fmi2CallbackFunctions:
    """FMI 2 callbacks that pass each message to ``log(status name, category, message)`` (keep the
    returned object alive while the instance lives). pythonfmu logs the exception that fails a
    call with no category (NULL): ""."""
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(lambda component, instance_name, status, category, message:
                                              log(STATUS_NAMES[status], (category or b"").decode(),
                                                  (message or b"").decode()))
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    return callbacks


class BushingFmu:
    """One FMU instance, initialised and ready to step."""

    def __init__(self, fmu_path, instance_name="bushing", start_values=None, x0_m=0.0, v0_m_s=0.0,
                 initial_inputs=None, exit_initialization=True):
        """``initial_inputs``: {port: value} set before initialisation ends (default: x and v of a
        one-axis FMU from ``x0_m``, ``v0_m_s``). ``exit_initialization=False``: the instance stays
        in initialization mode (the caller ends it: ``self.fmu.exitInitializationMode()``)."""
        self.description = read_model_description(fmu_path)
        self.refs = {v.name: v.valueReference for v in self.description.modelVariables}
        self.messages: list[tuple[str, str, str]] = []  # (status, category, message)
        self._callbacks = logging_callbacks(lambda *message: self.messages.append(message))
        self.unzip_dir = extract(fmu_path)
        self.fmu = FMU2Slave(guid=self.description.guid, unzipDirectory=self.unzip_dir,
                             modelIdentifier=self.description.coSimulation.modelIdentifier,
                             instanceName=instance_name)
        self.fmu.instantiate(callbacks=self._callbacks, loggingOn=True)
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        for name, value in (start_values or {}).items():
            self.set(name, value)
        for name, value in (initial_inputs if initial_inputs is not None else {"x": x0_m, "v": v0_m_s}).items():
            self.set(name, value)
        if exit_initialization:
            self.fmu.exitInitializationMode()
        self.time = 0.0

    def set(self, name: str, value: float) -> None:
        self.fmu.setReal([self.refs[name]], [value])

    def get(self, name: str) -> float:
        return self.fmu.getReal([self.refs[name]])[0]

    def step(self, x_m: float, v_m_s: float, h: float) -> str:
        """Set the inputs, do one step; return the status name ('ok' or 'discard'...)."""
        self.set("x", x_m)
        self.set("v", v_m_s)
        return self.do_step(h)

    def do_step(self, h: float) -> str:
        try:
            self.fmu.doStep(currentCommunicationPoint=self.time, communicationStepSize=h)
        except FMICallException as exc:
            return re.search(r"\((\w+)\)", str(exc)).group(1)
        self.time += h
        return "ok"

    def states(self) -> tuple[float, float, float, float]:
        """(y [m], z1 [N], w [m], z2 [N])"""
        return tuple(self.fmu.getReal([self.refs[n] for n in ("y", "z1", "w", "z2")]))

    def messages_with(self, status: str) -> list[str]:
        return [message for s, _, message in self.messages if s == status]

    def free(self) -> None:
        self.fmu.terminate()
        self.fmu.freeInstance()


MM = 1e-3


def simulate_with_fmpy(fmu_path, time_s, x_mm, v_mm_s, start_values=None):
    """Force [N] at the sample times from fmpy's simulate_fmu, one communication step per sample."""
    signals = np.zeros(time_s.size, dtype=[("time", float), ("x", float), ("v", float)])
    signals["time"], signals["x"], signals["v"] = time_s, x_mm * MM, v_mm_s * MM
    step = float(np.median(np.diff(time_s)))
    result = simulate_fmu(str(fmu_path), start_time=0.0, stop_time=time_s[-1], step_size=step,
                          output_interval=step, input=signals, output=["F"],
                          start_values=start_values or {})
    assert np.allclose(result["time"], time_s, rtol=0, atol=1e-9)
    return result["F"]


def kernel_forces(model, params, x_mm, step_s, state=None):
    """A one-axis model's force [N] after every step of ``step_s`` [s] along ``x_mm`` [mm], its
    kernels in plain Python from ``state`` at x_mm[0] (default: relaxed there), fed as an FMU is
    fed by a master that sets x and the secant velocity: the ports in metres, times 1000."""
    m = model.constants(params)
    x = [value * 1e-3 * 1000.0 for value in x_mm]
    velocity = [(x_mm[k + 1] - x_mm[k]) / step_s * 1e-3 * 1000.0 for k in range(len(x_mm) - 1)]
    state = model.initial_state(m, x[0]) if state is None else state
    state_x, out = x[0], []
    for k, v in enumerate(velocity):
        state, _, status = model.step(m, state, state_x, x[k], v, step_s, DEFAULT_MAX_SUBSTEPS)
        assert status == OK
        state_x = x[k] + v * step_s
        out.append(model.force(m, state, state_x, v))
    return np.array(out)
