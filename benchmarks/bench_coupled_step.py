"""Cost of the native six-axis FMU's step with coupled groups, against the same models uncoupled (issue target)

    python benchmarks/bench_coupled_step.py [--steps N] [--repeats R]

In the plain C master (``c_master_timing.c``, no Python in the loop), each axis driven by a 10 Hz
sine (2 mm, or 0.02 rad), the axes a third of a half period apart (C_MASTER_PHASED: a group moves
in its plane, a circle-like path, not along a line). Pairs of native FMUs with the same models and
parameters, uncoupled and coupled, timed alternately, run by run:

- six proposed axes (Table 5): uncoupled against spherical (x, y, z) and conical (rx, ry);
- the same against radial (x, y) alone;
- the default illustrative set (x, y proposed, z Spencer, rx, ry, rz Kelvin-Voigt) against radial.

Prints the medians (us/step) and the median over the runs of the coupled time over the uncoupled
time just before it (target <= 1.5), and the six proposed axes' absolute time (target <= 3 us).
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

import build_fmu  # noqa: E402
from bench_fmu_step import _c_master  # noqa: E402
from fmu_src.fmi.native.build import fmi_header_directory  # noqa: E402
from fmu_src.parameter_files import load_parameters, read_six_axis, save_six_axis  # noqa: E402
import harness  # noqa: E402

AXES = ("x", "y", "z", "rx", "ry", "rz")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200_000, help="steps per run (default 200000)")
    parser.add_argument("--repeats", type=int, default=11)
    args = parser.parse_args()
    os.environ["C_MASTER_PHASED"] = "1"
    with tempfile.TemporaryDirectory() as work:
        work = Path(work)
        table5 = load_parameters(REPO / "data" / "params_table5_combined.json")
        proposed = {axis: ("proposed", table5) for axis in AXES}
        default = read_six_axis(REPO / "data" / "params_six_axis_illustrative.json")
        illustrative = {axis: (one.model.name, one.parameters) for axis, one in default.axes.items()}
        sets = {"proposed_none": (proposed, "none"), "proposed_spherical_conical":
                (proposed, {"translation": "spherical", "rotation": "conical"}),
                "proposed_radial": (proposed, "radial"), "default_none": (illustrative, "none"),
                "default_radial": (illustrative, "radial")}
        fmus = {}
        for key, (axes, coupling) in sets.items():
            path = save_six_axis(work / f"{key}.json", axes, coupling=coupling)
            fmus[key] = build_fmu.build_native_fmu(path, work / key, model="six_axis").path
        master = work / "c_master_timing"
        subprocess.run(["cc", "-O2", "-std=c99", "-I", str(fmi_header_directory()), "-o", str(master),
                        str(Path(__file__).with_name("c_master_timing.c")), "-ldl", "-lm"], check=True)
        times = {key: [] for key in fmus}
        for k in range(args.repeats):
            for key, fmu in fmus.items():
                times[key] += _c_master(master, fmu, work / f"run_{key}_{k}", args.steps, 1)
    print(harness.provenance())
    print("C master, 10 Hz sines a third of a half period apart axis by axis; us/step, median; ratio: median "
          "over the runs of the coupled time over the uncoupled one's")
    for label, key, base in (("six proposed axes, uncoupled", "proposed_none", None),
                             ("six proposed axes, spherical + conical", "proposed_spherical_conical", "proposed_none"),
                             ("six proposed axes, radial", "proposed_radial", "proposed_none"),
                             ("default set, uncoupled", "default_none", None),
                             ("default set, radial", "default_radial", "default_none")):
        ratio = (f"{statistics.median(a / b for a, b in zip(times[key], times[base])):6.2f}" if base else "     -")
        print(f"  {label:42s} {statistics.median(times[key]) * 1e6:8.3f} {ratio}")
    print("targets: coupled <= 1.5x uncoupled; six proposed axes <= 3 us a step")


if __name__ == "__main__":
    main()
