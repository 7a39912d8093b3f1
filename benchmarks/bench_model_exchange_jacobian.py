"""Model exchange with the FMU's Jacobian against a difference Jacobian: the same accuracy with fewer right-hand sides?

    python benchmarks/bench_model_exchange_jacobian.py [--models proposed,berg,fractional] [--duration 1.0]

Builds each model's native FMU (FMI 2.0, default parameters: Table 5 for the proposed model) and
integrates its model-exchange states with scipy's implicit solvers (``Radau`` and ``BDF``, the
classes behind ``solve_ivp``) on the paper's sine (2 mm, 10 Hz, ``identification.measured.signals.Sine``;
the FMU takes metres): the inputs x(t), v(t) are set at the exact time of every right-hand side,
the right-hand side is ``fmi2GetDerivatives``. Each method and tolerance runs twice in one process:
once with the Jacobian d der(states)/d states from the FMU (``fmi2GetDirectionalDerivative``, one
call per column) and once with ``jac=None`` (scipy's forward differences, ``num_jac``).

Counting: scipy's ``nfev`` leaves out the right-hand sides that ``num_jac`` spends on a difference
Jacobian (``scipy/integrate/_ivp/base.py``: "the function evaluations used to compute a finite
difference approximation of the Jacobian should not be counted in nfev"; ``num_jac`` also
re-evaluates columns whose difference it finds too small). So the right-hand-side count here is
every call of ``fmi2GetDerivatives``, counted in the wrapper; Jacobian evaluations, LU
decompositions are scipy's ``njev`` and ``nlu``, summed over restarts; steps are accepted steps.

Events: the event indicators (a Bouc-Wen block's relative velocity and hysteretic force; the
friction element's velocity) are watched after every step; a sign change is located by bisection
on the step's dense output, the FMU gets ``fmi2EnterEventMode``/``fmi2NewDiscreteStates`` there
and the solver restarts (a restart costs a new Jacobian and LU in both variants). Berg's and the
fractional model's friction element reverses only at such an event, so they run with events. The
proposed model's event changes no state (it only restarts the integrator), so it also runs
"stepped through": no events, the solver steps across the switches of the non-smooth right-hand
side, the same for both Jacobians. Indicator and output evaluations are not right-hand sides and
are not counted.

Accuracy: F at 1 ms output times (the step's dense output, then ``fmi2GetReal(F)`` with the states
and inputs of that time) against a reference run of the same FMU (Radau, events, FMU Jacobian,
rtol 1e-12), the largest error over the peak |F|; for the proposed model the reference is also
compared with scipy's Radau on the paper's equations typed independently (``tests/conftest.py``
``paper_force``, rtol = atol = 1e-10). rtol 1e-6 and 1e-8, atol = rtol times each state's nominal.
"""
from __future__ import annotations

import argparse
import ctypes
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model
from scipy.integrate import BDF, Radau

REPO = Path(__file__).resolve().parents[1]

import build_fmu  # noqa: E402
from identification.measured.signals import Sine  # noqa: E402
import harness  # noqa: E402

SINE = Sine(2.0, 10.0, 1.0)                     # the paper's sine: 2 mm, 10 Hz, mm and s
SOLVERS = {"Radau": Radau, "BDF": BDF}
REFERENCE_RTOL = 1e-12
_DOUBLES = ctypes.POINTER(ctypes.c_double)


def sine_inputs(t: float) -> tuple[float, float]:
    """x [m], v [m/s] of the paper's sine at time t [s]."""
    x_mm, v_mm_s = SINE.signals(np.asarray(t, dtype=float))
    return float(x_mm) * 1e-3, float(v_mm_s) * 1e-3


@dataclass
class Counts:
    rhs: int = 0            # fmi2GetDerivatives calls: every right-hand side, differences included
    jacobians: int = 0      # scipy's njev (FMU Jacobians or num_jac calls)
    directional: int = 0    # fmi2GetDirectionalDerivative calls
    lu: int = 0
    steps: int = 0
    events: int = 0
    indicators: int = 0     # event-indicator evaluations (step ends and bisection), not right-hand sides


@dataclass
class Run:
    force_N: np.ndarray
    counts: Counts
    wall_s: float


class ModelExchange:
    """One native FMU (FMI 2.0) in continuous-time mode, driven through fmpy's low-level API, whose
    right-hand side, Jacobian, indicators and force are evaluated at (t, states) with the sine's
    inputs of that t. Units: s, m, m/s, N."""

    def __init__(self, fmu_path):
        d = read_model_description(str(fmu_path))
        self.refs = {v.name: v.valueReference for v in d.modelVariables}
        self.derivative_refs = [v.valueReference for v in d.modelVariables if v.derivative is not None]
        self.state_refs = [v.derivative.valueReference for v in d.modelVariables if v.derivative is not None]
        self.nominal = np.array([float(v.derivative.nominal or 1.0) for v in d.modelVariables
                                 if v.derivative is not None])
        self.n, self.nz = d.numberOfContinuousStates, d.numberOfEventIndicators
        self.fmu = FMU2Model(guid=d.guid, unzipDirectory=extract(str(fmu_path)),
                             modelIdentifier=d.modelExchange.modelIdentifier, instanceName="jacobian_bench")
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self._inputs(0.0)
        self.fmu.exitInitializationMode()
        self.fmu.enterContinuousTimeMode()
        self._dx = (ctypes.c_double * self.n)()
        self._z = (ctypes.c_double * max(self.nz, 1))()
        self._unknowns = (ctypes.c_uint * self.n)(*self.derivative_refs)      # fmi2ValueReference
        self._knowns = [(ctypes.c_uint * 1)(ref) for ref in self.state_refs]
        self._seed, self._column = (ctypes.c_double * 1)(1.0), (ctypes.c_double * self.n)()
        self.start = self._states()
        self.counts = Counts()

    def _inputs(self, t: float) -> None:
        self.fmu.setTime(t)
        self.fmu.setReal([self.refs["x"], self.refs["v"]], list(sine_inputs(t)))

    def _states(self) -> np.ndarray:
        x = np.zeros(self.n)
        self.fmu.getContinuousStates(x.ctypes.data_as(_DOUBLES), self.n)
        return x

    def _at(self, t: float, y) -> None:
        self._inputs(t)
        y = np.ascontiguousarray(y, dtype=float)
        self.fmu.setContinuousStates(y.ctypes.data_as(_DOUBLES), self.n)

    def rhs(self, t, y) -> np.ndarray:
        self.counts.rhs += 1
        self._at(t, y)
        self.fmu.getDerivatives(self._dx, self.n)
        return np.array(self._dx)

    def jacobian(self, t, y, _f=None) -> np.ndarray:
        """d der(states)/d states from fmi2GetDirectionalDerivative, column by column."""
        self._at(t, y)
        self.counts.directional += self.n
        jacobian = np.empty((self.n, self.n))
        for j in range(self.n):
            self._directional(j)
            jacobian[:, j] = self._column
        return jacobian

    def _directional(self, j: int) -> None:
        """Column j into self._column: fmi2GetDirectionalDerivative with arrays made once (fmpy's
        getDirectionalDerivative builds them at every call), as getDerivatives is called."""
        self.fmu.fmi2GetDirectionalDerivative(self.fmu.component, self._unknowns, self.n, self._knowns[j], 1,
                                              self._seed, self._column)

    def indicators(self, t, y) -> np.ndarray:
        self.counts.indicators += 1
        self._at(t, y)
        self.fmu.getEventIndicators(self._z, self.nz)
        return np.array(self._z[:self.nz])

    def force(self, t, y) -> float:
        self._at(t, y)
        return self.fmu.getReal([self.refs["F"]])[0]

    def event(self, t, y) -> np.ndarray:
        """The FMU's event at (t, y): event mode, discrete states until settled; the states after."""
        self._at(t, y)
        self.fmu.enterEventMode()
        while self.fmu.newDiscreteStates()[0]:
            pass
        self.fmu.enterContinuousTimeMode()
        return self._states()

    def free(self) -> None:
        self.fmu.terminate()
        self.fmu.freeInstance()


def _signs(values: np.ndarray, previous: np.ndarray | None = None) -> np.ndarray:
    """The indicators' signs, a zero keeping the previous sign (a zero is no crossing)."""
    signs = np.sign(values)
    if previous is not None:
        signs = np.where(signs == 0.0, previous, signs)
    return signs


def _crossing(model: ModelExchange, dense, t0: float, t1: float, i: int, before: float) -> float:
    """The first time in (t0, t1] at which indicator i has left the sign ``before``: the right end
    of a bisection bracket narrowed to 1e-13 s, where the new sign already holds."""
    a, b = t0, t1
    while b - a > 1e-13 * max(1.0, abs(b)):
        m = 0.5 * (a + b)
        if np.sign(model.indicators(m, dense(m))[i]) == before:
            a = m
        else:
            b = m
    return b


def integrate(model: ModelExchange, method: str, rtol: float, fmu_jacobian: bool, events: bool,
              times: np.ndarray) -> Run:
    """F at ``times`` from ``method`` with the FMU's Jacobian or scipy's differences."""
    model.counts = counts = Counts()
    atol = rtol * model.nominal
    t, y, t_end = float(times[0]), model.start.copy(), float(times[-1])
    forces = np.full(times.size, np.nan)
    forces[0] = model.force(t, y)
    k = 1
    signs = _signs(model.indicators(t, y)) if events else None
    started = time.perf_counter()
    while t < t_end:
        solver = SOLVERS[method](model.rhs, t, y, t_end, rtol=rtol, atol=atol,
                                 jac=model.jacobian if fmu_jacobian else None)
        restart = False
        while solver.status == "running" and not restart:
            solver.step()
            if solver.status == "failed":
                raise RuntimeError(f"{method} failed at t = {solver.t}")
            counts.steps += 1
            dense = solver.dense_output()
            t_step = solver.t
            if events:
                new = _signs(model.indicators(solver.t, solver.y), signs)
                crossed = np.flatnonzero((new != signs) & (signs != 0.0))
                if crossed.size:
                    t_step = min(_crossing(model, dense, solver.t_old, solver.t, i, signs[i]) for i in crossed)
                    restart = True
            while k < times.size and times[k] <= t_step:
                forces[k] = model.force(times[k], dense(times[k]))
                k += 1
            if restart:
                counts.events += 1
                y = model.event(t_step, dense(t_step))
                t = t_step
                signs = _signs(model.indicators(t, y), signs)
            else:
                t, y = solver.t, solver.y
                if events:
                    signs = new
        counts.jacobians += solver.njev
        counts.lu += solver.nlu
    wall = time.perf_counter() - started
    assert k == times.size and np.all(np.isfinite(forces))
    return Run(forces, counts, wall)


def paper_reference(times: np.ndarray) -> np.ndarray | None:
    """The proposed model with Table 5 from the paper's equations (tests/conftest.py), if importable."""
    try:
        sys.path.insert(0, str(REPO / "tests"))
        from conftest import paper_force, paper_parameters
    except ImportError:
        return None
    omega = 2.0 * np.pi * SINE.frequency_hz
    return paper_force(paper_parameters("table5"), times, lambda t: SINE.amplitude_mm * np.sin(omega * t),
                       lambda t: SINE.amplitude_mm * omega * np.cos(omega * t), rtol=1e-10, atol=1e-10)


def call_costs(model: ModelExchange, y: np.ndarray, repeats: int = 2000) -> tuple[float, float]:
    """µs per fmi2GetDerivatives and per fmi2GetDirectionalDerivative of one column (all state
    derivatives for one state), through fmpy's checked ctypes calls with arrays made once, the
    states and inputs set once before."""
    model._at(0.0123, y)
    started = time.perf_counter()
    for _ in range(repeats):
        model.fmu.getDerivatives(model._dx, model.n)
    rhs = (time.perf_counter() - started) / repeats
    started = time.perf_counter()
    for _ in range(repeats):
        model._directional(0)
    return rhs * 1e6, (time.perf_counter() - started) / repeats * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--models", default="proposed,berg,fractional")
    parser.add_argument("--duration", type=float, default=SINE.duration_s, help="s of the sine (default 1)")
    parser.add_argument("--rtols", default="1e-6,1e-8")
    args = parser.parse_args()
    times = np.arange(round(args.duration * 1000.0) + 1) / 1000.0
    rtols = [float(r) for r in args.rtols.split(",")]
    print(f"{harness.provenance()}\nmodel exchange on the sine {SINE.amplitude_mm:g} mm {SINE.frequency_hz:g} Hz, "
          f"{args.duration:g} s, native FMU (FMI 2.0), scipy Radau/BDF")
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name in args.models.split(","):
            path = build_fmu.build_native_fmu(out_dir=folder, model=name).path
            model = ModelExchange(path)
            reference = integrate(model, "Radau", REFERENCE_RTOL, True, True, times)
            peak = np.max(np.abs(reference.force_N))
            rhs_us, dd_us = call_costs(model, model.start + 0.1 * model.nominal)
            note = (f"{name}: {model.n} states, {model.nz} event indicators; reference (Radau, rtol "
                    f"{REFERENCE_RTOL:g}, FMU Jacobian, events): peak {peak:.1f} N, {reference.counts.events} "
                    f"events, {reference.counts.steps} steps; fmi2GetDerivatives {rhs_us:.1f} µs, "
                    f"fmi2GetDirectionalDerivative (one column) {dd_us:.1f} µs (through fmpy)")
            if name == "proposed":
                paper = paper_reference(times)
                if paper is not None:
                    apart = np.max(np.abs(reference.force_N - paper)) / peak
                    note += f"; reference against the paper's equations: {apart:.1e} of the peak"
            print(note)
            for events in ((False, True) if name == "proposed" else (True,)):
                for method in SOLVERS:
                    for rtol in rtols:
                        for fmu_jacobian in (True, False):
                            run = integrate(model, method, rtol, fmu_jacobian, events, times)
                            error = np.max(np.abs(run.force_N - reference.force_N)) / peak
                            c = run.counts
                            rows.append((name, "events" if events else "stepped through", method, f"{rtol:g}",
                                         "FMU" if fmu_jacobian else "differences", c.rhs, c.jacobians, c.lu,
                                         c.steps, c.events, f"{error:.1e}", f"{run.wall_s:.2f}"))
            model.free()
    header = ("model", "switches", "method", "rtol", "Jacobian", "RHS evaluations", "Jacobian evaluations",
              "LU decompositions", "steps", "events", "max error / peak F", "wall s")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for row in rows:
        print("| " + " | ".join(str(v) for v in row) + " |")


if __name__ == "__main__":
    main()
