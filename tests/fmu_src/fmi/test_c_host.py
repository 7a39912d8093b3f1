"""Smoke test: the FMU loaded by a small C host (no Python host process), as a C/C++
co-simulation tool would load it. Skipped where no C compiler or shared libpython exists."""
import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description

from conftest import paper_parameters
from identification.measured.signals import Sine
from python_core import simulate_python_core

HOST_SOURCE = Path(__file__).resolve().parents[2] / "c_host" / "fmi2_host.c"


def shared_libpython() -> Path | None:
    if not sysconfig.get_config_var("Py_ENABLE_SHARED"):
        return None
    path = Path(sysconfig.get_config_var("LIBDIR")) / sysconfig.get_config_var("LDLIBRARY")
    return path if path.exists() else None


@pytest.mark.skipif(shutil.which("gcc") is None or shared_libpython() is None,
                    reason="needs gcc and a shared libpython")
def test_fmu_runs_in_a_c_host_with_libpython_preloaded(fmu_path, tmp_path):
    host = tmp_path / "fmi2_host"
    subprocess.run(["gcc", "-O1", "-o", str(host), str(HOST_SOURCE), "-ldl", "-lm"], check=True)
    description = read_model_description(str(fmu_path))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    unzipped = Path(extract(str(fmu_path)))
    library = unzipped / "binaries" / "linux64" / f"{description.coSimulation.modelIdentifier}.so"
    # The embedded interpreter needs this environment's packages (pythonfmu) on its path.
    environment = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p),
                       PYTHONHOME=sys.base_prefix)
    steps, h = 50, 1e-3
    result = subprocess.run([str(host), str(shared_libpython()), str(library), description.guid,
                             (unzipped / "resources").as_uri(), str(refs["x"]), str(refs["v"]), str(refs["F"]),
                             str(steps), str(h)], capture_output=True, text=True, env=environment, timeout=120)
    assert result.returncode == 0, result.stderr
    # numba-compiled kernels corrupted this host's heap (2026-11-23): a C host runs the Python step
    assert "pure-Python step: the host is not a Python interpreter" in result.stderr
    rows = np.array([[float(value) for value in line.split()] for line in result.stdout.splitlines()])
    t = np.arange(steps + 1) * h
    x, v = Sine(2.0, 10.0).signals(t)
    expected = simulate_python_core(paper_parameters("table5"), t, x, v)[1:]
    np.testing.assert_allclose(rows[:, 1], expected, rtol=1e-9, atol=1e-6)
