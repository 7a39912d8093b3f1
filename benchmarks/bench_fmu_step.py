"""Cost of one 1 ms co-simulation step of the bushing FMU, against a trivial pythonfmu FMU.

    python benchmarks/bench_fmu_step.py [--steps N] [--repeats R]

Both FMUs are driven the same way through fmpy's FMI 2.0 API: set x and v, doStep(1 ms),
get F, on the paper's identification sine (2 mm, 10 Hz). The trivial FMU computes F = 2*x.
Runs alternate between the two FMUs and the median of the repeats is reported, so both
see the same machine state. Also printed: the model core alone (no FMI), and the real-time
factor (simulated time / wall time) of one bushing.
"""
from __future__ import annotations

import argparse
import math
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

TRIVIAL_SLAVE = '''
from pythonfmu import Fmi2Causality, Fmi2Slave, Real


class TrivialGain(Fmi2Slave):
    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.x = 0.0
        self.v = 0.0
        self.F = 0.0
        self.register_variable(Real("x", causality=Fmi2Causality.input))
        self.register_variable(Real("v", causality=Fmi2Causality.input))
        self.register_variable(Real("F", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        self.F = 2.0 * self.x
        return True
'''

STEP_S = 1e-3


def open_instance(fmu_path):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    description = read_model_description(fmu_path)
    refs = {v.name: v.valueReference for v in description.modelVariables}
    fmu = FMU2Slave(guid=description.guid, unzipDirectory=extract(fmu_path),
                    modelIdentifier=description.coSimulation.modelIdentifier, instanceName="bench")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu, [refs["x"], refs["v"]], [refs["F"]]


def time_fmu(fmu_path, inputs):
    """Seconds per step (set x, v; doStep; get F) over the given input samples [m, m/s]."""
    fmu, input_refs, output_refs = open_instance(fmu_path)
    set_real, get_real, do_step = fmu.setReal, fmu.getReal, fmu.doStep
    started = time.perf_counter()
    t = 0.0
    for x, v in inputs:
        set_real(input_refs, [x, v])
        do_step(t, STEP_S)
        get_real(output_refs)
        t += STEP_S
    elapsed = time.perf_counter() - started
    fmu.terminate()
    fmu.freeInstance()
    return elapsed / len(inputs)


def time_core(inputs_mm):
    from fmu_src.integration import advance
    from fmu_src.parameter_files import load_parameters
    from fmu_src.proposed_model import MODEL
    params = load_parameters(REPO / "data" / "params_table5_combined.json")
    constants = MODEL.constants(params)
    state, state_x = MODEL.initial_state(constants, 0.0), 0.0
    started = time.perf_counter()
    substeps = 0
    for x, v in inputs_mm:
        state, used = advance(MODEL, constants, state, state_x, x, v, STEP_S)
        state_x = x + v * STEP_S
        MODEL.force(constants, state, state_x, v)
        substeps += used
    return (time.perf_counter() - started) / len(inputs_mm), substeps / len(inputs_mm)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=5000, help="steps per run (default 5000 = 5 s)")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()

    import build_fmu
    from pythonfmu.builder import FmuBuilder

    with tempfile.TemporaryDirectory() as work:
        work = Path(work)
        bushing = build_fmu.build_fmu(out_dir=work)
        script = work / "trivial_gain_bench.py"
        script.write_text(TRIVIAL_SLAVE)
        trivial = FmuBuilder.build_FMU(script, dest=work)

        omega = 2 * math.pi * 10.0
        inputs_mm = [(2.0 * math.sin(omega * k * STEP_S), 2.0 * omega * math.cos(omega * k * STEP_S))
                     for k in range(args.steps)]
        inputs_m = [(x * 1e-3, v * 1e-3) for x, v in inputs_mm]

        trivial_runs, bushing_runs, core_runs = [], [], []
        for _ in range(args.repeats):
            trivial_runs.append(time_fmu(trivial, inputs_m))
            bushing_runs.append(time_fmu(bushing, inputs_m))
            core_time, substeps = time_core(inputs_mm)
            core_runs.append(core_time)

    trivial_step = statistics.median(trivial_runs)
    bushing_step = statistics.median(bushing_runs)
    core_step = statistics.median(core_runs)
    print(f"machine: {platform.machine()}, {platform.processor() or 'cpu'}, Python {platform.python_version()}, "
          f"{args.steps} steps x {args.repeats} repeats, sine 2 mm / 10 Hz, step {STEP_S * 1e3:g} ms")
    print(f"{'what':42s} {'us/step':>9s} {'ratio':>7s}")
    print(f"{'trivial pythonfmu FMU (F = 2x)':42s} {trivial_step * 1e6:9.1f} {1.0:7.2f}")
    print(f"{'bushing FMU (set x,v; doStep; get F)':42s} {bushing_step * 1e6:9.1f} {bushing_step / trivial_step:7.2f}")
    print(f"{'bushing model core alone (no FMI)':42s} {core_step * 1e6:9.1f} {core_step / trivial_step:7.2f}")
    print(f"substeps per 1 ms step (core): {substeps:.2f}")
    print(f"real-time factor of one bushing FMU at 1 ms: {STEP_S / bushing_step:.0f}x faster than real time")


if __name__ == "__main__":
    main()
