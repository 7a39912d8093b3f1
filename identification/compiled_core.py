"""The bushing models compiled with numba, for simulating whole populations of parameter sets.

One definition. For each model, the source of its module (``fmu_src/<name>_model.py``) is
written, with the population loop below appended, into a generated module in the cache folder
(:func:`cache_directory`), where its kernels are replaced by numba-compiled versions of
themselves; its imports of the shared machinery (``fmu_src/integration.py``) are pointed at a
generated module of that machinery, compiled the same way, so that every kernel calls the
others compiled. The FMU runs the same functions as plain Python;
``tests/test_compiled_core.py`` checks the two agree bitwise for every model. Compilation
takes a few seconds on a model's first use; numba caches the machine code on disk, so later
processes load it.

Units as in the models: mm, mm/s, N, s; parameters in the paper's N-mm-s units, each model's
own in its spec order (``parameter_matrix``).
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

from fmu_src import integration
from fmu_src.bushing_models import get_model
from fmu_src.proposed_model import PARAMETER_NAMES  # noqa: F401  (the proposed model's order, for callers)

CACHE_ENVIRONMENT = "BUSHING_CACHE_DIR"
_MAX_SUBSTEPS = integration.DEFAULT_MAX_SUBSTEPS


def _population_forces(matrix, t, x, v, out_index, out_velocity, max_substeps):
    """Forces of every parameter set (rows of ``matrix``) at the communication points
    ``t[out_index]``; the input over [t_k, t_k+1] is x_k + v_k*(t - t_k), as in the FMU, and the
    force at an output point is the model's force with the velocity ``out_velocity`` (the FMU's
    direct feedthrough of the velocity set at that instant).

    Written here, never called here: its source is compiled in each model's generated module
    (see :func:`_model_source`), where ``prepare`` ... ``force`` are that model's compiled
    kernels and ``_VALUES(row)`` the row's values as the tuple ``prepare`` takes."""
    count, samples, outputs = matrix.shape[0], t.size, out_index.size
    forces = np.full((count, outputs), np.nan)
    for i in numba.prange(count):
        row = matrix[i]
        m = prepare(_VALUES(row))
        state_x = x[0]
        state = initial_state(m, state_x)
        j = 0
        if out_index[0] == 0:
            forces[i, 0] = force(m, state, state_x, out_velocity[0])
            j = 1
        for k in range(samples - 1):
            if j == outputs:
                break
            h = t[k + 1] - t[k]
            status = _OK
            if x[k] != state_x:
                state, status = jump(m, state, x[k] - state_x)
            if status == _OK:
                state, used, status = integrate(m, state, x[k], v[k], h, max_substeps)
            if status != _OK:
                break  # this candidate failed: NaN from here on
            state_x = x[k] + v[k] * h
            if out_index[j] == k + 1:
                forces[i, j] = force(m, state, state_x, out_velocity[j])
                j += 1
    return forces


_JIT_KERNELS = (
    # error_model="numpy": a division by zero gives inf/nan (caught as NOT_FINITE) instead of an
    # exception that would abort the whole population.
    "for _name in KERNELS:\n"
    "    globals()[_name] = numba.njit(error_model='numpy', cache=True)(globals()[_name])\n")


def _integration_source() -> str:
    """The shared machinery, its kernels compiled."""
    return inspect.getsource(integration) + "\n\n# ---- appended by identification/compiled_core.py ----\n" \
        + "import numba\n\n" + _JIT_KERNELS


def _model_source(model_name: str, integration_module: str) -> str:
    """One model's module, its kernels compiled, and the population loop. Its relative imports
    point at the package (plain Python: specs, checks) and at the compiled machinery."""
    bushing = get_model(model_name)
    source = inspect.getsource(sys.modules[bushing.kernel_module])
    source = source.replace("from .integration import", f"from {integration_module} import")
    source = source.replace("from .", "from fmu_src.")
    values = ", ".join(f"row[{i}]" for i in range(len(bushing.specs)))
    return (source + "\n\n# ---- appended by identification/compiled_core.py ----\n"
            + f"import numba\nimport numpy as np\nfrom {integration_module} import OK as _OK\n\n"
            + _JIT_KERNELS + "\n\n"
            + f"@numba.njit(cache=True)\ndef _VALUES(row):\n    return ({values},)\n\n\n"
            + inspect.getsource(_population_forces)
            + "\n\n_simulate_population = numba.njit(error_model='numpy', parallel=True, cache=True)"
              "(_population_forces)\n")


def cache_directory() -> Path:
    """Where the generated modules and numba's cache live: $BUSHING_CACHE_DIR, else
    $XDG_CACHE_HOME/boucwen-bushing, else ~/.cache/boucwen-bushing."""
    if os.environ.get(CACHE_ENVIRONMENT):
        return Path(os.environ[CACHE_ENVIRONMENT])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "boucwen-bushing"


def _module_name(prefix: str, source: str) -> str:
    """Named after a hash of the content, so that a change to a model, to the machinery or to
    the loop compiles afresh (numba's cache checks only the file's own time stamp, not the
    sources of the functions a kernel calls; a model's source names the machinery's hash)."""
    return f"{prefix}_{hashlib.sha256(source.encode()).hexdigest()[:16]}"


def _load_generated(name: str, source: str):
    if name in sys.modules:
        return sys.modules[name]
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
                      f"in memory at every start (set {CACHE_ENVIRONMENT} to a writable folder)", stacklevel=4)
        module = types.ModuleType(name)
        sys.modules[name] = module
        exec(compile(source.replace(", cache=True", "").replace("(cache=True)", "()"), f"<{name}>", "exec"),
             module.__dict__)
        return module
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


_compiled_models: dict[str, types.ModuleType] = {}


def compiled_model(model: str = "proposed") -> types.ModuleType:
    """The generated, compiled module of ``model`` (loaded on first use)."""
    name = get_model(model).name
    if name not in _compiled_models:
        machinery_source = _integration_source()
        machinery = _module_name("bushing_integration", machinery_source)
        _load_generated(machinery, machinery_source)
        source = _model_source(name, machinery)
        _compiled_models[name] = _load_generated(_module_name(f"bushing_{name}", source), source)
    return _compiled_models[name]


def simulate_population_held(parameter_sets, time_s, displacement_mm, velocity_mm_s,
                             max_substeps: int = _MAX_SUBSTEPS, model: str = "proposed") -> np.ndarray:
    """Forces [N], shape (P, samples), of P parameter sets of ``model`` under the FMU's input
    convention.

    The FMU with a communication point at every sample: over [t_k, t_k+1] the displacement is
    x_k + v_k*(t - t_k) and the velocity v_k held (a displacement jump where x_k+1 differs from
    x_k + v_k*h), and the force at t_k+1 is read before the next inputs are set (velocity v_k).
    This is what a co-simulation master sees; the identification's forward model
    (``identification.forward_model``) drives the same kernel with a finer, consistent input.
    ``parameter_sets``: see :func:`parameter_matrix`; the sets must be valid. A candidate whose
    step fails (overflow, non-finite state, too many substeps) gets NaN from that sample on.
    Runs on all cores.
    """
    t, x, v = _input_arrays(time_s, displacement_mm, velocity_mm_s)
    out_velocity = np.concatenate([v[:1], v[:-1]])
    return compiled_model(model)._simulate_population(parameter_matrix(parameter_sets, model), t, x, v,
                                                      np.arange(t.size), out_velocity, max_substeps)


def simulate_population_at(parameter_sets, time_s, displacement_mm, velocity_mm_s, output_index,
                           output_velocity_mm_s, max_substeps: int = _MAX_SUBSTEPS,
                           model: str = "proposed") -> np.ndarray:
    """Forces [N], shape (P, outputs), at the communication points ``time_s[output_index]``
    (increasing), with the force's viscous feedthrough taken at ``output_velocity_mm_s``; the
    input between communication points as in :func:`simulate_population_held`."""
    t, x, v = _input_arrays(time_s, displacement_mm, velocity_mm_s)
    out_index = np.ascontiguousarray(output_index, dtype=np.int64)
    out_velocity = np.ascontiguousarray(output_velocity_mm_s, dtype=float)
    if not (out_index.ndim == 1 and out_index.size >= 1 and out_index.shape == out_velocity.shape
            and np.all(np.diff(out_index) > 0) and 0 <= out_index[0] and out_index[-1] < t.size):
        raise ValueError("output_index must be increasing indices into time_s, one output velocity each")
    return compiled_model(model)._simulate_population(parameter_matrix(parameter_sets, model), t, x, v, out_index,
                                                      out_velocity, max_substeps)


def _input_arrays(time_s, displacement_mm, velocity_mm_s):
    t = np.ascontiguousarray(time_s, dtype=float)
    x = np.ascontiguousarray(displacement_mm, dtype=float)
    v = np.ascontiguousarray(velocity_mm_s, dtype=float)
    if not (t.ndim == 1 and t.shape == x.shape == v.shape and t.size >= 2):
        raise ValueError(f"time, displacement and velocity must be 1-D arrays of equal length >= 2, "
                         f"got shapes {t.shape}, {x.shape}, {v.shape}")
    return t, x, v


def parameter_matrix(parameter_sets, model: str = "proposed") -> np.ndarray:
    """(P, m) float array of P parameter sets of ``model`` in its parameter order (its specs'),
    from a sequence of mappings or an array."""
    names = get_model(model).parameter_names
    if isinstance(parameter_sets, np.ndarray):
        matrix = np.atleast_2d(np.asarray(parameter_sets, dtype=float))
    else:
        matrix = np.array([[float(p[name]) for name in names] for p in parameter_sets])
    if matrix.ndim != 2 or matrix.shape[1] != len(names):
        raise ValueError(f"expected a (P, {len(names)}) parameter matrix of the {get_model(model).name} model "
                         f"in the order {', '.join(names)}, got shape {matrix.shape}")
    return np.ascontiguousarray(matrix)


def simulate_model_held(model: str, params: Mapping[str, float], time_s, displacement_mm,
                        velocity_mm_s) -> np.ndarray:
    """Force [N] of one parameter set of any model of ``bushing_models`` (by name) under the
    FMU's input convention (:func:`simulate_population_held`). Raises ParameterError for an
    invalid set."""
    values = get_model(model).check(params)
    return simulate_population_held([values], time_s, displacement_mm, velocity_mm_s, model=model)[0]
