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


def paper_equations(t, state, p, displacement, velocity):
    """Eqs. 1-4 of the paper, typed from the paper once more, independently of ``fmu_src``:
    d/dt of (y, z1, w, z2) for the input functions ``displacement(t)`` [mm] and
    ``velocity(t)`` [mm/s], parameters ``p`` in N-mm-s units."""
    y, z1, w, z2 = state
    x, xd = displacement(t), velocity(t)
    yd = (p["c1"] * xd + p["k1"] * (x - y) - p["k0"] * y + p["alpha1"] * z1) / p["c1"]      # eq. 3
    wd = (p["c2"] * xd + p["k2"] * (x - w) + p["alpha2"] * z2) / (p["c0"] + p["c2"])       # eq. 4
    z1d = (xd - yd) * (p["A1"] - (p["gamma1"] + p["beta1"] * np.sign(xd - yd) * np.sign(z1))
                       * abs(z1) ** p["n1"])                                                 # eq. 1
    z2d = (xd - wd) * (p["A2"] - (p["gamma2"] + p["beta2"] * np.sign(xd - wd) * np.sign(z2))
                       * abs(z2) ** p["n2"])                                                 # eq. 2
    return [yd, z1d, wd, z2d]


def paper_force(p, time_s, displacement, velocity, rtol=1e-10, atol=1e-10):
    """Eq. 5, F = k0*y + c0*dw/dt [N], at ``time_s`` for a smooth input given as functions of
    time, from scipy's Radau on :func:`paper_equations`, starting in relaxed equilibrium at
    x(0) (y = k1*x/(k0 + k1), w = x, z = 0)."""
    x0 = displacement(time_s[0])
    start = [p["k1"] * x0 / (p["k0"] + p["k1"]), 0.0, x0, 0.0]
    solution = solve_ivp(paper_equations, (time_s[0], time_s[-1]), start, method="Radau", t_eval=time_s,
                         args=(p, displacement, velocity), rtol=rtol, atol=atol)
    assert solution.success, solution.message
    y, _, w, z2 = solution.y
    x, xd = displacement(time_s), velocity(time_s)
    wd = (p["c2"] * xd + p["k2"] * (x - w) + p["alpha2"] * z2) / (p["c0"] + p["c2"])
    return p["k0"] * y + p["c0"] * wd


@pytest.fixture(scope="session")
def fmu_path(tmp_path_factory) -> Path:
    """The FMU built with the default parameters (Table 5)."""
    return build_fmu.build_fmu(out_dir=tmp_path_factory.mktemp("fmu_table5"))


@pytest.fixture(scope="session")
def fmu_path_table2(tmp_path_factory) -> Path:
    """An FMU built with the paper's Table 2 as default parameters."""
    return build_fmu.build_fmu(DATA / "params_table2_sine.json", tmp_path_factory.mktemp("fmu_table2"))
