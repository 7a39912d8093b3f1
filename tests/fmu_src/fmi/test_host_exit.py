"""A Python host that loads, runs and frees the pythonfmu FMUs of every model in one process exits
cleanly.

pythonfmu 0.7's export library crashed such hosts in two ways (found with valgrind and gdb;
``fmu_src/fmi/pythonfmu_slave.py`` says how each is contained):
- freeing an instance whose log messages were still queued handed them to a logger already
  destroyed: a segmentation fault in the instance's destructor (this file's host with the FMUs
  built before the fix: 4 of 4 processes with the compiled step, where numba's allocations reuse
  the freed logger's memory; 0 of 6 with the plain-Python step);
- at the process's exit its interpreter guard was released twice, the second time in freed
  memory: "corrupted double-linked list", exit 134, in a later free (fmpy's simulate_fmu of four
  FMUs in one process: 2 of 12 and 1 of 20 processes).

Each process here instantiates and frees every FMU at once, then simulates each one, then exits;
the quick test runs 2 such processes, the slow one 50.
"""
import os
import subprocess
import sys

import pytest

HOST = """
import sys
import numpy as np
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
t = np.arange(0.0, 0.02, 1e-3)
for path in sys.argv[1:]:
    description = read_model_description(path)
    folder = extract(path)
    bare = FMU2Slave(guid=description.guid, unzipDirectory=folder, instanceName="bare",
                     modelIdentifier=description.coSimulation.modelIdentifier)
    bare.instantiate()
    bare.freeInstance()                 # at once: nothing called between
    ports = {v.name for v in description.modelVariables if v.causality == "input"}
    signals = np.zeros(t.size, dtype=[("time", float)] + [(name, float) for name in sorted(ports)])
    signals["time"] = t
    for name in ports:
        signals[name] = 1e-3 * np.sin(40.0 * t)
    result = simulate_fmu(path, stop_time=t[-1], step_size=1e-3, input=signals)
    assert np.all(np.isfinite(result[result.dtype.names[1]]))
print("every FMU freed and run", flush=True)
"""


def run_hosts(fmus: dict, processes: int) -> list[tuple[int, str]]:
    """(exit code, the end of stderr) of each process that ran HOST on every FMU (each model's
    compiled step where numba is installed)."""
    env = {name: value for name, value in os.environ.items() if name != "BUSHING_FMU_STEP"}
    outcomes = []
    for _ in range(processes):
        done = subprocess.run([sys.executable, "-c", HOST, *map(str, fmus.values())], capture_output=True, text=True,
                              timeout=600, env=env)
        assert "every FMU freed and run" in done.stdout or done.returncode != 0, done.stderr[-2000:]
        outcomes.append((done.returncode, done.stderr[-300:]))
    return outcomes


@pytest.mark.slow
def test_a_python_host_frees_and_runs_every_models_pythonfmu_fmu_and_exits_cleanly(pythonfmu_model_fmus):
    outcomes = run_hosts(pythonfmu_model_fmus, 2)
    assert [code for code, _ in outcomes] == [0, 0], outcomes


@pytest.mark.slow
def test_fifty_python_hosts_free_and_run_every_models_pythonfmu_fmu_with_no_abort(pythonfmu_model_fmus):
    outcomes = run_hosts(pythonfmu_model_fmus, 50)
    failed = [outcome for outcome in outcomes if outcome[0] != 0]
    assert not failed, f"{len(failed)} of 50 processes failed: {failed[:3]}"
