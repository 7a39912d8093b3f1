"""The fit's exact Jacobian: the forces' sensitivities to the search coordinates, computed with the forces.

For a parameter set p (a row of the fit's candidates) and K seed directions dp/dtheta_j (the
derivatives of the search space's map theta -> p, ``SearchSpace.to_parameters_and_seeds``), one
simulation gives the forces F_k at the output samples and their derivatives dF_k/dtheta_j for all
K directions: forward-mode sensitivities propagated through the model's own kernels,

    m = prepare(p), state = start_state(m, x_0, F_rest), ms = prepare_step(m, h),
    state = step_prepared(m, ms, state, state_x, x_k, v_k, h, max_substeps)   (jump + integrate),
    F_k = force(m, state, x_k, v_out_k),

with p, m, ms and the state active and the input (x, v, h) constant. No derivative is typed here:
``fmu_src.kernels.tangents`` generates each kernel's tangent from its source (the kernels' own
statements, so the forces are bit for bit those of ``population``'s population loop: tested),
``tangents.Generator(lanes=K)`` makes them carry the K directions at once (the value, the
expensive part of a step, is computed once), and this module binds them to the population loop
that the forces run too (``population._population_loop``) in a generated module that numba
compiles and caches on disk like the plain kernels
(``fmu_src.kernels.numba_binding``; the first process compiles, later ones load).

What the derivative is where the forward model is not differentiable: the derivative of the
branch the kernels take (a Bouc-Wen block's sgn switches, the substep count of a step, which is
piecewise constant in p); ``tangents``' module docstring states each one-sided value. Away from
those it is the exact derivative of the computed forces (``tests/identification/fitting/test_fit_jacobian.py`` checks it
against central differences of the plain forward model).

Units as in the models: mm, mm/s, N, s; the derivatives in N per unit of each search coordinate.
"""
from __future__ import annotations

import ast
import builtins
import inspect
import math
import sys
import threading
import types
from typing import Callable

import numpy as np

from fmu_src.kernels import numba_binding as _kernels, tangents
from fmu_src.model import elements, integration
from fmu_src.model.registry import BushingModel, DEFAULT_BUSHING, required_model
from fmu_src.kernels.jit import numba
from fmu_src.syntax_trees import parse
from identification.forward.population import (CommunicationPoints, _input_arrays, _population_loop, _step_sizes,
                                               condition_columns, conditioned, output_points, parameter_matrix,
                                               rest_force)

_MAX_SUBSTEPS = integration.DEFAULT_MAX_SUBSTEPS


def _tangent_names(model: BushingModel, generator: tangents.Generator) -> dict[str, str]:
    """The generated tangents of the kernels the population loop calls, by the loop's slot names
    (``population._population_loop``)."""
    namespace = model.step.__globals__     # the step protocol bound to the model's kernels
    return {
        "_PREPARE": generator.emit(model.prepare, (True,)),
        "_INITIAL": generator.emit(model.start_state, (True, False, False)),
        "_PREPARE_STEP": generator.emit(namespace["prepare_step"], (True, False)),
        "_STEP": generator.emit(namespace["step_prepared"], (True, True, True, False, False, False, False, False)),
        "_FORCE": generator.emit(model.force, (True, True, False, False)),
    }


def _machinery_imports(model: BushingModel, source: str, machinery: str) -> str:
    """The imports from the compiled machinery and elements of the globals the tangents read that
    the model's module does not have (the tangents of ``integration``'s and ``elements``'
    functions read their own module's globals)."""
    module = sys.modules[model.kernel_module]
    tree = parse(source)
    defined = {node.name for node in tree.body if isinstance(node, ast.FunctionDef)}
    assigned, loaded = set(), set()
    for n in ast.walk(tree):        # one walk: the module is large (0.2 MB for 14 directions)
        if isinstance(n, ast.Name):
            (assigned if isinstance(n.ctx, ast.Store) else loaded if isinstance(n.ctx, ast.Load) else set()).add(n.id)
        elif isinstance(n, ast.arg):
            assigned.add(n.arg)
    names = sorted(loaded - defined - assigned - set(tangents.HELPERS))
    shared = ((machinery, integration), (_kernels.elements_module(), elements))
    needed: dict[str, list[str]] = {}
    for name in names:
        if name in module.__dict__:
            for _, kernels in shared:
                if name in kernels.__dict__ and module.__dict__[name] is not kernels.__dict__[name]:
                    raise ValueError(f"{module.__name__} defines {name!r}, which the tangents of "
                                     f"{kernels.__name__.rpartition('.')[2]}'s functions also read as its own: "
                                     "rename it")
            continue
        owner = next((compiled for compiled, kernels in shared if name in kernels.__dict__), None)
        if owner is not None:
            needed.setdefault(owner, []).append(name)
        elif name != "math" and not hasattr(builtins, name):
            raise ValueError(f"the tangents of the {model.name} model read {name!r}, found in neither its module "
                             "nor integration nor elements")
    return "".join(f"from {compiled} import {', '.join(found)}\n" for compiled, found in needed.items())


def _tuple_of_lanes(values: int, lanes: int) -> str:
    """``_SEEDS(seeds, i)``: row i of a (P, values, lanes) array as a tuple of K-tuples."""
    rows = ", ".join("(" + "".join(f"seeds[i, {a}, {k}], " for k in range(lanes)) + ")" for a in range(values))
    return f"@{_kernels.INNER_JIT}\ndef _SEEDS(seeds, i):\n    return ({rows},)\n\n\n"


def _appendix(model: BushingModel, lanes: int, machinery: str) -> str:
    """The vector tangents of ``model``'s kernels for ``lanes`` directions, their helpers and the
    population loop (``population._population_loop``) carrying the derivatives, as source for
    its generated module."""
    generator = tangents.Generator(lanes)
    loop_names = _tangent_names(model, generator)
    source = generator.lane_source()
    helpers = "\n\n".join(inspect.getsource(helper) for helper in tangents.HELPERS.values())
    functions = [*generator.sources, *tangents.HELPERS]
    stores = "".join(f"    out[i, j, {k}] = d[{k}]\n" for k in range(lanes))
    return ("\n\nimport math\nimport numpy as np\nfrom " + machinery + " import OK as _OK\n"
            + _machinery_imports(model, source, machinery)
            + f"\nSLOPE_CAP = {tangents.SLOPE_CAP!r}\n\n\n" + helpers + "\n\n\n" + source + "\n\n\n"
            + "".join(f"{name} = {_kernels.INNER_JIT}({name})\n" for name in functions)
            + "".join(f"{alias} = {name}\n" for alias, name in loop_names.items())
            + "\n\n" + _kernels.row_tuple("_VALUES", len(model.specs))
            + _tuple_of_lanes(len(model.specs), lanes)
            + f"@{_kernels.INNER_JIT}\ndef _STORE(out, i, j, d):\n{stores}\n\n"
            + inspect.getsource(_population_loop)
            # not parallel (its prange a range): the fit asks for one point's Jacobian at a time,
            # and numba's parallel loop over these tuple types costs a third of the compile time
            + "\n\n_simulate_sensitivities = numba.njit(error_model='numpy', cache=True)(_population_loop)\n")


MAX_LANES = 24
"""The most directions one compiled module carries: more are computed in equal chunks of at most
this many (numba's bytecode reader fails on some tuple displays of 30-odd elements, and a
module's compile time grows faster than its lanes)."""


def lane_chunk(lanes: int) -> int:
    """The directions of each chunk ``lanes`` directions are computed in: all of them up to
    MAX_LANES, else equal chunks of at most MAX_LANES (the last padded with zero directions), so
    that one module carries them."""
    count = -(-lanes // MAX_LANES)
    return -(-lanes // count)


_compiled: dict[tuple[str, int], types.ModuleType] = {}
_compile_locks: dict[tuple[str, int], threading.Lock] = {}
_locks_lock = threading.Lock()
_source_sizes: dict[tuple[str, int], int] = {}

COMPILE_SECONDS_PER_KB = 0.11
"""numba's compile time of a generated sensitivity module per kB of its source, on the project's
2-core VM, fitted to four models' modules (docs/benchmarks.md, "Figures behind the code's
constants"). An estimate for the progress shown while it compiles."""


def expected_compile_seconds(model: BushingModel, lanes: int) -> float | None:
    """About how long the module of ``model`` in ``lanes`` directions takes to compile (from its
    source's size, ``COMPILE_SECONDS_PER_KB``); None before its source is generated in this
    process."""
    size = _source_sizes.get((required_model(model).name, lanes))
    return None if size is None else size / 1000.0 * COMPILE_SECONDS_PER_KB


def _generated_module(model: BushingModel, lanes: int) -> types.ModuleType:
    """The generated module, its source made in every process (the tangents and their vector
    rewrite: about a second for the proposed model's 14 directions) and loaded by its name, a
    hash of that source and the compiler versions (``numba_binding.module_name``, the one
    cache key): numba's disk cache holds its machine code from the machine's first process on."""
    machinery = _kernels.integration_module()      # loaded first: the module imports it by name
    source = _kernels.model_source(model, machinery, _appendix(model, lanes, machinery))
    _source_sizes[model.name, lanes] = len(source)
    return _kernels.load_generated(_kernels.module_name(f"bushing_jacobian{lanes}_{model.name}", source), source)


def sensitivity_module(model: BushingModel, lanes: int) -> types.ModuleType:
    """The generated module of ``model`` with the forces' sensitivities in ``lanes`` directions,
    its population loop compiled (or loaded from numba's disk cache) by a first call on a
    two-sample input: once per process. The first process on a machine compiles (about 25 s for
    the proposed model's 14 directions: every tangent statement is written 14 times); later ones
    generate the source again and load the machine code, and one that asks while another compiles
    waits for it (``numba_binding.compile_lock``)."""
    bushing = required_model(model)
    key = (bushing.name, lanes)
    if key in _compiled:
        return _compiled[key]
    with _locks_lock:
        lock = _compile_locks.setdefault(key, threading.Lock())
    with lock:      # a second thread asking for the same module waits for the first's compile
        if key not in _compiled:
            module = _generated_module(bushing, lanes)
            values = np.array([bushing.values({spec.name: 1.0 for spec in bushing.specs})])
            two = np.array([0.0, 1e-3])
            with _kernels.compile_lock(module.__name__):      # and a second process too
                module._simulate_sensitivities(values, np.zeros(values.shape + (lanes,)), two, two, two,
                                               np.arange(2, dtype=np.int64), two, 10, *_step_sizes(two), math.nan)
            _compiled[key] = module
    return _compiled[key]


def python_sensitivities(model: BushingModel, lanes: int) -> Callable:
    """The population loop (``population._population_loop``, same arguments) with the vector
    tangents of ``model``'s kernels as plain Python, uncompiled: the very source the compiled
    module holds, for tests that check every model without compiling each (interpreted, some 100
    times slower; plain Python raises where numba gives inf or NaN)."""
    bushing = required_model(model)
    generator = tangents.Generator(lanes)
    loop_names = _tangent_names(bushing, generator)
    source = generator.lane_source()
    namespace: dict = {}
    # integration's and elements' globals under the model's own (_machinery_imports refuses a name both have)
    for function in (integration.block_gain, elements.softplus, bushing.prepare):
        namespace.update(generator.namespace(function))
    namespace.update(numba=numba, np=np, _OK=integration.OK)
    exec(compile(source, f"<vector tangents of {bushing.name}>", "exec"), namespace)
    namespace.update({alias: namespace[name] for alias, name in loop_names.items()})
    namespace["_VALUES"] = tuple
    namespace["_SEEDS"] = lambda seeds, i: tuple(tuple(float(s) for s in row) for row in seeds[i])

    def store(out, i, j, d):
        out[i, j, :] = d
    namespace["_STORE"] = store
    return types.FunctionType(_population_loop.__code__, namespace, "_population_loop")


def population_sensitivities(parameter_sets, seeds, points: CommunicationPoints, max_substeps: int = _MAX_SUBSTEPS,
                             model: BushingModel = DEFAULT_BUSHING) -> tuple[np.ndarray, np.ndarray]:
    """Forces [N], shape (P, outputs), as ``population.simulate_population_at`` gives them on
    ``points`` (the same bits), and their derivatives, shape (P, outputs, K), in the K directions
    ``seeds`` (P, m, K): the derivatives of each row's m parameters (in the model's order) along
    each direction. NaN (both) from where a candidate fails. More than MAX_LANES directions run in
    chunks (:func:`lane_chunk`)."""
    t, x, v = _input_arrays(points.time_s, points.displacement_mm, points.velocity_mm_s)
    out_index, out_velocity = output_points(t, points.output_index, points.output_velocity_mm_s)
    bushing = required_model(model)
    matrix = parameter_matrix(parameter_sets, bushing)
    seeds = np.ascontiguousarray(seeds, dtype=float)
    if seeds.ndim != 3 or seeds.shape[:2] != matrix.shape:
        raise ValueError(f"seeds must have shape (P, m, K) = ({matrix.shape[0]}, {matrix.shape[1]}, K), "
                         f"got {seeds.shape}")
    columns = condition_columns(bushing, getattr(points, "conditions", ()))
    if columns:      # a parameter the run's conditions set moves nothing: its direction is 0
        matrix = conditioned(matrix, bushing, getattr(points, "conditions", ()))
        seeds = seeds.copy()
        seeds[:, [column for column, _ in columns], :] = 0.0
    lanes = seeds.shape[2]
    size = lane_chunk(lanes)
    module = sensitivity_module(bushing, size)
    if size == lanes:
        return module._simulate_sensitivities(matrix, seeds, t, x, v, out_index, out_velocity, max_substeps,
                                              *_step_sizes(t), rest_force(points))
    forces, parts = None, []
    for first in range(0, lanes, size):
        chunk = np.zeros(seeds.shape[:2] + (size,))
        chunk[:, :, :min(size, lanes - first)] = seeds[:, :, first:first + size]
        values, derivatives = module._simulate_sensitivities(matrix, chunk, t, x, v, out_index, out_velocity,
                                                             max_substeps, *_step_sizes(t), rest_force(points))
        forces = values if forces is None else forces      # the same bits from every chunk
        parts.append(derivatives)
    return forces, np.concatenate(parts, axis=2)[:, :, :lanes]
