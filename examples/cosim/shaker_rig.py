"""Co-simulation example: a 300 kg body on four bushing FMUs over a shaker table (2 mm, 12 Hz).

    python examples/cosim/shaker_rig.py [--stop 1.0] [--step 0.001] [--out out/shaker_rig] [--native]

The system (``RigBody`` in ``rig_body.py``, built with pythonfmu like the bushings): the body's
displacement and velocity relative to the table go to the ``x`` and ``v`` of four instances
of ``BoucWenBushing.fmu``, each with its own parameter set (the paper's Tables 2, 4 and 5,
and the fit to the real friction damper), and the four forces come back to the body. It is
written once as an SSP 1.0 system (``SystemStructure.ssd``, the FMUs and one ``.ssv`` per
bushing bound to its component) and run twice, with the same fixed step and the same
exchange scheme (every FMU steps from the outputs of the previous step, Jacobi):

(a) by libcosim (Open Simulation Platform) through libcosimpy, from the SSP directory;
(b) by fmpy, in the short master loop :func:`run_fmpy`, with the same ``.ssv`` files as
    start values (``fmu_src.parameter_files.load_parameters``).

It prints the largest difference between the two and writes a plot and both time series.

The SSP writing and both masters are ``ssp_system.py`` (shared with ``engine_mount.py``).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(REPO))

sys.path.insert(0, str(HERE))

import ssp_system  # noqa: E402
from fmu_src.parameter_files import load_parameters, save_parameters  # noqa: E402
from ssp_system import Component, Connection, build_pythonfmu, largest_difference  # noqa: E402

BUSHINGS = {  # component name -> parameter set of the proposed model
    "bushing_front_left": REPO / "data" / "params_table2_sine.json",
    "bushing_front_right": REPO / "data" / "params_table4_step.json",
    "bushing_rear_left": REPO / "data" / "params_table5_combined.json",
    "bushing_rear_right": REPO / "data" / "params_fit_brfd_sine_0.5Hz_1in.json",
}
BODY = "body"


def build_fmus(out_dir: Path, native: bool = False) -> tuple[Path, Path]:
    """The bushing FMU (Table 5 defaults; ``native``: the compiled one) and the body FMU."""
    import build_fmu
    bushing = build_fmu.build_native_fmu(out_dir=out_dir).path if native else build_fmu.build_fmu(out_dir=out_dir)
    return bushing, build_pythonfmu(HERE / "rig_body.py", out_dir)


def components(system_dir: Path, bushing_fmu: Path, body_fmu: Path) -> list[Component]:
    """The body and the four bushings, each bushing bound to its own ``.ssv``."""
    resources = system_dir / "resources"
    return [Component(BODY, body_fmu, ("F1", "F2", "F3", "F4"), ("x_rel", "v_rel")),
            *(Component(name, bushing_fmu, ("x", "v"), ("F",), resources / f"{name}.ssv") for name in BUSHINGS)]


def connections() -> list[Connection]:
    links = []
    for i, name in enumerate(BUSHINGS, start=1):
        links += [Connection(BODY, "x_rel", name, "x"), Connection(BODY, "v_rel", name, "v"),
                  Connection(name, "F", BODY, f"F{i}")]
    return links


def write_ssp(system_dir: Path, bushing_fmu: Path, body_fmu: Path, stop_time: float) -> Path:
    """An SSP 1.0 system in ``system_dir`` (unzipped): SystemStructure.ssd + resources/."""
    resources = system_dir / "resources"
    resources.mkdir(parents=True, exist_ok=True)
    for name, params_file in BUSHINGS.items():
        save_parameters(resources / f"{name}.ssv", load_parameters(params_file))
    return ssp_system.write_ssp(system_dir, "ShakerRig", components(system_dir, bushing_fmu, body_fmu),
                                connections(), stop_time)


def run_libcosim(system_dir: Path, step_size: float, stop_time: float) -> dict[str, np.ndarray]:
    """Run the SSP system in libcosim; returns time and every output after each step."""
    parts = components(system_dir, Path("bushing.fmu"), Path("body.fmu"))   # only names and outputs are used
    return ssp_system.run_libcosim(system_dir, parts, step_size, stop_time)


def run_fmpy(bushing_fmu: Path, body_fmu: Path, system_dir: Path, step_size: float,
             stop_time: float) -> dict[str, np.ndarray]:
    """The same system in a plain fmpy master loop (Jacobi), parameter sets from the same .ssv files."""
    return ssp_system.run_fmpy(components(system_dir, bushing_fmu, body_fmu), connections(), step_size, stop_time)


def plot(libcosim: dict, fmpy_run: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figure, (forces, loops) = plt.subplots(1, 2, figsize=(12, 4.4))
    t = libcosim["time"]
    for i, name in enumerate(BUSHINGS):
        color = f"C{i}"
        label = f"{name.replace('bushing_', '')} ({BUSHINGS[name].stem.replace('params_', '')})"
        forces.plot(t, libcosim[f"{name}.F"] / 1e3, color=color, lw=1.2, label=label)
        forces.plot(t, fmpy_run[f"{name}.F"] / 1e3, color="k", lw=0.6, ls=":")
        loops.plot(libcosim[f"{BODY}.x_rel"] * 1e3, libcosim[f"{name}.F"] / 1e3, color=color, lw=1.0)
    forces.plot([], [], color="k", lw=0.6, ls=":", label="fmpy master loop (same system)")
    forces.set(xlabel="time [s]", ylabel="bushing force [kN]", title="libcosim (colours) and fmpy (dotted)")
    loops.set(xlabel="body minus table displacement [mm]", ylabel="bushing force [kN]",
              title="hysteresis loops of the four bushings")
    forces.legend(fontsize=7, loc="lower left")
    for axes in (forces, loops):
        axes.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop", type=float, default=1.0, help="stop time [s]")
    parser.add_argument("--step", type=float, default=1e-3, help="communication step [s]")
    parser.add_argument("--out", type=Path, default=REPO / "out" / "shaker_rig")
    parser.add_argument("--native", action="store_true", help="the native (compiled C) bushing FMU")
    args = parser.parse_args(argv)
    ssp_system.require_extras("examples/cosim/shaker_rig.py")
    args.out.mkdir(parents=True, exist_ok=True)
    bushing_fmu, body_fmu = build_fmus(args.out / "fmus", args.native)
    system_dir = args.out / "ShakerRig"
    write_ssp(system_dir, bushing_fmu, body_fmu, args.stop)
    libcosim = run_libcosim(system_dir, args.step, args.stop)
    fmpy_run = run_fmpy(bushing_fmu, body_fmu, system_dir, args.step, args.stop)
    differences = largest_difference(libcosim, fmpy_run)
    for key, value in differences.items():
        print(f"{key:32s} peak {np.max(np.abs(fmpy_run[key])):10.4g}   libcosim vs fmpy: {value:.2e} of peak")
    plot(libcosim, fmpy_run, args.out / "shaker_rig.png")
    np.savez(args.out / "series.npz", **{f"libcosim:{k}": v for k, v in libcosim.items()},
             **{f"fmpy:{k}": v for k, v in fmpy_run.items()})
    print(f"wrote {args.out / 'shaker_rig.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
