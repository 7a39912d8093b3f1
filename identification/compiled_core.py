"""The model core compiled with numba, for simulating whole populations of parameter sets.

One definition: the source of ``fmu_src/bushing_core.py`` is executed into a private
namespace and its kernels (plain float arithmetic, errors as status codes) are replaced by
numba-compiled versions of themselves, so that they call each other compiled. The FMU runs
the same functions as plain Python; ``tests/test_compiled_core.py`` checks the two agree to
1e-9 (they are bitwise equal in practice). Compilation takes a few seconds on first use.

Units as in the core: mm, mm/s, N, s; parameters in the paper's N-mm-s units.
"""
from __future__ import annotations

import inspect
from typing import Mapping

import numba
import numpy as np

from fmu_src import bushing_core as _core
from fmu_src.bushing_models import get_model
from fmu_src.bushing_params import PARAMETER_NAMES

_KERNELS = ("_decay_factors", "_rk4_in_xi", "_segment", "_block_step", "_gain_variation",
            "_substeps_needed", "_jump_kernel", "_integrate")


def _compile_core():
    namespace = {"__name__": "bushing_core_compiled"}
    exec(compile(inspect.getsource(_core), _core.__file__, "exec"), namespace)
    for name in _KERNELS:
        # error_model="numpy": a division by zero gives inf/nan (caught as NOT_FINITE)
        # instead of an exception that would abort the whole population.
        namespace[name] = numba.njit(error_model="numpy")(namespace[name])
    return namespace


_compiled = _compile_core()
_jump_kernel = _compiled["_jump_kernel"]
_integrate = _compiled["_integrate"]
_OK = _core.OK
_I = {name: i for i, name in enumerate(PARAMETER_NAMES)}
_C0, _K0, _C1, _K1, _C2, _K2 = _I["c0"], _I["k0"], _I["c1"], _I["k1"], _I["c2"], _I["k2"]
_ALPHA1, _ALPHA2, _BETA1, _BETA2 = _I["alpha1"], _I["alpha2"], _I["beta1"], _I["beta2"]
_GAMMA1, _GAMMA2, _N1, _N2, _A1, _A2 = _I["gamma1"], _I["gamma2"], _I["n1"], _I["n2"], _I["A1"], _I["A2"]


@numba.njit(error_model="numpy", parallel=True)
def _simulate_population(matrix, t, x, v, max_substeps):
    count, samples = matrix.shape[0], t.size
    forces = np.full((count, samples), np.nan)
    for i in numba.prange(count):
        p = matrix[i]
        C = p[_C0] + p[_C2]
        K1 = p[_K0] + p[_K1]
        # The tuple layout of bushing_core.compile_model (CompiledModel and its _Blocks).
        model = (p[_K0], p[_K1], p[_K2], p[_C0], p[_C1], C, K1, p[_ALPHA1], p[_ALPHA2],
                 (K1, p[_ALPHA1], p[_C1], p[_A1], p[_BETA1], p[_GAMMA1], p[_N1]),
                 (p[_K2], p[_ALPHA2], C, p[_A2], p[_BETA2], p[_GAMMA2], p[_N2]))
        state_x = x[0]
        y = p[_K1] * state_x / K1 if K1 > 0.0 else state_x  # bushing_core.initial_state
        z1, w, z2 = 0.0, state_x, 0.0
        forces[i, 0] = p[_K0] * y + p[_C0] * ((p[_C2] * v[0] + p[_K2] * (state_x - w) + p[_ALPHA2] * z2) / C)
        for k in range(samples - 1):
            h = t[k + 1] - t[k]
            status = _OK
            if x[k] != state_x:
                y, z1, w, z2, status = _jump_kernel(model, y, z1, w, z2, x[k] - state_x)
            if status == _OK:
                y, z1, w, z2, used, status = _integrate(model, y, z1, w, z2, x[k], v[k], h, max_substeps)
            if status != _OK:
                break  # this candidate failed: NaN from here on
            state_x = x[k] + v[k] * h
            # bushing_core.force: eq. 5 with eq. 4
            forces[i, k + 1] = p[_K0] * y + p[_C0] * ((p[_C2] * v[k] + p[_K2] * (state_x - w) + p[_ALPHA2] * z2) / C)
    return forces


def simulate_population(parameter_sets, time_s, displacement_mm, velocity_mm_s,
                        max_substeps: int = _core.DEFAULT_MAX_SUBSTEPS) -> np.ndarray:
    """Forces [N], shape (P, samples), of P parameter sets on one sampled input.

    The same convention as ``identification.simulate.simulate`` and the FMU with a
    communication point at every sample. ``parameter_sets`` is a (P, 16) array in
    ``PARAMETER_NAMES`` order or a sequence of mappings; the sets must be valid
    (``bushing_params.validate_parameters``). A candidate whose step fails (overflow,
    non-finite state, too many substeps) gets NaN from that sample on. Runs on all cores.
    """
    matrix = parameter_matrix(parameter_sets)
    t = np.ascontiguousarray(time_s, dtype=float)
    x = np.ascontiguousarray(displacement_mm, dtype=float)
    v = np.ascontiguousarray(velocity_mm_s, dtype=float)
    if not (t.ndim == 1 and t.shape == x.shape == v.shape and t.size >= 2):
        raise ValueError(f"time, displacement and velocity must be 1-D arrays of equal length >= 2, "
                         f"got shapes {t.shape}, {x.shape}, {v.shape}")
    return _simulate_population(matrix, t, x, v, max_substeps)


def parameter_matrix(parameter_sets) -> np.ndarray:
    """(P, 16) float array in PARAMETER_NAMES order from a sequence of mappings or an array."""
    if isinstance(parameter_sets, np.ndarray):
        matrix = np.atleast_2d(np.asarray(parameter_sets, dtype=float))
    else:
        matrix = np.array([[float(p[name]) for name in PARAMETER_NAMES] for p in parameter_sets])
    if matrix.ndim != 2 or matrix.shape[1] != len(PARAMETER_NAMES):
        raise ValueError(f"expected a (P, {len(PARAMETER_NAMES)}) parameter matrix "
                         f"in the order {', '.join(PARAMETER_NAMES)}, got shape {matrix.shape}")
    return np.ascontiguousarray(matrix)


def simulate_model(model: str, params: Mapping[str, float], time_s, displacement_mm,
                   velocity_mm_s) -> np.ndarray:
    """Force [N] of one parameter set of any model of ``bushing_models`` (by name) on one
    sampled input: the core's force of the model's 16 core parameters plus its constant
    force (preload). Raises ParameterError for an invalid set."""
    bushing = get_model(model)
    values = bushing.check(params)
    forces = simulate_population([bushing.core_parameters(values)], time_s, displacement_mm, velocity_mm_s)[0]
    return forces + bushing.force_offset(values)
