"""A Python host's exit with the project's pythonfmu FMUs (issue 57): the invalid memory accesses
valgrind finds in pythonfmu's export library, and the exit codes of many hosts.

    python benchmarks/bench_host_exit.py [--fmu FILE] [--processes N]

Builds the Kelvin-Voigt pythonfmu FMU (or takes ``--fmu``) and runs, under valgrind (where it is
installed; the plain-Python step, so that valgrind has no JIT to follow), a host that instantiates
and frees it at once, three times, then exits: prints valgrind's error contexts that name the
export library's ``clearLogBuffer`` (a freed instance's queued messages handed to a destroyed
logger) and ``finalizePythonInterpreter`` (the interpreter guard released a second time at exit).
Then ``--processes`` hosts (default 20) with the compiled step, and their exit codes.
"""
from __future__ import annotations

import argparse
import collections
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
HOST = """
import sys
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
description = read_model_description(sys.argv[1])
folder = extract(sys.argv[1])
for _ in range(3):
    fmu = FMU2Slave(guid=description.guid, unzipDirectory=folder, instanceName="host",
                    modelIdentifier=description.coSimulation.modelIdentifier)
    fmu.instantiate()
    fmu.freeInstance()
print("freed three instances", flush=True)
"""
FAULTS = ("clearLogBuffer", "finalizePythonInterpreter")


def under_valgrind(fmu: Path) -> dict[str, int]:
    """{export library function: valgrind's error reports that name it, "exit code": the host's}
    of one host run."""
    environment = dict(os.environ, BUSHING_FMU_STEP="python", PYTHONMALLOC="malloc")
    done = subprocess.run(["valgrind", "--num-callers=12", sys.executable, "-c", HOST, str(fmu)],
                          capture_output=True, text=True, env=environment, timeout=1800)
    reports, current = [], []
    for line in done.stderr.splitlines():        # a report: its lines up to valgrind's empty one
        text = re.sub(r"^==\d+== ?", "", line)
        if text:
            current.append(text)
        elif current:
            reports.append("\n".join(current))
            current = []
    return {name: sum(name in report for report in reports) for name in FAULTS} | {"exit code": done.returncode}


def exit_codes(fmu: Path, processes: int) -> collections.Counter:
    environment = {name: value for name, value in os.environ.items() if name != "BUSHING_FMU_STEP"}
    codes = collections.Counter()
    for _ in range(processes):
        codes[subprocess.run([sys.executable, "-c", HOST, str(fmu)], capture_output=True, env=environment,
                             timeout=600).returncode] += 1
    return codes


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fmu", type=Path, help="a pythonfmu FMU (default: the Kelvin-Voigt one, built now)")
    parser.add_argument("--processes", type=int, default=20)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench_host_exit_") as work:
        fmu = args.fmu
        if fmu is None:
            subprocess.run([sys.executable, str(REPO / "build_fmu.py"), "--model", "kelvin_voigt", "--out", work],
                           check=True, stdout=subprocess.DEVNULL)
            fmu = Path(work) / "KelvinVoigtBushing.fmu"
        if shutil.which("valgrind"):
            print(f"under valgrind, {fmu.name}: {under_valgrind(fmu)}", flush=True)
        else:
            print("valgrind is not installed: no memory check")
        print(f"{args.processes} hosts, compiled step, exit codes: {dict(exit_codes(fmu, args.processes))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
