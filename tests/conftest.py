from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import build_fmu
from fmu_src import bushing_core as core
from fmu_src.parameter_files import load_parameters

REPO = Path(__file__).resolve().parents[1]
DATA = REPO / "data"


def paper_parameters(table: str) -> dict[str, float]:
    """The paper's parameter sets as shipped in data/: 'table2', 'table4' or 'table5'."""
    files = {"table2": "params_table2_sine.json", "table4": "params_table4_step.json",
             "table5": "params_table5_combined.json"}
    return load_parameters(DATA / files[table])


def reference_jump(params, state, jump_mm):
    """Independent reference for a displacement jump (an impulse in dx/dt): y moves with x,
    w by c2/(c0 + c2) of it, and z2 follows dz2/dxi = g2 over xi = c0/(c0 + c2)*jump,
    integrated by scipy's solve_ivp on the gain of eq. 2."""
    y, z1, w, z2 = state
    if jump_mm == 0.0:
        return np.array(state, dtype=float)
    damping = params["c0"] + params["c2"]
    xi = params["c0"] / damping * jump_mm
    gain = lambda _, z: [core.hysteretic_gain(z[0], xi, params["A2"], params["beta2"], params["gamma2"], params["n2"])]
    z2_end = solve_ivp(gain, (0.0, xi), [z2], rtol=1e-12, atol=1e-12).y[0, -1]
    return np.array([y + jump_mm, z1, w + params["c2"] / damping * jump_mm, z2_end])


def reference_force(params, time_s, x_mm, v_mm_s, rtol=1e-10, atol=1e-9):
    """Independent reference: scipy's Radau on eqs. 1-4 (``bushing_core.rhs``), restarted at
    every sample with the same piecewise-linear input as the FMU (x_k + v_k*t, with a
    displacement jump where x_k differs from the previous step's end)."""
    state = np.array(core.initial_state(params, x_mm[0]))
    state_x = x_mm[0]
    forces = [core.force(state, x_mm[0], v_mm_s[0], params)]
    for k in range(len(time_s) - 1):
        h = time_s[k + 1] - time_s[k]
        state = reference_jump(params, state, x_mm[k] - state_x)
        solution = solve_ivp(core.rhs, (0.0, h), state, method="Radau", args=(x_mm[k], v_mm_s[k], params),
                             rtol=rtol, atol=atol)
        assert solution.success, solution.message
        state = solution.y[:, -1]
        state_x = x_mm[k] + v_mm_s[k] * h
        forces.append(core.force(state, state_x, v_mm_s[k], params))
    return np.array(forces)


@pytest.fixture(scope="session")
def fmu_path(tmp_path_factory) -> Path:
    """The FMU built with the default parameters (Table 5)."""
    return build_fmu.build_fmu(out_dir=tmp_path_factory.mktemp("fmu_table5"))


@pytest.fixture(scope="session")
def fmu_path_table2(tmp_path_factory) -> Path:
    """An FMU built with the paper's Table 2 as default parameters."""
    return build_fmu.build_fmu(DATA / "params_table2_sine.json", tmp_path_factory.mktemp("fmu_table2"))
