"""Does a bushing fitted along one axis predict combined loading? Coupled against uncoupled (issue targets)

    python benchmarks/bench_coupled_prediction.py [--model single_bouc_wen] [--seed 0] [--training x|plane]

The truth is a coupled single Bouc-Wen element in the plane with parameters of its own (TRUTH),
solved by the equations typed independently in tests/references/generate_coupled_references.py
(scipy's Radau on every straight piece between samples). From it, two sines along x alone, solved on
pieces of 0.1 ms and sampled at 1 ms with 3 N of seeded force noise: 2 mm at 10 Hz and 0.7 mm at
4 Hz, 1 s each (SYNTHETIC, written to a temporary folder). ``fit`` fits the model to them (default
preset). With ``--training plane`` it fits the first sine and a multi-axis test instead, an ellipse
of 1.5 x 1 mm at 7.3 Hz in the plane solved the same way, with the radial coupling
(``fit(..., multiaxis=..., coupling="radial")``). The fitted set goes on x and y
of two six-axis pythonfmu FMUs, one with the radial coupling and one without (z and the rotations
rigid), and both run, through fmpy, paths in the plane that no fit saw: a line along x (the
control), circles of 1 and 2.5 mm, an ellipse, a figure eight and a random path. Prints the NRMSE
of the force vector against the noise-free truth, rms|F - F_true|/rms|F_true|, for both FMUs (target
for the coupled one: <= 3 % on every plane path), and the energy the last cycle of each circle
dissipates against the truth's.
"""
from __future__ import annotations

import argparse
import importlib.util
import math
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

import build_fmu  # noqa: E402
from fmu_src.fmi.axes import SIX_AXES  # noqa: E402
from fmu_src.parameter_files import save_six_axis  # noqa: E402
from identification import fit, training_tests  # noqa: E402
from identification.measured.measurements import write_measurement  # noqa: E402
from identification.measured.multiaxis import write_multiaxis  # noqa: E402
import harness  # noqa: E402

_spec = importlib.util.spec_from_file_location("coupled_references",
                                               REPO / "tests" / "references" / "generate_coupled_references.py")
references = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(references)      # numpy and scipy only: the independent equations

STEP_S = 1e-3
NOISE_N = 3.0
TRUTH = {"c0": 0.6, "k0": 300.0, "alpha": 1.0, "A": 900.0, "beta": 0.045, "gamma": 0.016, "n": 1.5}
"""The truth's own single Bouc-Wen set (N-mm-s): z saturates near (A/(beta + gamma))^(1/n) = 600 N,
reached after about 1 mm of travel; k0 and c0 carry the rest."""
TRAINING = (("sine_2mm_10Hz", 2.0, 10.0), ("sine_0.7mm_4Hz", 0.7, 4.0))
PLANE_TRAINING = (1.5, 1.0, 7.3)
"""--training plane: the ellipse's half axes along x and y [mm] and its frequency [Hz]."""
RIGID = ("kelvin_voigt", {"k": 1e7, "c": 0.0, "preload": 0.0})


def paths(t: np.ndarray) -> dict[str, np.ndarray]:
    """The unseen paths [mm], (samples, 2), each from rest at the origin."""
    w = 2 * math.pi * 4.7
    rng = np.random.default_rng(11)
    frequencies, phases = rng.uniform(0.5, 12.0, (10, 2)), rng.uniform(0, 2 * math.pi, (10, 2))
    amplitudes = rng.normal(size=(10, 2)) / frequencies
    walk = np.stack([np.sum(amplitudes[:, j, None] * (np.sin(2 * math.pi * frequencies[:, j, None] * t
                                                              + phases[:, j, None]) - np.sin(phases[:, j, None])),
                            axis=0) for j in range(2)], axis=1)
    return {
        "line along x (control)": np.stack([2.0 * np.sin(w * t), 0 * t], axis=1),
        "circle 1 mm": np.stack([np.cos(w * t) - 1.0, np.sin(w * t)], axis=1),
        "circle 2.5 mm": 2.5 * np.stack([np.cos(w * t) - 1.0, np.sin(w * t)], axis=1),
        "ellipse 2 x 0.8 mm": np.stack([2.0 * np.sin(w * t), 0.8 * (1.0 - np.cos(w * t))], axis=1),
        "figure eight 2 mm": np.stack([2.0 * np.sin(w * t), 1.0 * np.sin(2 * w * t)], axis=1),
        "random, peak 2.5 mm": 2.5 * walk / np.max(np.hypot(walk[:, 0], walk[:, 1])),
    }


def truth(t: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """The truth's force vectors at every sample after the first [N]."""
    return references.solve_path(references.SingleBoucWen(TRUTH), t, xy, STEP_S)[1:, 3:5]


def run_fmu(fmu: Path, t: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """The FMU's (Fx, Fy) after every step, the ports fed with the path and its secant velocity."""
    from fmpy import simulate_fmu
    names = [name for axis in SIX_AXES for name in (axis.displacement, axis.velocity)]
    signals = np.zeros(len(t), dtype=[("time", float)] + [(name, float) for name in names])
    signals["time"] = t
    velocity = np.vstack([np.diff(xy, axis=0) / STEP_S, np.zeros((1, 2))])
    signals["dx"], signals["dy"] = xy[:, 0] * 1e-3, xy[:, 1] * 1e-3
    signals["vx"], signals["vy"] = velocity[:, 0] * 1e-3, velocity[:, 1] * 1e-3
    result = simulate_fmu(str(fmu), stop_time=t[-1], step_size=STEP_S, output_interval=STEP_S, input=signals,
                          output=["Fx", "Fy"])
    return np.column_stack([result["Fx"][1:], result["Fy"][1:]])


def vector_nrmse(predicted: np.ndarray, expected: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum((predicted - expected) ** 2, axis=1)) / np.mean(np.sum(expected ** 2, axis=1))))


def last_cycle_energy(xy: np.ndarray, forces: np.ndarray, period_samples: int) -> float:
    """The work done on the bushing over the last cycle [N.mm = mJ]: the integral of F.dx."""
    dx = np.diff(xy[-period_samples - 1:], axis=0)
    f = forces[-period_samples - 1:]
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * dx))


def plot_circle(path: Path, xy: np.ndarray, expected: np.ndarray, predicted: dict, period: int) -> None:
    """The last cycle of the circle: the path, and the force vector at 24 points of it, of the truth,
    the coupled and the uncoupled FMU (arrows from the point on the path)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    last = slice(len(xy) - period, len(xy), max(1, period // 24))
    scale = 1.2 / np.max(np.hypot(*expected[last].T))         # mm of arrow per N
    figure, axes = plt.subplots(figsize=(6.4, 6.0))
    axes.plot(xy[-period:, 0], xy[-period:, 1], color="0.6", lw=1, label="path (2.5 mm circle, 4.7 Hz)")
    for forces, colour, label, width in ((expected, "k", "truth (reference equations)", 0.006),
                                         (predicted["radial"], "C0", "coupled FMU (radial)", 0.004),
                                         (predicted["none"], "C3", "uncoupled FMU", 0.004)):
        axes.quiver(xy[last, 0], xy[last, 1], forces[last, 0] * scale, forces[last, 1] * scale, color=colour,
                    angles="xy", scale_units="xy", scale=1.0, width=width, label=label)
    tips = np.vstack([xy[last] + forces[last] * scale for forces in (expected, *predicted.values())] + [xy[-period:]])
    margin = 0.3
    axes.set_xlim(tips[:, 0].min() - margin, tips[:, 0].max() + margin)
    axes.set_ylim(tips[:, 1].min() - margin, tips[:, 1].max() + margin + 1.2)
    axes.set_aspect("equal")
    axes.set_xlabel("x [mm]")
    axes.set_ylabel("y [mm]")
    axes.set_title(f"Force vectors along a circle ({1 / scale:.0f} N per mm of arrow); fitted along x alone",
                   fontsize=10)
    axes.legend(loc="upper right", fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    print(f"wrote {path}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="single_bouc_wen", help="the model fitted along x (default single_bouc_wen)")
    parser.add_argument("--seed", type=int, default=0, help="the fit's seed and the noise's")
    parser.add_argument("--plot", type=Path, help="also draw the 2.5 mm circle's force vectors (PNG)")
    parser.add_argument("--training", choices=("x", "plane"), default="x",
                        help="x: two sines along x (default); plane: the first sine and an ellipse in the plane, "
                             "fitted with the radial coupling")
    args = parser.parse_args()
    started = time.perf_counter()
    rng = np.random.default_rng(args.seed)
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        files = []
        # the rig's paths are smooth: the truth runs them on pieces of a tenth of a sample
        fine = np.arange(round(10.0 / STEP_S) + 1) * STEP_S / 10
        t = fine[::10]
        for name, amplitude, frequency in TRAINING[:1] if args.training == "plane" else TRAINING:
            x_fine = amplitude * np.sin(2 * math.pi * frequency * fine)
            force = references.solve_path(references.SingleBoucWen(TRUTH), fine, np.column_stack([x_fine, 0 * fine]),
                                          STEP_S / 10)[::10, 3]
            force[0] = TRUTH["c0"] * amplitude * 2 * math.pi * frequency    # at rest, moving: the dashpot's force
            x = x_fine[::10]
            path = scratch / f"synthetic_coupled_truth_{name}.csv"
            write_measurement(path, t, x, force + NOISE_N * rng.standard_normal(t.size),
                              [f"SYNTHETIC: the coupled single Bouc-Wen truth {TRUTH} along x, {NOISE_N} N noise",
                               "made by benchmarks/bench_coupled_prediction.py"])
            files.append(path)
        multiaxis = []
        if args.training == "plane":
            a, b, frequency = PLANE_TRAINING
            w = 2 * math.pi * frequency
            xy_fine = np.stack([a * np.sin(w * fine), b * (1.0 - np.cos(w * fine))], axis=1)
            forces = references.solve_path(references.SingleBoucWen(TRUTH), fine, xy_fine, STEP_S / 10)[::10, 3:5]
            forces[0] = (TRUTH["c0"] * a * w, 0.0)        # at rest, moving along x: the dashpot's force
            multiaxis.append(write_multiaxis(
                scratch / "synthetic_coupled_truth_ellipse.csv", t, xy_fine[::10],
                forces + NOISE_N * rng.standard_normal(forces.shape),
                [f"SYNTHETIC: the coupled single Bouc-Wen truth {TRUTH} on an ellipse, {NOISE_N} N noise",
                 "made by benchmarks/bench_coupled_prediction.py"]))
        result = fit(training_tests(sine=files), model=args.model, seed=args.seed, progress=False,
                     multiaxis=multiaxis, coupling="radial" if multiaxis else None)
        print(result.summary().splitlines()[0])
        print("training: " + ", ".join(f"{f.name} {f.ratio:.2f}x its noise" for f in result.tests)
              + f"; converged: {result.converged}")
        fmus = {}
        for coupling in ("none", "radial"):
            axes = {axis.name: RIGID for axis in SIX_AXES}
            axes["x"] = axes["y"] = (result.model, result.parameters.parameters)
            params = save_six_axis(scratch / f"six_{coupling}.json", axes, coupling=coupling)
            fmus[coupling] = build_fmu.build_fmu(params, scratch / coupling, model="six_axis")
        t = np.arange(round(1.0 / STEP_S) + 1) * STEP_S
        period = round(1.0 / 4.7 / STEP_S)
        print("\n" + harness.provenance())
        print(f"{'path (unseen, 1 s)':24s} {'coupled FMU':>12s} {'uncoupled FMU':>14s}   NRMSE of the force vector")
        energies = []
        worst = 0.0
        for name, xy in paths(t).items():
            expected = truth(t, xy)
            errors = {coupling: vector_nrmse(run_fmu(fmu, t, xy), expected) for coupling, fmu in fmus.items()}
            if not name.startswith("line"):
                worst = max(worst, errors["radial"])
            print(f"{name:24s} {errors['radial']:12.2%} {errors['none']:14.2%}")
            if name.startswith("circle"):
                predicted = {c: run_fmu(f, t, xy) for c, f in fmus.items()}
                energies.append((name, last_cycle_energy(xy, expected, period),
                                 {c: last_cycle_energy(xy, np.vstack([[0, 0], f]), period) for c, f in predicted.items()}))
                if args.plot and name == "circle 2.5 mm":
                    plot_circle(args.plot, xy[1:], expected, predicted, period)
        print(f"largest coupled error on a plane path: {worst:.2%} (target <= 3 %)")
        for name, expected, found in energies:
            print(f"energy of the last cycle, {name}: truth {expected:.1f} mJ, coupled {found['radial']:.1f} mJ "
                  f"({found['radial'] / expected - 1:+.1%}), uncoupled {found['none']:.1f} mJ "
                  f"({found['none'] / expected - 1:+.1%})")
    print(f"total {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
