"""A light body on the bushing, coupled explicitly and linearly implicitly: what a host gains from
the native FMU's directional derivatives.

A body of mass m [kg] rests on one bushing (the native FMU, the paper's Table 5 by default), is
released from x0 = 1 mm with v = 0 and rings down; m*dv/dt = -F(x, v), x in m, F in N. A small
fmpy master couples the two at a fixed communication step h:

- explicit: at t_n the body's x_n, v_n go to the bushing, its force F_n comes back and is held over
  the step (the body moves under the constant force -F_n; the bushing steps with x_n, v_n, so the
  next step starts with the jump -h^2*F_n/(2m) that the dashpots carry);
- explicit with the secant velocity: the same, but the bushing steps with the body's secant
  velocity (x_n+1 - x_n)/h, so that it ends where the body does (no jumps);
- linearly implicit: as above, but the body's step uses the force linearised at the
  communication point, F_n + K*(x_n+1 - x_n) + C*(v_n+1 - v_n), with K = dF/dx and C = dF/dv from
  fmi2GetDirectionalDerivative (the correction PyFMI's master and OMSimulator's strongly coupled
  systems make); the body's step is then implicit Euler, first order, and the bushing steps from
  x_n with the secant velocity (x_n+1 - x_n)/h.

The reference is the explicit coupling at 0.01 ms. The deviation of a run is the largest |x - x_ref|
over the run at the 1 ms points, as a fraction of x0.

    python examples/cosim/implicit_coupling.py [--masses 0.3 1 3 10] [--step 1e-3] [--plot FILE.png]
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

X0_M = 1e-3
DURATION_S = 0.3
REFERENCE_STEP_S = 1e-5


@dataclass
class Run:
    """One coupled run: the body's displacement x [m] at times t [s]; ``refused_at``: the time [s]
    at which the bushing FMU refused a step (the coupling diverged), else None."""
    t: np.ndarray
    x: np.ndarray
    refused_at: float | None


class Bushing:
    """One co-simulation instance of a native bushing FMU (FMI 2.0) through fmpy."""

    def __init__(self, fmu_path: str, start_values: dict | None = None):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave
        description = read_model_description(fmu_path)
        if description.coSimulation is None or not description.coSimulation.providesDirectionalDerivative:
            raise ValueError(f"{fmu_path} provides no directional derivatives in co-simulation: build it with "
                             "build_fmu.py --native")
        self.refs = {v.name: v.valueReference for v in description.modelVariables}
        self.fmu = FMU2Slave(guid=description.guid, unzipDirectory=extract(fmu_path),
                             modelIdentifier=description.coSimulation.modelIdentifier, instanceName="bushing")
        from fmpy.fmi2 import (calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                               fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free)
        self.messages: list[str] = []     # kept, not printed: a diverging coupling warns at every step
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(lambda c, name, status, category, message:
                                                       self.messages.append(message.decode()))
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self.fmu.instantiate(callbacks=self.callbacks, loggingOn=True)
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        for name, value in (start_values or {}).items():
            self.fmu.setReal([self.refs[name]], [value])

    def start(self, x_m: float) -> None:
        self.fmu.setReal([self.refs["x"], self.refs["v"]], [x_m, 0.0])
        self.fmu.exitInitializationMode()

    def force(self, x_m: float, v_m_s: float) -> float:
        self.fmu.setReal([self.refs["x"], self.refs["v"]], [x_m, v_m_s])
        return self.fmu.getReal([self.refs["F"]])[0]

    def stiffness_and_damping(self) -> tuple[float, float]:
        """(dF/dx [N/m], dF/dv [N.s/m]) at the inputs set, of the output the FMU returns there."""
        force = [self.refs["F"]]
        return (self.fmu.getDirectionalDerivative(force, [self.refs["x"]], [1.0])[0],
                self.fmu.getDirectionalDerivative(force, [self.refs["v"]], [1.0])[0])

    def step(self, t: float, h: float) -> bool:
        from fmpy.fmi1 import FMICallException
        try:
            self.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        except FMICallException:
            return False
        return True

    def free(self) -> None:
        self.fmu.terminate()
        self.fmu.freeInstance()


SCHEMES = ("explicit", "explicit_secant", "implicit")


def couple(fmu_path: str, mass_kg: float, h: float, scheme: str, duration_s: float = DURATION_S,
           start_values: dict | None = None) -> Run:
    """The body of ``mass_kg`` on the bushing, released from X0_M, coupled at step ``h`` [s] by
    ``scheme`` (one of SCHEMES, the module docstring)."""
    if not (mass_kg > 0.0 and h > 0.0):
        raise ValueError(f"mass {mass_kg} kg and step {h} s must be > 0")
    if scheme not in SCHEMES:
        raise ValueError(f"scheme {scheme!r} is not one of {', '.join(SCHEMES)}")
    bushing = Bushing(fmu_path, start_values)
    bushing.start(X0_M)
    steps = int(round(duration_s / h))
    t, x = np.arange(steps + 1) * h, np.full(steps + 1, np.nan)
    position, velocity, refused_at = X0_M, 0.0, None
    x[0] = position
    for n in range(steps):
        force = bushing.force(position, velocity)
        if scheme == "implicit":
            stiffness, damping = bushing.stiffness_and_damping()
            # m*(v1 - v0)/h = -(F + K*h*v1 + C*(v1 - v0)), x1 = x0 + h*v1 (implicit Euler)
            change = -(force + stiffness * h * velocity) / (mass_kg / h + stiffness * h + damping)
            new_velocity = velocity + change
            new_position = position + h * new_velocity
            bushing.force(position, new_velocity)       # the bushing moves on the body's secant over the step
        else:
            new_velocity = velocity - h * force / mass_kg
            new_position = position + h * velocity - 0.5 * h * h * force / mass_kg
            if scheme == "explicit_secant":
                bushing.force(position, (new_position - position) / h)
        if not bushing.step(n * h, h) or not np.isfinite(new_position):
            refused_at = n * h
            break
        position, velocity = new_position, new_velocity
        x[n + 1] = position
    bushing.free()
    return Run(t, x, refused_at)


def deviation(run: Run, reference: Run) -> float:
    """Largest |x - x_ref| over the run at its own points, as a fraction of X0_M (inf if it diverged)."""
    if run.refused_at is not None or not np.all(np.isfinite(run.x)):
        return float("inf")
    stride = int(round((run.t[1] - run.t[0]) / (reference.t[1] - reference.t[0])))
    return float(np.max(np.abs(run.x - reference.x[::stride][:run.x.size])) / X0_M)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--masses", type=float, nargs="+", default=[0.3, 1.0, 3.0, 10.0], help="body masses [kg]")
    parser.add_argument("--step", type=float, default=1e-3, help="communication step [s] (default 1e-3)")
    parser.add_argument("--fmu", help="a native bushing FMU (default: build the proposed model's, Table 5)")
    parser.add_argument("--plot", help="write the 1 kg (or first) body's motion to this PNG")
    args = parser.parse_args(argv)
    fmu_path = args.fmu
    if fmu_path is None:
        import tempfile

        import build_fmu
        fmu_path = str(build_fmu.build_native_fmu(out_dir=tempfile.mkdtemp(prefix="implicit_coupling_")).path)
    print(f"body released from {X0_M * 1e3:g} mm on {Path(fmu_path).name}, {DURATION_S} s, communication step "
          f"{args.step * 1e3:g} ms, reference: explicit at {REFERENCE_STEP_S * 1e3:g} ms")
    print(f"{'mass [kg]':>10} {'explicit':>30} {'explicit, secant v':>30} {'linearly implicit':>18}   "
          "(largest |x - x_ref| / x0)")
    runs = {}
    for mass in args.masses:
        reference = couple(fmu_path, mass, REFERENCE_STEP_S, "explicit")
        explicit, secant, implicit = (couple(fmu_path, mass, args.step, scheme) for scheme in SCHEMES)
        runs[mass] = (reference, explicit, implicit)

        def text(run):
            return f"diverged (refused at {run.refused_at:.3f} s)" if run.refused_at is not None \
                else f"{deviation(run, reference):.3f}"
        print(f"{mass:>10g} {text(explicit):>30} {text(secant):>30} {text(implicit):>18}")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        mass = 1.0 if 1.0 in runs else args.masses[0]
        reference, explicit, implicit = runs[mass]
        figure, axis = plt.subplots(figsize=(7, 3.6))
        axis.plot(reference.t * 1e3, reference.x * 1e3, "k-", lw=1.0, label=f"reference ({REFERENCE_STEP_S * 1e3:g} ms)")
        axis.plot(explicit.t * 1e3, explicit.x * 1e3, "C3.-", ms=3, lw=0.6, label=f"explicit ({args.step * 1e3:g} ms)")
        axis.plot(implicit.t * 1e3, implicit.x * 1e3, "C0o-", ms=3, lw=0.6,
                  label=f"linearly implicit ({args.step * 1e3:g} ms)")
        axis.set(xlabel="t [ms]", ylabel="x [mm]", title=f"{mass:g} kg body on the bushing (Table 5)",
                 ylim=(-1.5 * X0_M * 1e3, 1.5 * X0_M * 1e3), xlim=(0, 30))
        axis.legend()
        axis.grid(alpha=0.3)
        figure.tight_layout()
        figure.savefig(args.plot, dpi=120)
        print(f"wrote {args.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
