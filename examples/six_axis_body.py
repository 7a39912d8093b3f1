"""A rigid body hung on the six-axis bushing from the ground, driven through fmpy: how a multibody
code applies SixAxisBushing's outputs, and a figure of the convention.

    python examples/six_axis_body.py [--fmu SixAxisBushing.fmu] [--out DIR]

Marker J is the ground frame at the origin; marker I is the body's centre of mass. Each
communication step (1 ms) the master
1. sends the pose of I relative to J in J's axes: d = (dx, dy, dz) [m] and the rotation vector
   (rx, ry, rz) [rad] of the body's orientation, and the velocities (vx, vy, vz) [m/s] and
   (wx, wy, wz) [rad/s];
2. steps the FMU and reads F = (Fx, Fy, Fz) [N] and M = (Mx, My, Mz) [N.m];
3. applies the convention: the body (I) receives -F at I's origin and the moment -M; the ground
   (J) receives F and, about J's origin, M + d x F;
4. advances the body by one step (semi-implicit Euler; rotation kept exact with scipy's Rotation).
The body (30 kg) starts at J with a kick in every direction, under gravity along -z; its
translations settle to the static sag within the 2 s (the torsional axis, Kelvin-Voigt with a
loss factor of 0.05 at 10 Hz, still rings). At the end the script prints the loads both ways:
on the body -F + m*g (zero once the translation has settled) and -M, on the ground F and
M + d x F about J's origin.

Writes ``six_axis_convention.png`` (the convention) and ``six_axis_body.png`` (the six outputs).
Units: SI throughout (the FMU's ports).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

MASS_KG = 30.0
INERTIA_KG_M2 = np.diag([0.5, 0.5, 0.8])
GRAVITY = np.array([0.0, 0.0, -9.81])
STEP_S = 1e-3
DURATION_S = 2.0
TRANSLATIONS, ROTATIONS = ("dx", "dy", "dz"), ("rx", "ry", "rz")
VELOCITIES, ANGULAR = ("vx", "vy", "vz"), ("wx", "wy", "wz")
FORCES, MOMENTS = ("Fx", "Fy", "Fz"), ("Mx", "My", "Mz")


def convention_figure(path: Path) -> Path:
    """Markers J (on body J) and I (on body I), d, and what each body receives."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import FancyBboxPatch
    fig, ax = plt.subplots(figsize=(7.0, 4.2))
    ax.add_patch(FancyBboxPatch((-0.4, -0.5), 2.0, 0.55, boxstyle="round,pad=0.05", fc="#dfe7f2", ec="#4a6fa5"))
    ax.add_patch(FancyBboxPatch((2.3, 1.2), 2.0, 0.9, boxstyle="round,pad=0.05", fc="#f2e3d5", ec="#b5651d"))
    ax.text(0.6, -0.35, "body J", ha="center", color="#4a6fa5")
    ax.text(3.3, 1.95, "body I", ha="center", color="#b5651d")
    J, I = np.array([0.6, -0.05]), np.array([3.0, 1.5])
    for origin, name, colour in ((J, "J", "#4a6fa5"), (I, "I", "#b5651d")):
        ax.annotate("", origin + [0.45, 0.0], origin, arrowprops=dict(arrowstyle="->", color=colour))
        ax.annotate("", origin + [0.0, 0.45], origin, arrowprops=dict(arrowstyle="->", color=colour))
        ax.plot(*origin, "o", color=colour)
        ax.text(*(origin + [-0.15, -0.2]), name, color=colour, fontsize=12)
    ax.annotate("", I, J, arrowprops=dict(arrowstyle="->", ls="--", color="0.3"))
    ax.text(2.05, 0.45, "d = (dx, dy, dz)\nI relative to J, in J's axes", color="0.3", fontsize=9, ha="left")
    unit = (I - J) / np.linalg.norm(I - J)      # a spring: F along +d for a positive displacement
    ax.annotate("", I - 0.8 * unit, I, arrowprops=dict(arrowstyle="-|>", color="k", lw=2))
    ax.text(*(I - 0.8 * unit + [0.1, -0.3]), "body I receives -F at I, and -M", fontsize=10)
    ax.annotate("", J + 0.8 * unit, J, arrowprops=dict(arrowstyle="-|>", color="k", lw=2))
    ax.text(*(J + [-1.1, 0.75]), "body J receives F,\nand M + d x F about J", fontsize=10)
    ax.text(-0.5, 2.35, "SixAxisBushing: inputs d, rotation vector (rx, ry, rz), their rates; outputs F [N], M [N.m],\n"
                        "each positive for a positive displacement of its axis (a spring: F = k d)", fontsize=9)
    ax.set_xlim(-1.2, 4.8)
    ax.set_ylim(-0.8, 2.7)
    ax.set_aspect("equal")
    ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def run(fmu_path: Path):
    """The body on the bushing: returns times, the outputs (N, N.m) and the final state."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    description = read_model_description(fmu_path)
    refs = {v.name: v.valueReference for v in description.modelVariables}
    fmu = FMU2Slave(guid=description.guid, unzipDirectory=extract(fmu_path),
                    modelIdentifier=description.coSimulation.modelIdentifier, instanceName="bushing")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()      # all inputs 0: the body starts at J, unloaded
    position, velocity = np.zeros(3), np.array([0.05, -0.03, 0.0])            # m, m/s
    orientation, angular_velocity = Rotation.identity(), np.array([0.5, -0.3, 1.0])   # rad/s, J's axes
    inputs = [refs[n] for n in TRANSLATIONS + ROTATIONS + VELOCITIES + ANGULAR]
    outputs = [refs[n] for n in FORCES + MOMENTS]
    times, history = [], []
    for k in range(int(round(DURATION_S / STEP_S))):
        rotation_vector = orientation.as_rotvec()
        fmu.setReal(inputs, [*position, *rotation_vector, *velocity, *angular_velocity])
        fmu.doStep(currentCommunicationPoint=k * STEP_S, communicationStepSize=STEP_S)
        values = np.array(fmu.getReal(outputs))
        force, moment = values[:3], values[3:]
        # the body receives -F at its origin (its centre of mass) and -M
        acceleration = (-force + MASS_KG * GRAVITY) / MASS_KG
        inertia_world = orientation.as_matrix() @ INERTIA_KG_M2 @ orientation.as_matrix().T
        gyroscopic = np.cross(angular_velocity, inertia_world @ angular_velocity)
        angular_acceleration = np.linalg.solve(inertia_world, -moment - gyroscopic)
        velocity = velocity + STEP_S * acceleration
        angular_velocity = angular_velocity + STEP_S * angular_acceleration
        position = position + STEP_S * velocity
        orientation = Rotation.from_rotvec(STEP_S * angular_velocity) * orientation
        times.append((k + 1) * STEP_S)
        history.append(values)
    fmu.terminate()
    fmu.freeInstance()
    return np.array(times), np.array(history), position, orientation.as_rotvec(), velocity, angular_velocity


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", type=Path, help="SixAxisBushing.fmu (default: build one with the illustrative set)")
    parser.add_argument("--out", type=Path, default=REPO / "out" / "six_axis_body")
    args = parser.parse_args()
    from identification.extras import require_or_exit
    require_or_exit("plot", "examples/six_axis_body.py")
    args.out.mkdir(parents=True, exist_ok=True)
    fmu_path = args.fmu
    if fmu_path is None:
        import build_fmu
        fmu_path = build_fmu.build_fmu(out_dir=args.out / "dist", model="six_axis")
    convention_figure(args.out / "six_axis_convention.png")
    times, history, d, rotation_vector, velocity, angular_velocity = run(fmu_path)
    force, moment = history[-1, :3], history[-1, 3:]
    print(f"after {times[-1]:.1f} s: d = {np.round(d * 1e3, 4)} mm, rotation = {np.round(rotation_vector, 6)} rad")
    print(f"  F = {np.round(force, 2)} N, M = {np.round(moment, 4)} N.m")
    print(f"  body I: -F + m*g = {np.round(-force + MASS_KG * GRAVITY, 3)} N (settled: 0), -M = {np.round(-moment, 4)} "
          "N.m (the torsion still rings)")
    print(f"  ground J: force F = {np.round(force, 2)} N, moment about J's origin M + d x F = "
          f"{np.round(moment + np.cross(d, force), 4)} N.m")
    print(f"  weight m*g = {MASS_KG * 9.81:.2f} N carried by Fz = {force[2]:.2f} N")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
    for i, name in enumerate(FORCES):
        axes[0].plot(times, history[:, i], label=name)
    for i, name in enumerate(MOMENTS):
        axes[1].plot(times, history[:, 3 + i], label=name)
    axes[0].set_ylabel("force [N]")
    axes[1].set_ylabel("moment [N.m]")
    axes[1].set_xlabel("time [s]")
    for a in axes:
        a.legend(ncol=3, fontsize=8)
        a.grid(alpha=0.3)
    fig.suptitle("30 kg body on SixAxisBushing (illustrative set), kicked in every direction")
    fig.tight_layout()
    fig.savefig(args.out / "six_axis_body.png", dpi=110)
    print(f"wrote {args.out / 'six_axis_convention.png'} and {args.out / 'six_axis_body.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
