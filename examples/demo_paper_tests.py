"""Demo: the paper's identification tests through the built FMU, with fmpy.

    python examples/demo_paper_tests.py [--fmu dist/BoucWenBushing.fmu] [--out out]

Simulates the sine test (2 mm, 10 Hz) and the step test (2 mm, rise time 0.4 s, held to
10 s) with the FMU's default parameters (the paper's Table 5), 1 ms communication steps,
prints the peak forces the paper discusses (Figs. 15-17) and writes a figure with the
force-displacement loops and the step response.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
from identification.measured.signals import Sine, Step, sample_times  # noqa: E402

STEP_S = 1e-3


def run_protocol(fmu_path: Path, protocol) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time [s], displacement [mm] and force [N] of the FMU driven by ``protocol``."""
    from fmpy import simulate_fmu
    t = sample_times(protocol.duration_s, 1.0 / STEP_S)
    x_mm, v_mm_s = protocol.signals(t)
    signals = np.zeros(t.size, dtype=[("time", float), ("x", float), ("v", float)])
    signals["time"], signals["x"], signals["v"] = t, x_mm * 1e-3, v_mm_s * 1e-3
    result = simulate_fmu(str(fmu_path), stop_time=t[-1], step_size=STEP_S, output_interval=STEP_S,
                          input=signals, output=["F"])
    return t, x_mm, result["F"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", type=Path, default=REPO / "dist" / "BoucWenBushing.fmu")
    parser.add_argument("--out", type=Path, default=REPO / "out")
    args = parser.parse_args()
    if not args.fmu.exists():
        sys.exit(f"error: {args.fmu} does not exist; build it first with: python build_fmu.py")

    sine = Sine(amplitude_mm=2.0, frequency_hz=10.0, duration_s=1.0)
    step = Step(amplitude_mm=2.0, rise_time_s=0.4, duration_s=10.0)
    t_sine, x_sine, f_sine = run_protocol(args.fmu, sine)
    t_step, x_step, f_step = run_protocol(args.fmu, step)

    last_cycle = t_sine >= sine.duration_s - 1.0 / sine.frequency_hz
    at_rise = np.argmin(np.abs(t_step - step.rise_time_s))
    print("Paper test protocols through the FMU (Table 5 parameters, 1 ms steps):")
    print(f"  sine 2 mm / 10 Hz, last cycle : F max {f_sine[last_cycle].max():8.1f} N, "
          f"F min {f_sine[last_cycle].min():8.1f} N")
    print(f"  step 2 mm, rise 0.4 s         : F at 0.4 s {f_step[at_rise]:8.1f} N, "
          f"F at 10 s {f_step[-1]:8.1f} N (relaxation {f_step[at_rise] - f_step[-1]:.1f} N)")

    try:
        import matplotlib
    except ImportError:
        print("no plot: matplotlib is not installed (pip install 'boucwen-bushing[plot]')")
        return
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figure, (loops, response) = plt.subplots(1, 2, figsize=(11, 4.2))
    first_cycle = t_sine < 1.0 / sine.frequency_hz
    loops.plot(x_sine[first_cycle], f_sine[first_cycle] / 1e3, color="0.6", lw=1, label="first cycle (from rest)")
    loops.plot(x_sine[last_cycle], f_sine[last_cycle] / 1e3, color="C0", lw=2, label="10th cycle")
    loops.set(xlabel="displacement x [mm]", ylabel="force F [kN]", title="Sine 2 mm, 10 Hz: hysteresis loop")
    loops.legend(loc="upper left")
    loops.grid(alpha=0.3)
    response.plot(t_step, f_step / 1e3, color="C3", lw=2, label="force")
    response.set(xlabel="time [s]", ylabel="force F [kN]", title="Step 2 mm, rise time 0.4 s: relaxation")
    twin = response.twinx()
    twin.plot(t_step, x_step, color="0.5", ls="--", lw=1)
    twin.set_ylabel("displacement x [mm] (dashed)")
    response.grid(alpha=0.3)
    figure.suptitle("BoucWenBushing.fmu with the paper's Table 5 parameters (fmpy, 1 ms steps)")
    figure.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "demo_paper_tests.png"
    figure.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
