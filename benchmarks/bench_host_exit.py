"""A Python host's exit with the project's pythonfmu FMUs (issue 57): the invalid memory accesses
valgrind finds in pythonfmu's export library, and the exit codes of many hosts.

    python benchmarks/bench_host_exit.py [--fmu FILE] [--processes N]

Builds the Kelvin-Voigt pythonfmu FMU (or takes ``--fmu``) and runs, under valgrind (where it is
installed; the plain-Python step, so that valgrind has no JIT to follow), a host that instantiates
and frees it at once, three times, then exits: prints valgrind's error contexts that name the
export library's ``clearLogBuffer`` (a freed instance's queued messages handed to a destroyed
logger) and ``finalizePythonInterpreter`` (the interpreter guard released a second time at exit).
Then ``--processes`` hosts (default 20) with the compiled step, and their exit codes; and, where
gcc and a shared libpython are here, as many runs of the C host of ``tests/c_host/fmi2_host.c``
(libpython loaded by the host, 200 steps of the proposed model) with ``BUSHING_FMU_STEP=compiled``.
"""
from __future__ import annotations

import argparse
import collections
import os
import re
import shutil
import subprocess
import sys
import sysconfig
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


def c_host_exit_codes(fmu: Path, processes: int, work: Path) -> collections.Counter | str:
    """Exit codes of the C host (tests/c_host/fmi2_host.c) running the proposed model's FMU
    ``fmu`` with the compiled step, or why it cannot run here."""
    from fmpy import extract, read_model_description
    libpython = Path(sysconfig.get_config_var("LIBDIR") or "") / (sysconfig.get_config_var("LDLIBRARY") or "")
    if shutil.which("gcc") is None or not sysconfig.get_config_var("Py_ENABLE_SHARED") or not libpython.is_file():
        return "needs gcc and a shared libpython"
    host = work / "fmi2_host"
    subprocess.run(["gcc", "-O1", "-o", str(host), str(REPO / "tests" / "c_host" / "fmi2_host.c"), "-ldl", "-lm"],
                   check=True)
    description = read_model_description(str(fmu))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    folder = Path(extract(str(fmu)))
    library = folder / "binaries" / "linux64" / f"{description.coSimulation.modelIdentifier}.so"
    environment = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p), PYTHONHOME=sys.base_prefix,
                       BUSHING_FMU_STEP="compiled")
    codes = collections.Counter()
    for _ in range(processes):
        codes[subprocess.run([str(host), str(libpython), str(library), description.guid,
                              (folder / "resources").as_uri(), str(refs["x"]), str(refs["v"]), str(refs["F"]), "200",
                              "1e-3"], capture_output=True, env=environment, timeout=600).returncode] += 1
    shutil.rmtree(folder, ignore_errors=True)
    return codes


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fmu", type=Path, help="a pythonfmu FMU (default: the Kelvin-Voigt one, built now)")
    parser.add_argument("--proposed", type=Path, help="the proposed model's pythonfmu FMU for the C host "
                                                       "(default: built now)")
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
        print(f"{args.processes} hosts, compiled step, exit codes: {dict(exit_codes(fmu, args.processes))}", flush=True)
        proposed = args.proposed
        if proposed is None:
            subprocess.run([sys.executable, str(REPO / "build_fmu.py"), "--out", work], check=True,
                           stdout=subprocess.DEVNULL)
            proposed = Path(work) / "BoucWenBushing.fmu"
        codes = c_host_exit_codes(proposed, args.processes, Path(work))
        print(f"C host, {proposed.name}, compiled step: {codes if isinstance(codes, str) else dict(codes)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
