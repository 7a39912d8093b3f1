"""What an instance of the pythonfmu FMU costs in memory, and a new process's first instance in
time (loading the compiled kernels from numba's disk cache).

    python benchmarks/bench_fmu_instances.py [--instances 500]

In a fresh Python process per FMU (the bushing FMU, built with its default set, and a trivial
pythonfmu FMU with the same ports, F = 2x), the FMU extracted once: one instance is made and
stepped (imports, numba's cache), then ``--instances`` more are made, initialised, stepped once
and kept; prints the
resident memory they add per instance (psutil), and the first instance's time in a process whose
numba cache is already filled (the FMU's default cache directory, filled by a run before).
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

from bench_fmu_step import TRIVIAL_SLAVE  # noqa: E402
import harness  # noqa: E402

INSTANCES = """
import sys, time
import psutil
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
process = psutil.Process()
description = read_model_description({fmu!r})
refs = {{v.name: v.valueReference for v in description.modelVariables}}
folder = extract({fmu!r})


def instance(number):
    fmu = FMU2Slave(guid=description.guid, unzipDirectory=folder,
                    modelIdentifier=description.coSimulation.modelIdentifier, instanceName=f"i{{number}}")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.setReal([refs["x"], refs["v"]], [1e-3, 0.0])
    fmu.doStep(0.0, 1e-3)
    return fmu


started = time.perf_counter()
kept = [instance(0)]
first_s = time.perf_counter() - started
before = process.memory_info().rss
kept += [instance(number) for number in range(1, {count} + 1)]
print(first_s, (process.memory_info().rss - before) / {count})
"""


def run(fmu: Path, count: int) -> tuple[float, float]:
    script = INSTANCES.format(fmu=str(fmu), count=count)
    output = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    first_s, per_instance = output.split()[-2:]
    return float(first_s), float(per_instance)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--instances", type=int, default=500)
    args = parser.parse_args()
    import build_fmu
    from pythonfmu import FmuBuilder
    print(harness.provenance())
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        bushing = build_fmu.build_fmu(out_dir=work / "bushing")
        script = work / "trivial_gain_instances.py"
        script.write_text(TRIVIAL_SLAVE)
        trivial = FmuBuilder.build_FMU(script, dest=work)
        run(bushing, 1)   # fills numba's cache for this FMU's kernels, if empty
        for name, fmu in (("bushing FMU", bushing), ("trivial FMU (F = 2x)", trivial)):
            first_s, per_instance = run(fmu, args.instances)
            print(f"{name:22s} first instance {first_s:6.2f} s; memory per further instance "
                  f"{per_instance / 1024:7.1f} kB ({args.instances} kept)")


if __name__ == "__main__":
    main()
