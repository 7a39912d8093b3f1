"""A 30 kg body on the bushing inside Exudyn, a multibody engine (PyPI: exudyn), the bushing the
native FMU: the glue a user writes to host the FMU in an implicit integrator, checked against the
same system stepped by fmpy alone.

The body (a mass point, 30 kg, under gravity) sits on one bushing (the native FMU of the paper's
Table 5 along z, ground below), launched upwards at 0.2 m/s: it rings down onto its static
deflection. Exudyn integrates it with its generalized-alpha solver (spectral radius 1) at the step
h, its Newton iterations evaluating the bushing's force many times per step at trial positions and
velocities. The glue (``FmuBushing``) keeps the FMU's state at the step's start (fmi2GetFMUstate)
and answers each evaluation from it: restore the state, step the FMU from the start's x to the
trial x at the mean velocity over the step, read the force with the trial velocity; before each
step (Exudyn's pre-step function, called with the time the step goes to) it commits the accepted
end the same way. An evaluation at the step's start answers from the committed state at the
given inputs.

The reference: the body and the FMU stepped by fmpy alone, symplectic Euler at 2 us (the FMU
stepping at the body's velocity over each step, its force read at the step's end). The figure:
the largest force difference over the run (after t = 0, where the two start from different force
conventions), as a fraction of the peak force.

    python examples/cosim/exudyn_body.py [--step 1e-4] [--plot FILE.png]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

MASS_KG, GRAVITY_M_S2, LAUNCH_M_S, DURATION_S = 30.0, 9.81, 0.2, 0.3
REFERENCE_STEP_S = 2e-6
PARAMETERS = REPO / "data" / "params_table5_combined.json"


def open_slave(fmu_path: Path, name: str):
    """A started FMI 2 co-simulation instance of the FMU and its value references by name."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    description = read_model_description(str(fmu_path))
    slave = FMU2Slave(guid=description.guid, unzipDirectory=extract(str(fmu_path)),
                      modelIdentifier=description.coSimulation.modelIdentifier, instanceName=name)
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    return slave, {v.name: v.valueReference for v in description.modelVariables}


class FmuBushing:
    """The FMU as an implicit integrator's force (module docstring): x [m], v [m/s] -> F [N]."""

    def __init__(self, fmu_path: Path):
        self.fmu, self.ref = open_slave(fmu_path, "exudyn")
        self.t0, self.x0 = 0.0, 0.0
        self.state = self.fmu.getFMUstate()
        self.evaluations = 0

    def force(self, t: float, x: float, v: float) -> float:
        self.evaluations += 1
        self.fmu.setFMUstate(self.state)
        if t > self.t0 + 1e-12:          # a trial end of the step: the path to x from the start's
            h = t - self.t0
            self.fmu.setReal([self.ref["x"], self.ref["v"]], [self.x0, (x - self.x0) / h])
            self.fmu.doStep(self.t0, h)
            self.fmu.setReal([self.ref["v"]], [v])
        else:                            # the step's start: the committed state at the given inputs
            self.fmu.setReal([self.ref["x"], self.ref["v"]], [x, v])
        return self.fmu.getReal([self.ref["F"]])[0]

    def commit(self, t: float, x: float, v: float) -> float:
        """The accepted state at time t (x, v): the FMU's state there, kept; its force [N]."""
        force = self.force(t, x, v)
        if t > self.t0 + 1e-12:
            self.state = self.fmu.getFMUstate()
            self.t0, self.x0 = t, x
        return force

    def close(self):
        self.fmu.freeFMUstate(self.state)
        self.fmu.terminate()
        self.fmu.freeInstance()


@dataclass
class Run:
    time_s: np.ndarray
    displacement_m: np.ndarray
    force_N: np.ndarray
    wall_s: float
    evaluations: int = 0


def run_exudyn(fmu_path: Path, step_s: float) -> Run:
    """The body on the bushing in Exudyn at ``step_s`` (module docstring)."""
    import exudyn as exu
    from exudyn.itemInterface import (CoordinateSpringDamper, Force, MarkerBodyPosition, MarkerNodeCoordinate,
                                      MassPoint, NodePoint, NodePointGround)
    container = exu.SystemContainer()
    mbs = container.AddSystem()
    node = mbs.AddNode(NodePoint(referenceCoordinates=[0, 0, 0], initialVelocities=[0, 0, LAUNCH_M_S]))
    body = mbs.AddObject(MassPoint(mass=MASS_KG, nodeNumber=node))
    ground_z = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=2))
    body_z = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=2))
    bushing = FmuBushing(fmu_path)
    mbs.AddObject(CoordinateSpringDamper(
        markerNumbers=[ground_z, body_z],
        springForceUserFunction=lambda mbs, t, item, u, v, k, d, offset: bushing.force(t, u, v)))
    mbs.AddLoad(Force(markerNumber=mbs.AddMarker(MarkerBodyPosition(bodyNumber=body, localPosition=[0, 0, 0])),
                      loadVector=[0, 0, -MASS_KG * GRAVITY_M_S2]))
    record = []

    def before_step(mbs, t):
        start = t - step_s           # Exudyn passes the time the step goes to; the state is its start's
        z = mbs.GetNodeOutput(node, exu.OutputVariableType.Position)[2]
        w = mbs.GetNodeOutput(node, exu.OutputVariableType.Velocity)[2]
        record.append((start, z, bushing.commit(start, z, w)))
        return True
    mbs.SetPreStepUserFunction(before_step)
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps = int(round(DURATION_S / step_s))
    settings.timeIntegration.endTime = DURATION_S
    settings.timeIntegration.verboseMode = 0
    settings.timeIntegration.newton.useModifiedNewton = False
    settings.timeIntegration.generalizedAlpha.spectralRadius = 1.0
    settings.solution.file.write = False
    start = time.perf_counter()
    mbs.SolveDynamic(settings)
    wall = time.perf_counter() - start
    evaluations = bushing.evaluations
    bushing.close()
    t, z, f = np.array(record).T
    return Run(t, z, f, wall, evaluations)


def run_reference(fmu_path: Path, step_s: float = REFERENCE_STEP_S) -> Run:
    """The same system stepped by fmpy alone (module docstring)."""
    slave, ref = open_slave(fmu_path, "reference")
    n = int(round(DURATION_S / step_s))
    t, z_out, f_out = np.arange(n) * step_s, np.empty(n), np.empty(n)
    z, w = 0.0, LAUNCH_M_S
    start = time.perf_counter()
    for k in range(n):
        force = slave.getReal([ref["F"]])[0]
        z_out[k], f_out[k] = z, force
        w = w + step_s * (-force - MASS_KG * GRAVITY_M_S2) / MASS_KG
        slave.setReal([ref["x"], ref["v"]], [z, w])
        slave.doStep(k * step_s, step_s)
        z = z + step_s * w
    wall = time.perf_counter() - start
    slave.terminate()
    slave.freeInstance()
    return Run(t, z_out, f_out, wall)


def compare(exudyn_run: Run, reference: Run, reference_step_s: float = REFERENCE_STEP_S) -> float:
    """The largest force difference after t = 0 over the reference's peak force."""
    index = np.round(exudyn_run.time_s / reference_step_s).astype(int)
    keep = (index > 0) & (index < reference.time_s.size)
    difference = np.abs(exudyn_run.force_N[keep] - reference.force_N[index[keep]])
    return float(np.max(difference) / np.max(np.abs(reference.force_N)))


def build_fmu(folder: Path) -> Path:
    import build_fmu as builder
    return builder.build_native_fmu(PARAMETERS, folder, model="proposed", fmi_version=2).path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--step", type=float, default=1e-4, help="Exudyn's step [s] (default 1e-4)")
    parser.add_argument("--plot", type=Path, help="write the forces and the difference to this PNG")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        fmu = build_fmu(Path(folder))
        body = run_exudyn(fmu, args.step)
        reference = run_reference(fmu)
    error = compare(body, reference)
    steps = body.time_s.size
    print(f"Exudyn, generalized-alpha at {args.step:g} s: {steps} steps in {body.wall_s:.2f} s "
          f"({1e6 * body.wall_s / steps:.0f} us a step, {body.evaluations / steps:.1f} force evaluations a step)")
    print(f"fmpy alone, symplectic Euler at {REFERENCE_STEP_S:g} s: {reference.wall_s:.1f} s")
    print(f"largest force difference: {100 * error:.3f} % of the peak force ({np.max(np.abs(reference.force_N)):.0f} N); "
          f"at rest {body.force_N[-1]:.2f} N (the weight {MASS_KG * GRAVITY_M_S2:.2f} N)")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        figure, axes = plt.subplots(figsize=(8, 4))
        axes.plot(reference.time_s, reference.force_N, "k-", lw=1, label="fmpy alone, 2 us")
        axes.plot(body.time_s, body.force_N, "C1--", lw=1, label=f"Exudyn, {args.step:g} s")
        axes.set(xlabel="time [s]", ylabel="bushing force F [N]",
                 title=f"30 kg on the bushing (Table 5) in Exudyn: largest difference {100 * error:.3f} % of the peak")
        axes.grid(alpha=0.3)
        axes.legend()
        figure.tight_layout()
        figure.savefig(args.plot, dpi=90)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
