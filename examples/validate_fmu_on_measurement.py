"""Validate the FMU against a measurement the way the fit saw it.

    python examples/validate_fmu_on_measurement.py [--fmu dist/BoucWenBushing.fmu] [--native]

Runs the FMU (built here, with the shipped defaults, unless ``--fmu`` names one) with the parameter
set a fit returned on a real friction-damper test (``data/params_fit_brfd_sine_0.5Hz_1in.json``,
fitted on ``data/brfd/sine_0.5Hz30lbtension1amplitude.csv.gz``) given as start values, and prints the
NRMSE against the measured force of:

- the fit's forward model (``identification.predict``);
- the FMU driven by ``identification.fmu_input`` (a continuous path, v the secant velocity), through
  ``simulate_measurement`` and through fmpy's ``simulate_fmu``;
- the FMU fed the file's columns as they are (x and the measured v, which is not dx/dt of the
  sampled x), the validation that disagrees with the fit.
"""
import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from fmu_src.parameter_files import load_parameters  # noqa: E402
from identification import load_measurement, predict  # noqa: E402
from identification.analysis.fmu_input import fmu_input, simulate_measurement, table_step  # noqa: E402
from identification.fitting.objectives import nrmse  # noqa: E402

PARAMS = REPO / "data" / "params_fit_brfd_sine_0.5Hz_1in.json"
MEASUREMENT = REPO / "data" / "brfd" / "sine_0.5Hz30lbtension1amplitude.csv.gz"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", help="a built bushing FMU (default: build one in a temporary directory)")
    parser.add_argument("--native", action="store_true", help="build the native FMU (needs a C compiler)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        if args.fmu:
            fmu = Path(args.fmu)
        else:
            import build_fmu
            fmu = (build_fmu.build_native_fmu(out_dir=folder).path if args.native
                   else build_fmu.build_fmu(out_dir=folder))
        run(fmu)


def run(fmu: Path) -> None:
    m = load_measurement(MEASUREMENT)
    fitted = load_parameters(PARAMS)
    measured = m.force_N

    def on_samples(result):
        return np.interp(m.time_s, result["time"], result["F"])

    fit = predict(PARAMS, m.time_s, m.displacement_mm, m.measured_velocity_mm_s).force_N
    print(f"{m.source}: {len(m)} samples; NRMSE against the measured force")
    print(f"  fit's forward model (identification.predict)              {nrmse(fit, measured):.4f}")

    helper = simulate_measurement(fmu, m, start_values=fitted)
    print(f"  FMU, simulate_measurement (fmu_input)                      {nrmse(helper, measured):.4f}"
          f"   max |FMU - fit| = {np.max(np.abs(helper - fit)):.2g} N")

    table = fmu_input(m)
    run_table = simulate_fmu(str(fmu), input=table, start_values=fitted, start_time=table["time"][0],
                             stop_time=table["time"][-1], output_interval=table_step(table), output=["F"])
    print(f"  FMU, fmpy simulate_fmu(input=fmu_input(m))                 {nrmse(on_samples(run_table), measured):.4f}")

    columns = np.rec.fromarrays([m.time_s, m.displacement_mm / 1000.0, m.velocity_mm_s / 1000.0],
                                names=["time", "x", "v"])
    interval = float(np.median(np.diff(m.time_s)))
    run_columns = simulate_fmu(str(fmu), input=columns, start_values=fitted, start_time=m.time_s[0],
                               stop_time=m.time_s[-1], output_interval=interval, output=["F"])
    print(f"  FMU, fmpy simulate_fmu on the file's x and measured v      {nrmse(on_samples(run_columns), measured):.4f}"
          "   (the FMU logs that its inputs keep jumping; the pythonfmu FMU with debug logging on)")


if __name__ == "__main__":
    main()
