"""The FMU's compiled step (numba) against its pure-Python step: the same forces to 1e-12, and the
FMU says which one runs."""
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import REPO

RUN = """
import sys, numpy as np
from fmpy import read_model_description, simulate_fmu
path, out = sys.argv[1], sys.argv[2]
description = read_model_description(path)
inputs = [v.name for v in description.modelVariables if v.causality == "input"]
outputs = [v.name for v in description.modelVariables if v.causality == "output"]
t = np.arange(0.0, 0.3, 1e-3)
rng = np.random.default_rng(3)
columns = []
for i, name in enumerate(inputs):
    scale = 0.05 if name in ("rx", "ry", "rz", "wx", "wy", "wz") else 2e-3
    columns.append(scale * np.sin(2 * np.pi * (3 + 4 * i) * t + rng.uniform(0, 6)))
table = np.array(list(zip(t, *columns)), dtype=[("time", float)] + [(n, float) for n in inputs])
messages = []
result = simulate_fmu(path, stop_time=t[-1], step_size=1e-3, input=table, output=outputs, debug_logging=True,
                      logger=lambda *args: messages.append(args[-1].decode() if isinstance(args[-1], bytes) else str(args[-1])))
np.save(out, np.column_stack([result[n] for n in outputs]))
print(next(m for m in messages if "step" in m and ("compiled" in m or "pure-Python" in m)))
"""


def run(fmu, out, step=None):
    environment = dict(os.environ, PYTHONPATH=str(REPO))
    environment.pop("BUSHING_FMU_STEP", None)
    if step:
        environment["BUSHING_FMU_STEP"] = step
    result = subprocess.run([sys.executable, "-c", RUN, str(fmu), str(out)], env=environment, capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    return np.load(out), result.stdout


@pytest.mark.parametrize("which", ["one_axis", "six_axis"])
def test_compiled_and_pure_python_steps_give_the_same_outputs(which, fmu_path, tmp_path):
    if which == "six_axis":
        import build_fmu
        fmu = build_fmu.build_fmu(out_dir=tmp_path / "six", model="six_axis")
    else:
        fmu = fmu_path
    compiled, said = run(fmu, tmp_path / "compiled.npy")
    plain, said_plain = run(fmu, tmp_path / "plain.npy", "python")
    assert "compiled step (numba)" in said and "pure-Python step (BUSHING_FMU_STEP=python)" in said_plain
    np.testing.assert_allclose(compiled, plain, rtol=1e-12, atol=1e-12 * np.max(np.abs(plain)))
    assert np.max(np.abs(plain)) > 10.0
