"""The model core in plain Python, stepped like the FMU: the scalar path that tests compare the
FMU, the compiled kernel and independent references with.

Units: time in s, displacement in mm, velocity in mm/s, force in N, parameters in the
paper's N-mm-s units.
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from fmu_src.model.registry import get_model
from fmu_src.model.integration import DEFAULT_MAX_SUBSTEPS, OK, advance


def simulate_python_core(params: Mapping[str, float], time_s, displacement_mm, velocity_mm_s,
             substeps_per_sample: int = 1, model: str = "proposed") -> np.ndarray:
    """Force [N] at every sample time of the bushing ``model`` (``registry``) with ``params``,
    through ``integration.advance`` and the model's own kernels, as the FMU calls them.

    Between samples k and k+1 the displacement is x_k + v_k*(t - t_k) and the velocity v_k,
    exactly as in the FMU with communication points at the sample times (where x_{k+1}
    differs from x_k + v_k*h the model takes it as a displacement jump); the state starts in
    the relaxed equilibrium at x_0 (the model's ``initial_state``). ``substeps_per_sample``
    > 1 splits each interval into equal communication steps (for fine reference runs).
    """
    bushing = get_model(model)
    constants = bushing.constants(bushing.check(params))
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(displacement_mm, dtype=float)
    v = np.asarray(velocity_mm_s, dtype=float)
    if not (t.shape == x.shape == v.shape and t.ndim == 1):
        raise ValueError(f"time, displacement and velocity must be 1-D arrays of equal length, "
                         f"got shapes {t.shape}, {x.shape}, {v.shape}")
    state_x = float(x[0])
    state = bushing.initial_state(constants, state_x)
    forces = np.empty_like(t)
    forces[0] = bushing.force(constants, state, state_x, v[0])
    for k in range(t.size - 1):
        x_k, v_k = float(x[k]), float(v[k])
        h = (float(t[k + 1]) - float(t[k])) / substeps_per_sample
        for i in range(substeps_per_sample):
            state, _ = advance(bushing, constants, state, state_x, x_k + v_k * h * i, v_k, h)
            state_x = x_k + v_k * h * (i + 1)
        forces[k + 1] = bushing.force(constants, state, state_x, v_k)
    return forces


def run_coupled(model, params, path, step_s: float = 1e-3):
    """The coupled model's force vectors (samples - 1, 3) along ``path`` (samples, 2 or 3) [mm], one
    step of ``step_s`` [s] between samples."""
    kernels, m = model.coupled, model.constants(params)
    path = np.column_stack([path, np.zeros((len(path), 3 - path.shape[1]))])
    x0 = tuple(float(c) for c in path[0])
    state, state_x, out = kernels.initial_state(m, x0), x0, []
    for k in range(len(path) - 1):
        x = tuple(float(c) for c in path[k])
        v = tuple(float(c) for c in (path[k + 1] - path[k]) / step_s)
        state, _, status = kernels.step(m, state, state_x, x, v, step_s, DEFAULT_MAX_SUBSTEPS)
        assert status == OK
        state_x = tuple(x[i] + v[i] * step_s for i in range(3))
        out.append(kernels.force(m, state, state_x, v))
    return np.array(out)
