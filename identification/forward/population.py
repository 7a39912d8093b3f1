"""The bushing models compiled with numba, for simulating whole populations of parameter sets.

One definition. Each model's own source (``fmu_src/models/<name>_model.py``) is compiled by
``fmu_src/kernels/numba_binding.py`` (a generated module named after its content, in the cache
folder, its kernels and the shared machinery compiled: ``kernel_module``); the population loops
below are compiled in a generated module of their own that imports the kernels from it. The FMU
runs the same functions, as plain Python or compiled in that same module;
``tests/fmu_src/kernels/test_compiled_core.py`` checks the two agree bitwise for every model. Compilation
takes a few seconds on a model's first use; numba caches the machine code on disk, so later
processes load it.

Units as in the models: mm, mm/s, N, s; parameters in the paper's N-mm-s units, each model's
own in its spec order (``parameter_matrix``). ``model``: a ``BushingModel`` (what the front door
resolved and passes on) or a model's name.
"""
from __future__ import annotations

import inspect
import math
import types
from dataclasses import dataclass
from typing import Mapping

from fmu_src.kernels.jit import numba
import numpy as np

from fmu_src.kernels import numba_binding as _kernels
from fmu_src.model import integration
from fmu_src.model.registry import BushingModel, DEFAULT_BUSHING, required_model, resolve_model
from identification.forward import steady_state

_MAX_SUBSTEPS = integration.DEFAULT_MAX_SUBSTEPS


def _population_loop(matrix, seeds, t, x, v, out_index, out_velocity, max_substeps, step_sizes, step_size_index,
                     rest_force):
    """Forces (P, outputs) of every parameter set (rows of ``matrix``) at the communication points
    ``t[out_index]``, and what the loop carries beside them: their derivatives (P, outputs, K) in
    the K directions ``seeds`` (P, m, K: dp/dtheta of each row) for the fit's Jacobian
    (``parameter_jacobian``), nothing (K = 0) for the forces alone. The input over [t_k, t_k+1] is
    x_k + v_k*(t - t_k), as in the FMU, and the force at an output point is the model's force
    with the velocity ``out_velocity`` (the FMU's direct feedthrough of the velocity set at that
    instant). ``step_sizes``: the distinct t_k+1 - t_k, and ``step_size_index[k]`` which one step
    k has: the step's constants (``prepare_step``) are made once per candidate and step size
    (empty: at every step). Each candidate starts at rest holding ``rest_force`` [N] where that is a
    number (the model's ``resting_state``, for a model that has one), else relaxed (NaN). A
    candidate that fails gets NaN from there on.

    Written here, never called here: its source is compiled in a generated module for each
    model, where its slots are bound to what it carries. Each slot returns a value and its derivative:
    ``_PREPARE(values, d_values)``, ``_INITIAL(m, x0, rest_force, d_m)`` (``integration.start_state``), ``_PREPARE_STEP(m, h, d_m)``,
    ``_STEP(m, ms, state, state_x, x, v, h, max_substeps, d_m, d_ms, d_state)`` (the step
    protocol, ``integration.step_prepared``), ``_FORCE(m, state, x, v, d_m, d_state)``;
    ``_VALUES(row)`` is the row as ``prepare``'s tuple, ``_SEEDS(seeds, i)`` row i's derivatives in
    the same layout and ``_STORE(out, i, j, d)`` stores a force's. The forces alone
    (:func:`_population_source`) bind the model's kernels with empty derivatives; the
    Jacobian's bind their generated tangents (``parameter_jacobian``). The forces are the same bits."""
    count, samples, outputs = matrix.shape[0], t.size, out_index.size
    forces = np.full((count, outputs), np.nan)
    sensitivities = np.full((count, outputs, seeds.shape[2]), np.nan)
    cached = step_sizes.size > 0
    for i in numba.prange(count):
        m, d_m = _PREPARE(_VALUES(matrix[i]), _SEEDS(seeds, i))
        prepared = [_PREPARE_STEP(m, step_sizes[u] if cached else t[1] - t[0], d_m)
                    for u in range(max(step_sizes.size, 1))]
        state_x = x[0]
        state, d_state = _INITIAL(m, state_x, rest_force, d_m)
        j = 0
        if out_index[0] == 0:
            f, d_f = _FORCE(m, state, state_x, out_velocity[0], d_m, d_state)
            forces[i, 0] = f
            _STORE(sensitivities, i, 0, d_f)
            j = 1
        for k in range(samples - 1):
            if j == outputs:
                break
            h = t[k + 1] - t[k]
            if cached:
                ms, d_ms = prepared[step_size_index[k]]
            else:
                ms, d_ms = _PREPARE_STEP(m, h, d_m)
            result, d_result = _STEP(m, ms, state, state_x, x[k], v[k], h, max_substeps, d_m, d_ms, d_state)
            state, used, status = result
            d_state = d_result[0]
            if status != _OK:
                break  # this candidate failed: NaN from here on
            state_x = x[k] + v[k] * h
            if out_index[j] == k + 1:
                f, d_f = _FORCE(m, state, state_x, out_velocity[j], d_m, d_state)
                forces[i, j] = f
                _STORE(sensitivities, i, j, d_f)
                j += 1
    return forces, sensitivities


# The forces alone: the loop's slots bound to the model's kernels, carrying no derivative.
def _PREPARE(values, d_values):
    return prepare(values), ()  # noqa: F821 (the model's, where bound)


def _INITIAL(m, x0, rest_force, d_m):
    return start_state(m, x0, rest_force), ()  # noqa: F821


def _PREPARE_STEP(m, h, d_m):
    return prepare_step(m, h), ()  # noqa: F821


def _STEP(m, ms, state, state_x, x, v, h, max_substeps, d_m, d_ms, d_state):
    return step_prepared(m, ms, state, state_x, x, v, h, max_substeps), ((),)  # noqa: F821


def _FORCE(m, state, x, v, d_m, d_state):
    return force(m, state, x, v), ()  # noqa: F821


def _SEEDS(seeds, i):
    return ()


def _STORE(out, i, j, d):
    pass


FORCES_ONLY = (_PREPARE, _INITIAL, _PREPARE_STEP, _STEP, _FORCE, _SEEDS, _STORE)
"""The population loop's slots for the forces alone (:func:`_population_loop`)."""


def _coupled_population_forces(matrix, t, x, v, out_index, out_velocity, max_substeps):
    """Force vectors (P, outputs, 3) of every parameter set (rows of ``matrix``) at the communication
    points ``t[out_index]`` on the path ``x`` (points, 3) [mm], the model's coupled form under the
    FMU's input convention: over [t_k, t_k+1] the displacement x_k + v_k*(t - t_k) with ``v``
    (points, 3) the step's velocity; the force at an output point with the velocity ``out_velocity``
    (outputs, 3) (the viscous feedthrough); relaxed at x_0. NaN from where a candidate fails.

    Written here, never called here: compiled in a coupled model's generated module, where
    ``initial_state_coupled``, ``step_coupled`` and ``force_coupled`` are its compiled kernels."""
    count, samples, outputs = matrix.shape[0], t.size, out_index.size
    forces = np.full((count, outputs, 3), np.nan)
    for i in numba.prange(count):
        m = prepare(_VALUES(matrix[i]))
        state_x = (x[0, 0], x[0, 1], x[0, 2])
        state = initial_state_coupled(m, state_x)
        j = 0
        if out_index[0] == 0:
            f = force_coupled(m, state, state_x, (out_velocity[0, 0], out_velocity[0, 1], out_velocity[0, 2]))
            forces[i, 0, 0], forces[i, 0, 1], forces[i, 0, 2] = f[0], f[1], f[2]
            j = 1
        for k in range(samples - 1):
            if j == outputs:
                break
            h = t[k + 1] - t[k]
            position = (x[k, 0], x[k, 1], x[k, 2])
            velocity = (v[k, 0], v[k, 1], v[k, 2])
            state, used, status = step_coupled(m, state, state_x, position, velocity, h, max_substeps)
            if status != _OK:
                break
            state_x = (position[0] + velocity[0] * h, position[1] + velocity[1] * h, position[2] + velocity[2] * h)
            if out_index[j] == k + 1:
                f = force_coupled(m, state, state_x, (out_velocity[j, 0], out_velocity[j, 1], out_velocity[j, 2]))
                forces[i, j, 0], forces[i, j, 1], forces[i, j, 2] = f[0], f[1], f[2]
                j += 1
    return forces


KERNELS = ("prepare", "initial_state", "start_state", "prepare_step", "step_prepared", "force", "_VALUES")
"""What the population loops take from a model's compiled module (``numba_binding.kernel_module``;
``_VALUES(row)``: the row's values as the tuple ``prepare`` takes)."""
COUPLED_KERNELS = ("initial_state_coupled", "step_coupled", "force_coupled")
"""What the coupled population loop takes besides, from a coupled model's."""


def _population_source(model) -> str:
    """The population loops for ``model``, as the source of a module of their own: the forces-only
    slots, ``_simulate_population``, ``_sine_steady_state`` (``identification.forward.steady_state``)
    and for a coupled model ``_simulate_coupled_population``; the kernels imported from the model's
    compiled module, which the FMU runs too (one compiled copy of them)."""
    kernels = (*KERNELS, *(COUPLED_KERNELS if model.coupled is not None else ()))
    return ("import math\nimport numpy as np\nfrom " + _kernels.integration_module() + " import OK as _OK\n"
            + f"from {_kernels.kernel_module(model).__name__} import {', '.join(kernels)}\n\n\n"
            + "".join(inspect.getsource(slot) + "\n\n" for slot in FORCES_ONLY)
            + "".join(f"{slot.__name__} = {_kernels.INNER_JIT}({slot.__name__})\n"
                      for slot in FORCES_ONLY)
            + "\n\n" + inspect.getsource(_population_loop)
            + "\n\n_simulate_population = numba.njit(error_model='numpy', parallel=True, cache=True)"
              "(_population_loop)\n\n\n"
            + f"ROUNDING = {steady_state.ROUNDING!r}\n\n\n"
            + inspect.getsource(steady_state._sine_steady_state)
            + "\n\n_sine_steady_state = numba.njit(error_model='numpy', parallel=True, cache=True)"
              "(_sine_steady_state)\n"
            + ("\n\n" + inspect.getsource(_coupled_population_forces)
               + "\n\n_simulate_coupled_population = numba.njit(error_model='numpy', parallel=True, cache=True)"
                 "(_coupled_population_forces)\n" if model.coupled is not None else ""))


def _forces(module, matrix, *arguments) -> np.ndarray:
    """The population loop's forces, carrying no derivative."""
    return module._simulate_population(matrix, np.empty((matrix.shape[0], matrix.shape[1], 0)), *arguments)[0]


_compiled_models: dict[str, types.ModuleType] = {}


def compiled_model(model: BushingModel = DEFAULT_BUSHING) -> types.ModuleType:
    """The generated, compiled module of ``model``'s population loops (loaded on first use)."""
    bushing = required_model(model)
    if bushing.name not in _compiled_models:
        source = _population_source(bushing)
        _compiled_models[bushing.name] = _kernels.load_generated(
            _kernels.module_name(f"bushing_population_{bushing.name}", source), source)
    return _compiled_models[bushing.name]


def simulate_population_held(parameter_sets, time_s, displacement_mm, velocity_mm_s,
                             max_substeps: int = _MAX_SUBSTEPS,
                             model: BushingModel = DEFAULT_BUSHING, rest_force_N: float = math.nan) -> np.ndarray:
    """Forces [N], shape (P, samples), of P parameter sets of ``model`` under the FMU's input
    convention.

    The FMU with a communication point at every sample: over [t_k, t_k+1] the displacement is
    x_k + v_k*(t - t_k) and the velocity v_k held (a displacement jump where x_k+1 differs from
    x_k + v_k*h), and the force at t_k+1 is read before the next inputs are set (velocity v_k).
    This is what a co-simulation master sees; the identification's forward model
    (``identification.forward.input_path``) drives the same kernel with a finer, consistent input.
    ``parameter_sets``: see :func:`parameter_matrix`; the sets must be valid. A candidate whose
    step fails (overflow, non-finite state, too many substeps) gets NaN from that sample on.
    ``rest_force_N``: the force [N] the run starts holding at rest (a model with a resting state;
    NaN: relaxed). Runs on all cores.
    """
    t, x, v = _input_arrays(time_s, displacement_mm, velocity_mm_s)
    out_velocity = np.concatenate([v[:1], v[:-1]])
    return _forces(compiled_model(model), parameter_matrix(parameter_sets, model), t, x, v, np.arange(t.size),
                   out_velocity, max_substeps, *_step_sizes(t), rest_force_N)


@dataclass(frozen=True)
class CommunicationPoints:
    """The path a population runs on: the communication points ``time_s`` [s] (increasing), the
    displacement there ``displacement_mm`` [mm] and each step's velocity ``velocity_mm_s``
    [mm/s]; the forces are read at ``time_s[output_index]`` (increasing indices), the viscous
    feedthrough taken at ``output_velocity_mm_s`` [mm/s] (one each). One axis: 1-D arrays; the
    coupled form: (points, d) and (outputs, d). ``input_path.DrivenInput`` and
    ``DrivenVectorInput`` carry the same names and serve as well."""
    time_s: np.ndarray
    displacement_mm: np.ndarray
    velocity_mm_s: np.ndarray
    output_index: np.ndarray
    output_velocity_mm_s: np.ndarray
    rest_force_N: float = math.nan
    """The force [N] the run starts holding at rest (NaN: relaxed), for a model with a resting state."""
    conditions: tuple[tuple[str, float], ...] = ()
    """The run's conditions, (``Measurement`` field, value), such as ``temperature_K`` [K]
    (:func:`conditioned`)."""


def rest_force(points) -> float:
    """The force [N] a run on ``points`` starts holding at rest: its ``rest_force_N``, NaN (relaxed)
    where it has none."""
    return float(getattr(points, "rest_force_N", math.nan))


def condition_columns(model: BushingModel, conditions) -> list[tuple[int, float]]:
    """(column, value) of each parameter of ``model`` that the ``conditions`` ((``Measurement``
    field, value) pairs: a run's ``DrivenInput.conditions``) set (``BushingModel.conditions``: a
    temperature law's ``temperature`` from ``temperature_K``)."""
    given = dict(conditions)
    names = model.parameter_names
    return [(names.index(parameter), float(given[field])) for parameter, field in model.conditions if field in given]


def conditioned(matrix: np.ndarray, model: BushingModel, conditions) -> np.ndarray:
    """The (P, m) parameter matrix with the columns the ``conditions`` set (:func:`condition_columns`)
    replaced by them: a test at its own temperature; the matrix itself where none is set."""
    columns = condition_columns(model, conditions)
    if not columns:
        return matrix
    matrix = matrix.copy()
    for column, value in columns:
        matrix[:, column] = value
    return matrix


def conditioned_set(model: BushingModel, values, conditions) -> dict[str, float]:
    """The parameter set ``values`` with the parameters the ``conditions`` ((``Measurement`` field,
    value) pairs: a test's temperature) set (``BushingModel.conditions``); as it is where none."""
    given = dict(conditions)
    out = dict(values)
    for parameter, field in model.conditions:
        if field in given:
            out[parameter] = float(given[field])
    return out


def simulate_population_at(parameter_sets, points: CommunicationPoints, max_substeps: int = _MAX_SUBSTEPS,
                           model: BushingModel = DEFAULT_BUSHING) -> np.ndarray:
    """Forces [N], shape (P, outputs), at the output points of ``points``
    (``CommunicationPoints``); the input between communication points as in
    :func:`simulate_population_held`, the start at rest holding ``points.rest_force_N`` where given,
    the parameters its conditions set at them (:func:`conditioned`)."""
    t, x, v = _input_arrays(points.time_s, points.displacement_mm, points.velocity_mm_s)
    out_index, out_velocity = output_points(t, points.output_index, points.output_velocity_mm_s)
    matrix = conditioned(parameter_matrix(parameter_sets, model), required_model(model),
                         getattr(points, "conditions", ()))
    return _forces(compiled_model(model), matrix, t, x, v, out_index, out_velocity,
                   max_substeps, *_step_sizes(t), rest_force(points))


def simulate_coupled_held(parameter_sets, time_s, displacement_mm, velocity_mm_s,
                          max_substeps: int = _MAX_SUBSTEPS, model: BushingModel = DEFAULT_BUSHING) -> np.ndarray:
    """Force vectors [N], shape (P, samples, d), of P parameter sets of ``model``'s coupled form on
    the path ``displacement_mm`` (samples, d = 2 or 3) [mm] with the steps' velocities
    ``velocity_mm_s`` (samples, d) [mm/s], under the FMU's input convention (as
    :func:`simulate_population_held` for one axis: the force at t_k+1 with the velocity v_k). Runs
    on all cores."""
    v = np.atleast_2d(np.asarray(velocity_mm_s, dtype=float))
    points = CommunicationPoints(time_s, displacement_mm, v, np.arange(v.shape[0]), np.vstack([v[:1], v[:-1]]))
    return simulate_coupled_at(parameter_sets, points, max_substeps, model)


def simulate_coupled_at(parameter_sets, points: CommunicationPoints, max_substeps: int = _MAX_SUBSTEPS,
                        model: BushingModel = DEFAULT_BUSHING) -> np.ndarray:
    """Force vectors [N], shape (P, outputs, d), of P parameter sets of ``model``'s coupled form at
    the output points of ``points`` (``CommunicationPoints``: the displacement and the steps'
    velocities (points, d = 2 or 3), the output velocities (outputs, d)): the coupled counterpart
    of :func:`simulate_population_at`. Runs on all cores."""
    if required_model(model).coupled is None:
        raise ValueError(f"the {model.name} model has no coupled form")
    t = np.ascontiguousarray(points.time_s, dtype=float)
    x = np.atleast_2d(np.asarray(points.displacement_mm, dtype=float))
    v = np.atleast_2d(np.asarray(points.velocity_mm_s, dtype=float))
    d = x.shape[1]
    if not (t.ndim == 1 and t.size >= 2 and x.shape == v.shape == (t.size, d) and d in (2, 3)):
        raise ValueError(f"time (points,) and displacement and velocity (points, 2 or 3): got {t.shape}, {x.shape}, "
                         f"{v.shape}")
    out_index = np.ascontiguousarray(points.output_index, dtype=np.int64)
    out_velocity = np.atleast_2d(np.asarray(points.output_velocity_mm_s, dtype=float))
    if not (out_index.ndim == 1 and out_index.size >= 1 and out_velocity.shape == (out_index.size, d)
            and np.all(np.diff(out_index) > 0) and 0 <= out_index[0] and out_index[-1] < t.size):
        raise ValueError("output_index must be increasing indices into time_s, one output velocity vector each")
    pad = lambda a: np.ascontiguousarray(np.column_stack([a, np.zeros((a.shape[0], 3 - d))]))   # noqa: E731
    forces = compiled_model(model)._simulate_coupled_population(parameter_matrix(parameter_sets, model), t, pad(x),
                                                                pad(v), out_index, pad(out_velocity), max_substeps)
    return forces[:, :, :d]


MAX_STEP_SIZES = 256
"""Distinct step sizes up to which the population loop prepares the step's constants once per size
(a sampled test has a few dozen, from rounding); beyond, at every step."""


def _step_sizes(t):
    """(distinct step sizes, index of each step's among them) of the communication points t, or
    two empty arrays where there are more than MAX_STEP_SIZES distinct sizes."""
    sizes, index = np.unique(np.diff(t), return_inverse=True)
    if sizes.size > MAX_STEP_SIZES:
        return np.empty(0), np.empty(0, dtype=np.int64)
    return np.ascontiguousarray(sizes), np.ascontiguousarray(index, dtype=np.int64)


def output_points(t, output_index, output_velocity_mm_s) -> tuple[np.ndarray, np.ndarray]:
    """(indices, velocities) of the population loop's output points, checked: increasing indices
    into the communication points ``t``, one velocity [mm/s] each."""
    out_index = np.ascontiguousarray(output_index, dtype=np.int64)
    out_velocity = np.ascontiguousarray(output_velocity_mm_s, dtype=float)
    if not (out_index.ndim == 1 and out_index.size >= 1 and out_index.shape == out_velocity.shape
            and np.all(np.diff(out_index) > 0) and 0 <= out_index[0] and out_index[-1] < t.size):
        raise ValueError("output_index must be increasing indices into time_s, one output velocity each")
    return out_index, out_velocity


def _input_arrays(time_s, displacement_mm, velocity_mm_s):
    t = np.ascontiguousarray(time_s, dtype=float)
    x = np.ascontiguousarray(displacement_mm, dtype=float)
    v = np.ascontiguousarray(velocity_mm_s, dtype=float)
    if not (t.ndim == 1 and t.shape == x.shape == v.shape and t.size >= 2):
        raise ValueError(f"time, displacement and velocity must be 1-D arrays of equal length >= 2, "
                         f"got shapes {t.shape}, {x.shape}, {v.shape}")
    return t, x, v


def parameter_matrix(parameter_sets, model: BushingModel = DEFAULT_BUSHING) -> np.ndarray:
    """(P, m) float array of P parameter sets of ``model`` in its parameter order (its specs'),
    from a sequence of mappings or an array."""
    bushing = required_model(model)
    names = bushing.parameter_names
    if isinstance(parameter_sets, np.ndarray):
        matrix = np.atleast_2d(np.asarray(parameter_sets, dtype=float))
    else:
        matrix = np.array([[float(p[name]) for name in names] for p in parameter_sets])
    if matrix.ndim != 2 or matrix.shape[1] != len(names):
        raise ValueError(f"expected a (P, {len(names)}) parameter matrix of the {bushing.name} model "
                         f"in the order {', '.join(names)}, got shape {matrix.shape}")
    return np.ascontiguousarray(matrix)


def simulate_model_held(model: str | BushingModel, params: Mapping[str, float], time_s, displacement_mm,
                        velocity_mm_s) -> np.ndarray:
    """Force [N] of one parameter set of any model of ``registry`` (the model or its name)
    under the FMU's input convention (:func:`simulate_population_held`). Raises ParameterError
    for an invalid set."""
    model = resolve_model(model)
    values = model.check(params)
    return simulate_population_held([values], time_s, displacement_mm, velocity_mm_s, model=model)[0]
