"""Cost of one 1 ms co-simulation step of the bushing FMU, against a trivial pythonfmu FMU.

    python benchmarks/bench_fmu_step.py [--steps N] [--repeats R]
    python benchmarks/bench_fmu_step.py --native-against REV [--repeats R]

Both FMUs are driven the same way through fmpy's FMI 2.0 API: set x and v, doStep(1 ms),
get F, on the paper's identification sine (2 mm, 10 Hz). The trivial FMU computes F = 2*x.
The six-axis FMU (all six axes the proposed model with Table 5) is measured against a trivial
six-axis pythonfmu FMU with the same 12 inputs and 6 outputs. Everything is measured twice: with
the compiled step (numba, the default where importable) and, in a second process, with the
pure-Python step (BUSHING_FMU_STEP=python).
Runs alternate between the FMUs: the times are the medians of the repeats, and each ratio is
the median over the repeats of the FMU's time over its trivial FMU's timed just before it
(the pair sees the same machine state; a shared VM's speed drifts between repeats). Also
printed: the model core alone (no FMI), and the real-time
factor (simulated time / wall time) of one bushing.

Then the native FMUs (``build_fmu.py --native``): through fmpy against a trivial native FMU of
the same ports built from the same C layer (the stateless Kelvin-Voigt model, F = 2x) and
against the pythonfmu bushing FMU, side by side; and in a plain C master
(``c_master_timing.c``, 100 times the steps per run), where no Python is in the loop; and the
native FMUs of the filled-rubber models (berg, fractional) with their default sets, the same way.

``--native-against REV``: only the C master, each model's native FMU built from this tree and from
the commit REV (a git worktree of it, built by its own build_fmu.py), the two timed alternately
in the same run: whether a change to the native FMU changed its step's cost.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
import harness

REPO = Path(__file__).resolve().parents[1]

FILLED_RUBBER = ("berg", "fractional")
"""The filled-rubber models, timed on the same sine with their default sets (data/params_*_filled_rubber.json)."""

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

TRIVIAL_SIX_AXIS_SLAVE = '''
from pythonfmu import Fmi2Causality, Fmi2Slave, Real

PORTS = (("dx", "vx", "Fx"), ("dy", "vy", "Fy"), ("dz", "vz", "Fz"), ("rx", "wx", "Mx"), ("ry", "wy", "My"),
         ("rz", "wz", "Mz"))


class TrivialSixAxis(Fmi2Slave):
    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        for x, v, f in PORTS:
            for name in (x, v, f):
                setattr(self, name, 0.0)
            self.register_variable(Real(x, causality=Fmi2Causality.input))
            self.register_variable(Real(v, causality=Fmi2Causality.input))
            self.register_variable(Real(f, causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        for x, v, f in PORTS:
            setattr(self, f, 2.0 * getattr(self, x))
        return True
'''

STEP_S = 1e-3
ONE_AXIS_PORTS = (("x", "v"), ("F",))
SIX_AXIS_PORTS = (("dx", "vx", "dy", "vy", "dz", "vz", "rx", "wx", "ry", "wy", "rz", "wz"),
                  ("Fx", "Fy", "Fz", "Mx", "My", "Mz"))


def open_instance(fmu_path, ports):
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
    inputs, outputs = ports
    return fmu, [refs[n] for n in inputs], [refs[n] for n in outputs]


def time_fmu(fmu_path, inputs, ports=ONE_AXIS_PORTS):
    """Seconds per step (set the inputs; doStep; get the outputs) over the given input rows."""
    fmu, input_refs, output_refs = open_instance(fmu_path, ports)
    set_real, get_real, do_step = fmu.setReal, fmu.getReal, fmu.doStep
    started = time.perf_counter()
    t = 0.0
    for row in inputs:
        set_real(input_refs, row)
        do_step(t, STEP_S)
        get_real(output_refs)
        t += STEP_S
    elapsed = time.perf_counter() - started
    fmu.terminate()
    fmu.freeInstance()
    return elapsed / len(inputs)


def time_core(inputs_mm):
    from fmu_src.model.integration import advance
    from fmu_src.parameter_files import load_parameters
    from fmu_src.models.proposed_model import MODEL
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


def measure(steps: int, repeats: int) -> dict:
    """Median seconds per step of each FMU, in this process (whose step, compiled or pure
    Python, $BUSHING_FMU_STEP chooses), the FMUs alternating run by run."""
    import build_fmu
    from fmu_src.parameter_files import load_parameters, save_six_axis
    from pythonfmu.builder import FmuBuilder

    with tempfile.TemporaryDirectory() as work:
        work = Path(work)
        bushing = build_fmu.build_fmu(out_dir=work)
        table5 = load_parameters(REPO / "data" / "params_table5_combined.json")
        all_proposed = save_six_axis(work / "six_proposed.json", {a: ("proposed", table5) for a in
                                                                 ("x", "y", "z", "rx", "ry", "rz")})
        six = build_fmu.build_fmu(all_proposed, work, model="six_axis")
        trivial, trivial_six = [], []
        for name, text in (("trivial_gain_bench.py", TRIVIAL_SLAVE), ("trivial_six_axis_bench.py", TRIVIAL_SIX_AXIS_SLAVE)):
            script = work / name
            script.write_text(text)
            (trivial if name.startswith("trivial_gain") else trivial_six).append(FmuBuilder.build_FMU(script, dest=work))

        omega = 2 * math.pi * 10.0
        inputs_mm = [(2.0 * math.sin(omega * k * STEP_S), 2.0 * omega * math.cos(omega * k * STEP_S))
                     for k in range(steps)]
        inputs_m = [[x * 1e-3, v * 1e-3] for x, v in inputs_mm]
        # six axes: 2 mm / 10 Hz on x, y, z; 0.02 rad / 10 Hz on rx, ry, rz
        inputs_six = [[x * 1e-3, v * 1e-3] * 3 + [x * 1e-2, v * 1e-2] * 3 for x, v in inputs_mm]

        runs = {key: [] for key in ("trivial", "bushing", "core", "trivial_six", "six")}
        for _ in range(repeats):
            runs["trivial"].append(time_fmu(trivial[0], inputs_m))
            runs["bushing"].append(time_fmu(bushing, inputs_m))
            runs["trivial_six"].append(time_fmu(trivial_six[0], inputs_six, SIX_AXIS_PORTS))
            runs["six"].append(time_fmu(six, inputs_six, SIX_AXIS_PORTS))
            core_time, substeps = time_core(inputs_mm)
            runs["core"].append(core_time)
    result = {key: statistics.median(values) for key, values in runs.items()}
    # The ratio of each repeat (the two FMUs timed back to back), then their median: a shared
    # machine's speed drifts between repeats, and this cancels the drift that the ratio of
    # medians keeps.
    for key, base in (("bushing", "trivial"), ("core", "trivial"), ("six", "trivial_six")):
        result[f"{key}_ratio"] = statistics.median(a / b for a, b in zip(runs[key], runs[base]))
    result["substeps"] = substeps
    return result


def measure_native(steps: int, repeats: int) -> dict:
    """The native FMUs (build_fmu.py --native): seconds per step through fmpy, alternating with a
    trivial native FMU of the same ports (the stateless Kelvin-Voigt model of the same C layer with
    k = 0.002 N/mm, c = 0: F = 2x) and with the pythonfmu bushing FMU; and in a plain C master
    (benchmarks/c_master_timing.c)."""
    import statistics

    import build_fmu
    from fmu_src.fmi.native.build import fmi_header_directory
    from fmu_src.parameter_files import load_parameters, save_parameters, save_six_axis

    with tempfile.TemporaryDirectory() as work:
        work = Path(work)
        table5 = load_parameters(REPO / "data" / "params_table5_combined.json")
        gain = {"k": 0.002, "c": 0.0, "preload": 0.0}
        all_proposed = save_six_axis(work / "six_proposed.json", {a: ("proposed", table5) for a in
                                                                 ("x", "y", "z", "rx", "ry", "rz")})
        # on the rotational axes the same model gives N.mm for rad: 2 N.mm/rad is 2e-3 N.m/rad
        all_gain = save_six_axis(work / "six_gain.json", {a: ("kelvin_voigt", gain if len(a) == 1 else
                                                              dict(gain, k=2.0)) for a in
                                                          ("x", "y", "z", "rx", "ry", "rz")})
        gain_file = save_parameters(work / "gain.json", gain, "kelvin_voigt")
        fmus = {"native_trivial": build_fmu.build_native_fmu(gain_file, work / "a", "kelvin_voigt").path,
                "native": build_fmu.build_native_fmu(out_dir=work / "b").path,
                "pythonfmu": build_fmu.build_fmu(out_dir=work / "c"),
                "native_trivial_six": build_fmu.build_native_fmu(all_gain, work / "d", "six_axis").path,
                "native_six": build_fmu.build_native_fmu(all_proposed, work / "e", "six_axis").path,
                "native_six_default": build_fmu.build_native_fmu(out_dir=work / "f", model="six_axis").path,
                **{f"native_{model}": build_fmu.build_native_fmu(out_dir=work / model, model=model).path
                   for model in FILLED_RUBBER}}
        omega = 2 * math.pi * 10.0
        inputs_m = [[2e-3 * math.sin(omega * k * STEP_S), 2e-3 * omega * math.cos(omega * k * STEP_S)]
                    for k in range(steps)]
        inputs_six = [row * 3 + [10.0 * row[0], 10.0 * row[1]] * 3 for row in inputs_m]
        runs = {key: [] for key in fmus}
        for _ in range(repeats):
            for key in ("native_trivial", "native", "pythonfmu", *(f"native_{model}" for model in FILLED_RUBBER)):
                runs[key].append(time_fmu(fmus[key], inputs_m))
            for key in ("native_trivial_six", "native_six", "native_six_default"):
                runs[key].append(time_fmu(fmus[key], inputs_six, SIX_AXIS_PORTS))
        result = {f"fmpy_{key}": statistics.median(values) for key, values in runs.items()}
        for key in ("native", *(f"native_{model}" for model in FILLED_RUBBER)):
            result[f"fmpy_{key}_ratio"] = statistics.median(a / b for a, b in zip(runs[key], runs["native_trivial"]))
        for key in ("native_six", "native_six_default"):
            result[f"fmpy_{key}_ratio"] = statistics.median(a / b for a, b in zip(runs[key], runs["native_trivial_six"]))
        result["fmpy_native_over_pythonfmu"] = statistics.median(a / b for a, b in zip(runs["native"],
                                                                                       runs["pythonfmu"]))
        master = work / "c_master_timing"
        subprocess.run(["cc", "-O2", "-std=c99", "-I", str(fmi_header_directory()), "-o", str(master),
                        str(Path(__file__).with_name("c_master_timing.c")), "-ldl", "-lm"], check=True)
        for key in ("native_trivial", "native", "native_trivial_six", "native_six", "native_six_default",
                    *(f"native_{model}" for model in FILLED_RUBBER)):
            result[f"c_{key}"] = statistics.median(_c_master(master, fmus[key], work / key, 100 * steps, repeats))
    return result


def _c_master(master: Path, fmu: Path, folder: Path, steps: int, repeats: int) -> list[float]:
    """Seconds per step of each repeat in the C master."""
    from fmpy import extract, read_model_description
    description = read_model_description(str(fmu))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    ports = [p for p in SIX_AXIS_PORTS[0]] if "dx" in refs else ["x", "v"]
    outputs = SIX_AXIS_PORTS[1] if "dx" in refs else ("F",)
    library = Path(extract(str(fmu), str(folder))) / "binaries" / "linux64" / f"{description.coSimulation.modelIdentifier}.so"
    arguments = [str(master), str(library), description.guid, str(steps), str(repeats), str(len(outputs))]
    for a, output in enumerate(outputs):
        arguments += [str(refs[ports[2 * a]]), str(refs[ports[2 * a + 1]]), str(refs[output])]
    run = subprocess.run(arguments, capture_output=True, text=True, check=True)
    return [float(line) * 1e-9 for line in run.stdout.split()]


def measure_native_against(revision: str, steps: int, repeats: int) -> dict:
    """{model: (this tree's, ``revision``'s seconds per step)} in the C master, the two FMUs of a
    model timed alternately (each repeat one run of each)."""
    import build_fmu
    from fmu_src.fmi.native.build import fmi_header_directory

    models = ("proposed", *FILLED_RUBBER)
    with tempfile.TemporaryDirectory() as work:
        work = Path(work)
        tree = work / "baseline"
        subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", str(tree), revision], check=True,
                       capture_output=True)
        try:
            build = ("import sys, build_fmu\nfor model in sys.argv[2:]:\n"
                     "    print(build_fmu.build_native_fmu(out_dir=sys.argv[1] + '/' + model, model=model).path)")
            baseline = subprocess.run([sys.executable, "-c", build, str(work / "old"), *models], cwd=tree,
                                      env=dict(os.environ, PYTHONPATH=str(tree)), capture_output=True, text=True,
                                      check=True).stdout.split()
        finally:
            subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(tree)], check=True)
        current = [build_fmu.build_native_fmu(out_dir=work / "new" / model, model=model).path for model in models]
        master = work / "c_master_timing"
        subprocess.run(["cc", "-O2", "-std=c99", "-I", str(fmi_header_directory()), "-o", str(master),
                        str(Path(__file__).with_name("c_master_timing.c")), "-ldl", "-lm"], check=True)
        result = {}
        for model, new, old in zip(models, current, baseline):
            times = {"new": [], "old": []}
            for k in range(repeats):
                for key, fmu in (("new", new), ("old", old)):
                    times[key] += _c_master(master, Path(fmu), work / f"{key}_{model}_{k}", 100 * steps, 1)
            result[model] = (statistics.median(times["new"]), statistics.median(times["old"]),
                             statistics.median(a / b for a, b in zip(times["new"], times["old"])))
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=2000, help="steps per run (default 2000 = 2 s)")
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--native-against", metavar="REV", help="only the C master: this tree's native FMUs "
                        "against those of the commit REV, side by side")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.native_against:
        result = measure_native_against(args.native_against, args.steps, args.repeats)
        print(f"{harness.provenance()}\nC master, {100 * args.steps} steps a run, {args.repeats} runs each, "
              "alternating; us/step, median")
        print(f"{'model':12s} {'this tree':>10s} {args.native_against[:12]:>12s} {'ratio':>6s}")
        for model, (new, old, ratio) in result.items():
            print(f"{model:12s} {new * 1e6:10.3f} {old * 1e6:12.3f} {ratio:6.3f}")
        return
    if args.child:
        print(json.dumps(measure(args.steps, args.repeats)))
        return

    # The compiled step here; the pure-Python step in a process started with BUSHING_FMU_STEP=python
    # (an FMU decides which it runs when its library is first imported).
    compiled = measure(args.steps, args.repeats)
    environment = dict(os.environ, BUSHING_FMU_STEP="python")
    child = subprocess.run([sys.executable, __file__, "--child", "--steps", str(args.steps), "--repeats",
                            str(args.repeats)], env=environment, capture_output=True, text=True, check=True)
    plain = json.loads(child.stdout.strip().splitlines()[-1])

    print(f"{harness.provenance()}\n{platform.processor() or 'cpu'}; {args.steps} steps x {args.repeats} repeats, "
          f"sine 2 mm (0.02 rad) / 10 Hz, step {STEP_S * 1e3:g} ms")
    print(f"{'what':46s} {'compiled':>9s} {'ratio':>6s} {'pure Py':>9s} {'ratio':>6s}   (us/step, median; "
          "ratio: median over the repeats of the time over its trivial FMU's just before)")
    for key, label in (("trivial", "trivial pythonfmu FMU (F = 2x)"),
                       ("bushing", "bushing FMU, one axis (target <= 1.5x)"),
                       ("core", "bushing model core alone, pure Python"),
                       ("trivial_six", "trivial six-axis pythonfmu FMU (F = 2x)"),
                       ("six", "six-axis FMU, six proposed axes (<= 2x)")):
        print(f"{label:46s} {compiled[key] * 1e6:9.1f} {compiled.get(key + '_ratio', 1.0):6.2f} "
              f"{plain[key] * 1e6:9.1f} {plain.get(key + '_ratio', 1.0):6.2f}")
    print(f"six-axis FMU against the one-port trivial FMU: {compiled['six'] / compiled['trivial']:.2f} (compiled), "
          f"{plain['six'] / plain['trivial']:.2f} (pure Python)")
    print(f"substeps per 1 ms step (core): {compiled['substeps']:.2f}")
    print(f"real-time factor of one bushing FMU at 1 ms: {STEP_S / compiled['bushing']:.0f}x (compiled), "
          f"{STEP_S / plain['bushing']:.0f}x (pure Python) faster than real time")

    native = measure_native(args.steps, args.repeats)
    print("\nnative FMU (build_fmu.py --native), against a trivial native FMU of the same ports and C layer "
          "(Kelvin-Voigt, F = 2x), us/step, median; ratios as above")
    print(f"{'what':46s} {'fmpy':>9s} {'ratio':>6s} {'C master':>9s}")
    for key, label, ratio in (("native_trivial", "trivial native FMU, one axis", 1.0),
                              ("native", "native bushing FMU, one axis (<= 1.15x)", native["fmpy_native_ratio"]),
                              *((f"native_{model}", f"native {model} FMU (C master: <= 1 us)",
                                 native[f"fmpy_native_{model}_ratio"]) for model in FILLED_RUBBER),
                              ("native_trivial_six", "trivial native FMU, six axes", 1.0),
                              ("native_six", "native six-axis FMU, six proposed axes", native["fmpy_native_six_ratio"]),
                              ("native_six_default", "native six-axis FMU, its default set",
                               native["fmpy_native_six_default_ratio"])):
        print(f"{label:46s} {native['fmpy_' + key] * 1e6:9.2f} {ratio:6.2f} {native['c_' + key] * 1e6:9.3f}")
    print(f"native bushing FMU over the pythonfmu bushing FMU (compiled step) through fmpy, side by side: "
          f"{native['fmpy_native_over_pythonfmu']:.2f} ({native['fmpy_pythonfmu'] * 1e6:.1f} us/step)")
    print(f"C master: one bushing {native['c_native'] * 1e6:.3f} us/step (target <= 1 us), six axes "
          f"{native['c_native_six'] * 1e6:.3f} us/step with six proposed axes, {native['c_native_six_default'] * 1e6:.3f} "
          f"with the default set (x, y proposed, z Spencer, rx, ry, rz Kelvin-Voigt; target <= 3 us); 20 bushings "
          f"{STEP_S / (20 * native['c_native']):.0f}x faster than real time at 1 ms (target >= 50x)")


if __name__ == "__main__":
    main()
