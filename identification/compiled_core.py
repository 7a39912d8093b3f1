"""The model core compiled with numba, for simulating whole populations of parameter sets.

One definition: the source of ``fmu_src/bushing_core.py`` is written, with the population
loop below appended, into a generated module in the cache folder (:func:`cache_directory`),
where its kernels (plain float arithmetic, errors as status codes) are replaced by
numba-compiled versions of themselves, so that they call each other compiled. The FMU runs
the same functions as plain Python; ``tests/test_compiled_core.py`` checks the two agree to
1e-9 (they are bitwise equal in practice). Compilation takes a few seconds on first use; numba
caches the machine code on disk, so later processes load it.

Units as in the core: mm, mm/s, N, s; parameters in the paper's N-mm-s units.
"""
from __future__ import annotations

import hashlib
import importlib.util
import inspect
import os
import sys
import types
import warnings
from pathlib import Path
from typing import Mapping

import numba
import numpy as np

from fmu_src import bushing_core as _core
from fmu_src.bushing_models import get_model
from fmu_src.bushing_params import PARAMETER_NAMES

_KERNELS = ("_decay_factors", "_rk4_in_xi", "_segment", "_block_step", "_gain_variation",
            "_substeps_needed", "_jump_kernel", "_integrate")
_I = {name: i for i, name in enumerate(PARAMETER_NAMES)}
CACHE_ENVIRONMENT = "BUSHING_CACHE_DIR"


def _population_forces(matrix, t, x, v, out_index, out_velocity, max_substeps):
    """Forces of every parameter set (rows of ``matrix``) at the communication points
    ``t[out_index]``; the input over [t_k, t_k+1] is x_k + v_k*(t - t_k), as in the FMU, and the
    force at an output point is eq. 5 with the velocity ``out_velocity`` (the FMU's direct
    feedthrough of the velocity set at that instant).

    Written here, never called here: its source is compiled in the generated module (see
    :func:`_load_compiled_module`), where ``_jump_kernel`` and ``_integrate`` are the core's
    compiled kernels and the parameter indices are constants."""
    count, samples, outputs = matrix.shape[0], t.size, out_index.size
    forces = np.full((count, outputs), np.nan)
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
        j = 0
        if out_index[0] == 0:
            # bushing_core.force: eq. 5 with eq. 4
            forces[i, 0] = p[_K0] * y + p[_C0] * ((p[_C2] * out_velocity[0] + p[_K2] * (state_x - w)
                                                    + p[_ALPHA2] * z2) / C)
            j = 1
        for k in range(samples - 1):
            if j == outputs:
                break
            h = t[k + 1] - t[k]
            status = _OK
            if x[k] != state_x:
                y, z1, w, z2, status = _jump_kernel(model, y, z1, w, z2, x[k] - state_x)
            if status == _OK:
                y, z1, w, z2, used, status = _integrate(model, y, z1, w, z2, x[k], v[k], h, max_substeps)
            if status != _OK:
                break  # this candidate failed: NaN from here on
            state_x = x[k] + v[k] * h
            if out_index[j] == k + 1:
                forces[i, j] = p[_K0] * y + p[_C0] * ((p[_C2] * out_velocity[j] + p[_K2] * (state_x - w)
                                                        + p[_ALPHA2] * z2) / C)
                j += 1
    return forces


def _compiled_source() -> str:
    """One module: the core's source, its kernels compiled, and the population loop. Generated
    as a file so that numba can cache the machine code on disk, and named after a hash of its
    content, so that a change to the core or to the loop compiles afresh (numba's cache checks
    only the file's own time stamp, not the sources of the functions a kernel calls)."""
    indices = "\n".join(f"_{name.upper()} = {index}" for name, index in _I.items())
    return (inspect.getsource(_core)
            + "\n\n# ---- appended by identification/compiled_core.py ----\n"
            + "import numba\nimport numpy as np\n\n"
            + "_OK = OK\n" + indices + "\n"
            # error_model="numpy": a division by zero gives inf/nan (caught as NOT_FINITE)
            # instead of an exception that would abort the whole population.
            + f"for _name in {_KERNELS!r}:\n"
            + "    globals()[_name] = numba.njit(error_model='numpy', cache=True)(globals()[_name])\n\n\n"
            + inspect.getsource(_population_forces)
            + "\n\n_simulate_population = numba.njit(error_model='numpy', parallel=True, cache=True)"
              "(_population_forces)\n")


def cache_directory() -> Path:
    """Where the generated module and numba's cache live: $BUSHING_CACHE_DIR, else
    $XDG_CACHE_HOME/boucwen-bushing, else ~/.cache/boucwen-bushing."""
    if os.environ.get(CACHE_ENVIRONMENT):
        return Path(os.environ[CACHE_ENVIRONMENT])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "boucwen-bushing"


def _load_compiled_module():
    source = _compiled_source()
    name = f"bushing_compiled_{hashlib.sha256(source.encode()).hexdigest()[:16]}"
    try:
        folder = cache_directory()
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{name}.py"
        if not path.is_file() or path.read_text() != source:
            # Written whole and renamed: worker processes start at once and must never read half a file.
            partial = path.with_suffix(f".{os.getpid()}.tmp")
            partial.write_text(source)
            os.replace(partial, path)
    except OSError as exc:
        warnings.warn(f"cannot write the compiled model's cache in {cache_directory()} ({exc}); compiling "
                      f"in memory at every start (set {CACHE_ENVIRONMENT} to a writable folder)", stacklevel=3)
        module = types.ModuleType(name)
        exec(compile(source.replace(", cache=True", ""), f"<{name}>", "exec"), module.__dict__)
        return module
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


_compiled = _load_compiled_module()
_jump_kernel = _compiled._jump_kernel
_integrate = _compiled._integrate
_simulate_population = _compiled._simulate_population
_OK = _core.OK
_C0, _K0, _C1, _K1, _C2, _K2 = _I["c0"], _I["k0"], _I["c1"], _I["k1"], _I["c2"], _I["k2"]
_ALPHA1, _ALPHA2, _BETA1, _BETA2 = _I["alpha1"], _I["alpha2"], _I["beta1"], _I["beta2"]
_GAMMA1, _GAMMA2, _N1, _N2, _A1, _A2 = _I["gamma1"], _I["gamma2"], _I["n1"], _I["n2"], _I["A1"], _I["A2"]


def simulate_population_held(parameter_sets, time_s, displacement_mm, velocity_mm_s,
                             max_substeps: int = _core.DEFAULT_MAX_SUBSTEPS) -> np.ndarray:
    """Forces [N], shape (P, samples), of P parameter sets under the FMU's input convention.

    The FMU with a communication point at every sample: over [t_k, t_k+1] the displacement is
    x_k + v_k*(t - t_k) and the velocity v_k held (a displacement jump where x_k+1 differs from
    x_k + v_k*h), and the force at t_k+1 is read before the next inputs are set (velocity v_k).
    This is what a co-simulation master sees; the identification's forward model
    (``identification.forward_model``) drives the same kernel with a finer, consistent input.
    ``parameter_sets`` is a (P, 16) array in ``PARAMETER_NAMES`` order or a sequence of
    mappings; the sets must be valid. A candidate whose step fails (overflow, non-finite
    state, too many substeps) gets NaN from that sample on. Runs on all cores.
    """
    t, x, v = _input_arrays(time_s, displacement_mm, velocity_mm_s)
    out_velocity = np.concatenate([v[:1], v[:-1]])
    return _simulate_population(parameter_matrix(parameter_sets), t, x, v, np.arange(t.size), out_velocity,
                                max_substeps)


def simulate_population_at(parameter_sets, time_s, displacement_mm, velocity_mm_s, output_index,
                           output_velocity_mm_s, max_substeps: int = _core.DEFAULT_MAX_SUBSTEPS) -> np.ndarray:
    """Forces [N], shape (P, outputs), at the communication points ``time_s[output_index]``
    (increasing), with the force's viscous feedthrough taken at ``output_velocity_mm_s``; the
    input between communication points as in :func:`simulate_population_held`."""
    t, x, v = _input_arrays(time_s, displacement_mm, velocity_mm_s)
    out_index = np.ascontiguousarray(output_index, dtype=np.int64)
    out_velocity = np.ascontiguousarray(output_velocity_mm_s, dtype=float)
    if not (out_index.ndim == 1 and out_index.size >= 1 and out_index.shape == out_velocity.shape
            and np.all(np.diff(out_index) > 0) and 0 <= out_index[0] and out_index[-1] < t.size):
        raise ValueError("output_index must be increasing indices into time_s, one output velocity each")
    return _simulate_population(parameter_matrix(parameter_sets), t, x, v, out_index, out_velocity, max_substeps)


def _input_arrays(time_s, displacement_mm, velocity_mm_s):
    t = np.ascontiguousarray(time_s, dtype=float)
    x = np.ascontiguousarray(displacement_mm, dtype=float)
    v = np.ascontiguousarray(velocity_mm_s, dtype=float)
    if not (t.ndim == 1 and t.shape == x.shape == v.shape and t.size >= 2):
        raise ValueError(f"time, displacement and velocity must be 1-D arrays of equal length >= 2, "
                         f"got shapes {t.shape}, {x.shape}, {v.shape}")
    return t, x, v


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


def simulate_model_held(model: str, params: Mapping[str, float], time_s, displacement_mm,
                        velocity_mm_s) -> np.ndarray:
    """Force [N] of one parameter set of any model of ``bushing_models`` (by name) under the
    FMU's input convention (:func:`simulate_population_held`): the core's force of the model's
    16 core parameters plus its constant force (preload). Raises ParameterError for an
    invalid set."""
    bushing = get_model(model)
    values = bushing.check(params)
    forces = simulate_population_held([bushing.core_parameters(values)], time_s, displacement_mm, velocity_mm_s)[0]
    return forces + bushing.force_offset(values)
