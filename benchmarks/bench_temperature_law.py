"""The temperature law (``wlf``) on the synthetic temperature-dependent bushing, and its step's cost.

    python benchmarks/bench_temperature_law.py [--seed N] [--steps N] [--repeats R]

1. Fit ``kelvin_voigt+maxwell+iwan1+wlf`` to the six training sines at -20, 23 and 60 degC
   (data/synthetic_thermal_*, data/generate_thermal_rubber.py: the truth of
   tests/references/thermal_rubber.py), print each training test's NRMSE, the held-out 0 and
   80 degC sines' and the 40 degC random road's (each run at its file's temperature), and the law's
   constants with the ensemble's range beside the truth's.
2. The native FMU's step (the C master, benchmarks/c_master_timing.c: no Python in the loop) of
   ``kelvin_voigt+maxwell+iwan1`` and of the same model with the law at 253.15 K, built from this
   tree, timed alternately in one run: the median ratio.
3. Self-heating: a 600 s, 3 mm, 10 Hz durability sine at 1 ms steps on
   ``kelvin_voigt+maxwell+iwan1+wlf+heating`` (540 J/K, 1.2 K/W) against the textbook bushing
   heated by its own elements' dissipation: the reference's warming, and each FMU's (native and
   pythonfmu, through fmpy, FMI 2) largest temperature difference and force NRMSE, the host's
   velocity the mean over each step; and the native FMU given the velocity at each step's start.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import harness

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "tests" / "references"))
import thermal_rubber  # noqa: E402

MODEL = "kelvin_voigt+maxwell+iwan1+wlf"
DATA = REPO / "data"
TRAINING = [DATA / f"synthetic_thermal_{name}_{t}.csv" for t in ("m20C", "p23C", "p60C")
            for name in ("sine_1mm_2Hz", "sine_0.3mm_12Hz")]
HELD_OUT = [DATA / f"synthetic_thermal_{name}.csv" for name in ("sine_1mm_5Hz_p0C", "sine_1mm_5Hz_p80C",
                                                                  "random_2mm_p40C")]
LAW = ("wlf_c1", "wlf_c2", "elastic_per_K", "friction_per_K")


def identification(seed: int) -> None:
    from identification.fitting.fit import fit
    from identification.fitting.objectives import nrmse
    from identification.forward.simulate import simulate_record
    from identification.measured.measurements import load_measurement
    from identification.measured.rig_tests import RigTest
    tests = [RigTest(load_measurement(path), kind="sine") for path in TRAINING]
    start = time.perf_counter()
    result = fit(tests, model=MODEL, seed=seed, progress=False)
    print(f"fit of {MODEL} to {len(tests)} sines at -20, 23, 60 degC: chi^2/n {result.misfit:.4f}, "
          f"{time.perf_counter() - start:.1f} s, ensemble {len(result.ensemble)} sets")
    for test in result.tests:
        print(f"  training {test.name:46s} NRMSE {100 * test.nrmse:6.3f} %  noise {100 * test.noise_fraction:6.3f} %")
    for path in HELD_OUT:
        m = load_measurement(path)
        predicted = simulate_record(result.parameters, m)
        print(f"  held out {path.name:46s} NRMSE {100 * nrmse(predicted, m.force_N):6.3f} %  "
              f"at {m.mean_temperature_K - 273.15:.0f} degC")
    for name in LAW:
        members = [member[name] for member in result.ensemble]
        print(f"  {name:15s} fitted {result.parameters.parameters[name]:+.5g}  ensemble {min(members):+.5g} .. "
              f"{max(members):+.5g}  truth {thermal_rubber.TRUTH[name]:+.5g}")


def step_cost(steps: int, repeats: int) -> None:
    import subprocess
    import build_fmu
    from bench_fmu_step import _c_master
    from fmu_src.fmi.native.build import fmi_header_directory
    from fmu_src.parameter_files import save_parameters
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        cold = thermal_rubber.project_parameters(temperature_K=253.15)
        plain = {name: value for name, value in thermal_rubber.project_parameters().items()
                 if name not in ("temperature", "temperature_ref", *LAW)}
        fmus = {}
        for key, model, params in (("without", "kelvin_voigt+maxwell+iwan1", plain), ("with", MODEL, cold)):
            file = save_parameters(work / f"{key}.json", params, model)
            fmus[key] = build_fmu.build_native_fmu(file, work / key, model=model, fmi_version=2).path
        master = work / "c_master_timing"
        subprocess.run(["cc", "-O2", "-std=c99", "-I", str(fmi_header_directory()), "-o", str(master),
                        str(REPO / "benchmarks" / "c_master_timing.c"), "-ldl", "-lm"], check=True)
        times = {"without": [], "with": []}
        for k in range(repeats):
            for key in ("without", "with"):
                times[key] += _c_master(master, fmus[key], work / f"run_{key}_{k}", steps, 1)
        ratio = statistics.median(a / b for a, b in zip(times["with"], times["without"]))
        print(f"native step (C master, {steps} steps x {repeats} alternating runs): without the law "
              f"{1e9 * statistics.median(times['without']):.1f} ns, with it at 253.15 K "
              f"{1e9 * statistics.median(times['with']):.1f} ns; ratio {ratio:.3f}")


def durability() -> None:
    import build_fmu
    from fmpy import simulate_fmu
    from fmu_src.parameter_files import save_parameters
    from identification.fitting.objectives import nrmse
    model, capacity, resistance = "kelvin_voigt+maxwell+iwan1+wlf+heating", 540.0, 1.2
    dt, stop = 1e-3, 600.0
    t = np.arange(0.0, stop + dt / 2, dt)
    x = 3.0 * np.sin(2 * np.pi * 10.0 * t)
    v = 3.0 * 2 * np.pi * 10.0 * np.cos(2 * np.pi * 10.0 * t)
    secant = np.append(np.diff(x) / dt, 0.0)
    start = time.perf_counter()
    held = np.append(0.0, secant[:-1])             # the velocity the FMU's dashpot reads at each output
    want, temperature = thermal_rubber.heated_force(thermal_rubber.TRUTH, capacity, resistance, 296.15, t, x, held)
    print(f"durability sine 3 mm, 10 Hz, {stop:g} s at {1e3 * dt:g} ms: the reference warms by "
          f"{temperature[-1] - 296.15:.2f} K ({time.perf_counter() - start:.1f} s)")
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        params = dict(thermal_rubber.project_parameters(), thermal_capacity=capacity, thermal_resistance=resistance)
        file = save_parameters(work / "params.json", params, model)
        fmus = {"native": build_fmu.build_native_fmu(file, work / "native", model=model, fmi_version=2).path,
                "pythonfmu": build_fmu.build_fmu(file, work / "python", model=model)}
        for key, velocity, label in (("native", secant, "mean velocity"), ("pythonfmu", secant, "mean velocity"),
                                     ("native", v, "velocity at the step's start")):
            signals = np.zeros(t.size, dtype=[("time", float), ("x", float), ("v", float)])
            signals["time"], signals["x"], signals["v"] = t, x * 1e-3, velocity * 1e-3
            start = time.perf_counter()
            result = simulate_fmu(str(fmus[key]), stop_time=stop, step_size=dt, output_interval=dt, input=signals,
                                  output=["F", "rubber_temperature"])
            n = len(result)
            print(f"  {key:9s} ({label}): warms by {result['rubber_temperature'][-1] - 296.15:.2f} K, largest "
                  f"difference {np.max(np.abs(result['rubber_temperature'] - temperature[:n])):.4f} K, force NRMSE "
                  f"{100 * nrmse(result['F'], want[:n]):.3f} % ({time.perf_counter() - start:.0f} s)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--steps", type=int, default=200000)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    print(harness.provenance())
    identification(args.seed)
    step_cost(args.steps, args.repeats)
    durability()


if __name__ == "__main__":
    main()
