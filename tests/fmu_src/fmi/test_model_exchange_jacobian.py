"""Model exchange given the FMU's Jacobian (fmi2GetDirectionalDerivative) against scipy's difference
Jacobian: the issue's target on a short stretch (the full run: benchmarks/bench_model_exchange_jacobian.py,
docs/benchmarks.md "Model exchange with the FMU's Jacobian").

The fractional model (23 states) on the paper's sine (2 mm, 10 Hz) up to 0.024 s, before the first
reversal at 0.025 s, so no event falls in the stretch (its event indicator, v, stays positive). The
model is linear in its relaxation states there, and both runs take the same steps: the FMU's Jacobian
saves the right-hand sides scipy's num_jac spends on a difference Jacobian (n per Jacobian and its
step refinements), which scipy's nfev leaves out, so every fmi2GetDerivatives call is counted here.
The proposed model is no test of this: its difference and exact Jacobians take Radau down
different step sequences across the Bouc-Wen switches (errors apart by up to 45x either way, the
benchmark). Units at this interface: s, m, m/s, N.
"""
from __future__ import annotations

import ctypes

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model
from scipy.integrate import solve_ivp

OMEGA = 2.0 * np.pi * 10.0
AMPLITUDE_M = 2e-3
END_S = 0.024
_DOUBLES = ctypes.POINTER(ctypes.c_double)


class Exchange:
    """A native FMU (FMI 2.0) in continuous-time mode, evaluated at (t, states) with the sine's
    inputs of that t; counts its right-hand sides."""

    def __init__(self, path):
        d = read_model_description(str(path))
        self.refs = {v.name: v.valueReference for v in d.modelVariables}
        derivatives = [v for v in d.modelVariables if v.derivative is not None]
        self.derivative_refs = [v.valueReference for v in derivatives]
        self.state_refs = [v.derivative.valueReference for v in derivatives]
        self.nominal = np.array([float(v.derivative.nominal or 1.0) for v in derivatives])
        self.n, self.nz = d.numberOfContinuousStates, d.numberOfEventIndicators
        self.fmu = FMU2Model(guid=d.guid, unzipDirectory=extract(str(path)),
                             modelIdentifier=d.modelExchange.modelIdentifier, instanceName="exchange")
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.at(0.0, None)
        self.fmu.exitInitializationMode()
        self.fmu.enterContinuousTimeMode()
        self.start = np.zeros(self.n)
        self.fmu.getContinuousStates(self.start.ctypes.data_as(_DOUBLES), self.n)
        self.rhs_calls = 0

    def at(self, t, y) -> None:
        self.fmu.setTime(t)
        self.fmu.setReal([self.refs["x"], self.refs["v"]],
                         [AMPLITUDE_M * np.sin(OMEGA * t), AMPLITUDE_M * OMEGA * np.cos(OMEGA * t)])
        if y is not None:
            y = np.ascontiguousarray(y, dtype=float)
            self.fmu.setContinuousStates(y.ctypes.data_as(_DOUBLES), self.n)

    def rhs(self, t, y) -> np.ndarray:
        self.rhs_calls += 1
        self.at(t, y)
        dx = (ctypes.c_double * self.n)()
        self.fmu.getDerivatives(dx, self.n)
        return np.array(dx)

    def jacobian(self, t, y) -> np.ndarray:
        self.at(t, y)
        return np.column_stack([self.fmu.getDirectionalDerivative(self.derivative_refs, [ref], [1.0])
                                for ref in self.state_refs])

    def indicators(self, t, y) -> np.ndarray:
        self.at(t, y)
        z = (ctypes.c_double * self.nz)()
        self.fmu.getEventIndicators(z, self.nz)
        return np.array(z)

    def forces(self, times, states) -> np.ndarray:
        out = []
        for t, y in zip(times, states.T):
            self.at(t, y)
            out.append(self.fmu.getReal([self.refs["F"]])[0])
        return np.array(out)

    def run(self, rtol: float, fmu_jacobian: bool, times):
        self.rhs_calls = 0
        solution = solve_ivp(self.rhs, (times[0], times[-1]), self.start, method="Radau", t_eval=times,
                             rtol=rtol, atol=rtol * self.nominal, jac=self.jacobian if fmu_jacobian else None)
        assert solution.success, solution.message
        return solution, self.rhs_calls, self.forces(times, solution.y)


@pytest.mark.parametrize("rtol", (1e-6, 1e-8))
def test_radau_given_the_fmus_jacobian_is_as_accurate_with_fewer_right_hand_sides(native_model_fmus, rtol):
    exchange = Exchange(native_model_fmus["fractional"])
    times = np.linspace(0.0, END_S, 25)
    _, _, reference = exchange.run(1e-11, True, times)
    peak = np.max(np.abs(reference))
    exact, exact_rhs, exact_force = exchange.run(rtol, True, times)
    differences, difference_rhs, difference_force = exchange.run(rtol, False, times)
    assert np.all(exchange.indicators(times[-1], exact.y[:, -1]) > 0.0), "an event fell in the stretch"
    exact_error = np.max(np.abs(exact_force - reference)) / peak
    difference_error = np.max(np.abs(difference_force - reference)) / peak
    assert exact_error <= max(2.0 * difference_error, 1e-3 * rtol), (exact_error, difference_error)
    assert exact_error <= 10.0 * rtol, exact_error
    # a difference Jacobian costs n right-hand sides (23); ask for at least half of that per Jacobian
    saved = difference_rhs - exact_rhs
    assert saved >= 0.5 * exchange.n * exact.njev, (exact_rhs, difference_rhs, exact.njev, differences.njev)
    # scipy's nfev counts every right-hand side given the FMU's Jacobian, and leaves num_jac's out
    assert exact.nfev == exact_rhs and differences.nfev + exchange.n * differences.njev <= difference_rhs
