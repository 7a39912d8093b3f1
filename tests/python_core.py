"""The model core in plain Python, stepped like the FMU: the scalar path that tests compare the
FMU, the compiled kernel and independent references with.

Units: time in s, displacement in mm, velocity in mm/s, force in N, parameters in the
paper's N-mm-s units.
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from fmu_src.model.registry import get_model
from fmu_src.model.integration import advance


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
