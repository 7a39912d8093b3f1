"""The models' kernels compiled with numba from their own source, cached on disk.

One definition, two ways to run it. For a model, the source of its module (``proposed_model``
...) is written into a generated module in the cache folder (:func:`cache_directory`), where
every function the module defines (its kernels and their helpers) is replaced by a
numba-compiled version of itself (numba compiles a function on its first call, so a helper
that only plain Python calls costs nothing); its imports of the shared machinery
(``integration``) are pointed at a generated module of that machinery, compiled the same way,
so that every kernel calls the others compiled. Tuples and sums over a constant range are
written out term by term first (``unrolling``), which numba needs. Generated modules are
named after a hash of their content and the compiler versions (:func:`module_name`, the one
cache key): a changed model or machinery compiles afresh (numba's cache
checks only a file's own time stamp, not the sources of the functions a kernel calls), and
numba's on-disk cache lets the next process load the machine code instead of compiling.

The contract a model module keeps for this (checked on its syntax tree by
:func:`checked_imports`, which raises :class:`ModelContractError` naming the module and line of
anything else):

- its imports are at the module's top and of these forms only: ``from __future__ import ...``,
  ``import math``, ``from ..model.integration import names`` and ``from ..model.elements import
  names`` (the shared machinery and elements: in the generated module they come from their
  compiled copies), ``from ..model.<module> import names``
  (the contract: ``definition``, ``parameter_specs``, ``search_coordinates``) and
  ``from .<sibling> import names`` (another model's module): plain-Python values, such as specs,
  constants and ``BushingModel``. The generated module keeps of these only the constants (numbers,
  strings, tuples of them), written in as values (:func:`kernels_only`), so that its source
  names no package and every FMU of a model shares it and numba's cache with the
  identification; a kernel that reads anything else from there is refused when the module is
  generated (``generated_source.GenerationError``). Nothing else: ``from math import exp``, ``import numpy``,
  ``from ..model import integration`` and imports inside functions are refused, not copied.
- the step protocol (``integration.step`` and ``step_prepared``, appended to the generated module)
  calls the module's globals ``jump`` and ``integrate`` (and ``prepare_step``, where the module
  defines one): they must be the kernels its ``MODEL`` holds (``definition.check_step_kernels``, which
  ``BushingModel`` runs when a model is defined).

Users: the FMU (:func:`compiled_model`, when numba is importable in the host's Python; the slave
falls back to the plain-Python kernels otherwise) and the identification, whose population loops
(``identification/forward/population.py``) live in a generated module of their own that imports
the kernels from the FMU's (:func:`kernel_module`: one compiled copy of them); its exact
Jacobian's tangents (``parameter_jacobian``) are appended to a model's module. Numba is optional
here: nothing imports it until a model is compiled.
"""
from __future__ import annotations

import ast
import contextlib
import ctypes
import dataclasses
import hashlib
import importlib.util
import inspect
import math
import ntpath
import os
import re
import sys
import time
import types
import warnings
from pathlib import Path

from ..model import elements, integration
from .generated_source import check_bound_names, free_names, module_bindings
from ..model.definition import ModelContractError, check_step_kernels
from .unrolling import unroll
from ..syntax_trees import parse

CACHE_ENVIRONMENT = "BUSHING_CACHE_DIR"
INJECTED = ("numba",)
"""The names :func:`load_generated` binds in a generated module before running it: numba or its
plain-Python stand-in (``jit``), of this package (``fmu_src`` or an FMU's packed copy). Bound,
not imported, so that the source names no package: every FMU of a model and the identification
share one generated module and numba's cache of it."""

INNER_JIT = "numba.njit(error_model='numpy', cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)"
"""How a generated module compiles a function that only its compiled loops call (a row's tuple, a
store, a loop's slot, a tangent): without the wrappers that would let Python or C call it, which
numba otherwise writes for every function (a quarter of the compile time of the proposed model's
exact Jacobian in 14 directions: 30.8 s -> 23.0 s, measured side by side on 2026-11-29)."""

_JIT_KERNELS = (
    # every function this module defines; error_model="numpy": a division by zero gives inf/nan
    # (caught as NOT_FINITE) instead of an exception that would abort a whole population.
    "import types as _types\n"
    "for _name, _value in list(globals().items()):\n"
    "    if isinstance(_value, _types.FunctionType) and _value.__module__ == __name__:\n"
    "        globals()[_name] = numba.njit(error_model='numpy', cache=True)(_value)\n")


def cache_directory() -> Path:
    """Where the generated modules and numba's cache live: $BUSHING_CACHE_DIR, else
    $XDG_CACHE_HOME/boucwen-bushing, else ~/.cache/boucwen-bushing."""
    if os.environ.get(CACHE_ENVIRONMENT):
        return Path(os.environ[CACHE_ENVIRONMENT])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "boucwen-bushing"


def compiler_versions() -> str:
    """The versions of what compiles a generated module (Python, numba, llvmlite, numpy), read
    without importing numba: part of every generated module's name."""
    from importlib import metadata
    versions = [f"python {sys.version.split()[0]}"]
    for package in ("numba", "llvmlite", "numpy"):
        try:
            versions.append(f"{package} {metadata.version(package)}")
        except metadata.PackageNotFoundError:
            versions.append(f"{package} absent")
    return ", ".join(versions)


def module_name(prefix: str, source: str) -> str:
    """``prefix`` and a hash of ``source`` and the compiler versions: the one key of a generated
    module and of numba's cache of it (a changed model, machinery, template or compiler compiles
    afresh; anything else that changes no generated source, such as a docstring outside the
    kernel modules, does not). An identifier (a derived model's "+" written "_"), so that another
    generated module can import it by name."""
    digest = hashlib.sha256((compiler_versions() + chr(10) + source).encode()).hexdigest()[:16]
    return re.sub(r"\W", "_", f"{prefix}_{digest}")


def _numba():
    from .jit import numba
    return numba


_UNWRITABLE_WARNED: set[str] = set()
"""The cache folders this process has said it cannot write."""


def load_generated(name: str, source: str, check: bool = True) -> types.ModuleType:
    """The module ``name`` with ``source``, written to the cache folder and imported (once per
    process), with :data:`INJECTED` bound; in memory, uncached, if the folder cannot be written.
    Where it is generated (not
    yet in the folder, or in memory) and ``check``, every name its functions read must be bound
    (``generated_source.check_bound_names``: a GenerationError naming the function and the name);
    the shared machinery's module, whose step protocol is a template bound in each model's
    module, is loaded unchecked."""
    if name in sys.modules:
        return sys.modules[name]
    try:
        folder = cache_directory()
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{name}.py"
        if not path.is_file() or path.read_text() != source:
            if check:
                check_bound_names(source, name, INJECTED)
            # Written whole and renamed: worker processes start at once and must never read half a file.
            partial = path.with_suffix(f".{os.getpid()}.tmp")
            partial.write_text(source)
            os.replace(partial, path)
    except OSError as exc:
        if str(cache_directory()) not in _UNWRITABLE_WARNED:     # said once a process, not once a module
            _UNWRITABLE_WARNED.add(str(cache_directory()))
            warnings.warn(f"cannot write the compiled model's cache in {cache_directory()} ({exc}); compiling "
                          f"in memory at every start (set {CACHE_ENVIRONMENT} to a writable folder)", stacklevel=4)
        if check:
            check_bound_names(source, name, INJECTED)
        module = types.ModuleType(name)
        module.numba = _numba()
        sys.modules[name] = module
        exec(compile(source.replace(", cache=True", "").replace("(cache=True)", "()"), f"<{name}>", "exec"),
             module.__dict__)
        return module
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    module.numba = _numba()
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


ALLOWED_IMPORTS = ("from __future__ import ..., import math, from ..model.integration import <names>, "
                   "from ..model.elements import <names>, from ..model.<module> import <names>, "
                   "from .<model module> import <names>")
MACHINERY = "model.integration"
"""The shared machinery, as the models' package's parent names it: what a kernel module's imports of
it are pointed at in the generated module (the compiled machinery)."""
ELEMENTS = "model.elements"
"""The shared elements (``fmu_src/model/elements.py``), compiled as the machinery is: a kernel
module's imports of them are pointed at their compiled copy (:func:`elements_module`)."""


def checked_imports(tree: ast.Module, module: str, machinery: str | None, package: str) -> ast.Module:
    """``tree``, the source of the kernel module ``module`` of the package ``package``, with its
    relative imports made absolute: ``from ..model.integration import`` from ``machinery`` (the
    compiled machinery's module; None: the package's own), ``from ..model.<module> import`` from the
    parent package's ``model``, ``from .<sibling> import`` from ``package`` (the shared elements'
    ``from .integration import`` from the compiled machinery). Raises
    ModelContractError for an import of any other form (:data:`ALLOWED_IMPORTS`) or anywhere but
    at the module's top. Changes ``tree`` in place."""
    def refuse(node, why: str):
        return ModelContractError(f"{module}, line {node.lineno}: {ast.unparse(node)!r} {why}; a model module "
                                  f"may import only: {ALLOWED_IMPORTS}")
    top_level = {id(node) for node in tree.body}
    for node in ast.walk(tree):
        if not isinstance(node, (ast.Import, ast.ImportFrom)):
            continue
        if id(node) not in top_level:
            raise refuse(node, "is inside a function or block")
        if isinstance(node, ast.Import):
            if [(alias.name, alias.asname) for alias in node.names] != [("math", None)]:
                raise refuse(node, "is not allowed")
        elif node.level == 0:
            if node.module != "__future__":
                raise refuse(node, "is not allowed (an absolute import would not be compiled)")
        elif any(alias.name == "*" for alias in node.names) or node.module is None \
                or not (node.level == 1 and "." not in node.module
                        or node.level == 2 and node.module.startswith("model.") and node.module.count(".") == 1):
            raise refuse(node, "is not allowed (relative imports name one model module, or one module of the "
                               "model contract, and its names)")
        elif node.level == 2 and node.module == MACHINERY and machinery is not None:
            node.module, node.level = machinery, 0
        elif node.level == 1 and f"model.{node.module}" == MACHINERY and module == elements.__name__:
            node.module, node.level = integration_module(), 0    # the shared elements' own machinery
        elif node.level == 2 and node.module == ELEMENTS and machinery is not None:
            node.module, node.level = elements_module(), 0
        elif node.level == 2:
            node.module, node.level = f"{package.rpartition('.')[0]}.{node.module}", 0
        else:
            node.module, node.level = f"{package}.{node.module}", 0
    return tree


def kernel_source(module: types.ModuleType, machinery: str | None = None) -> str:
    """The source of a kernel module as numba reads it: tuples and sums over a constant range
    written out (``unrolling``), its imports checked and made absolute (:func:`checked_imports`;
    ``machinery``: the compiled machinery's module, or None for the machinery itself); a model's
    module (``machinery`` given) cut to its kernels (:func:`kernels_only`)."""
    tree = unroll(parse(inspect.getsource(module)), module.__dict__, module.__name__)
    tree = checked_imports(tree, module.__name__, machinery, module.__package__)
    return ast.unparse(kernels_only(tree, module.__dict__, module.__package__) if machinery is not None else tree)


def _literal(value) -> bool:
    """Whether ``value`` is a number, string, None or a tuple of them: a constant a kernel may read."""
    if isinstance(value, tuple):
        return all(_literal(item) for item in value)
    return value is None or isinstance(value, (bool, int, str)) or isinstance(value, float) and math.isfinite(value)


def kernels_only(tree: ast.Module, values: dict, package: str) -> ast.Module:
    """A model module's syntax tree (imports absolute, :func:`checked_imports`) cut to what its
    compiled copy runs: its docstring, ``__future__``, ``math`` and the compiled machinery's and
    elements' imports, its functions, and every module-level name (assigned, or imported from the
    model contract or another model's module) whose value (``values``, the module's) is a
    constant (:func:`_literal`), written as that value. Specs, the search box and ``MODEL`` go:
    the generated source names no package (its imports of the package are not needed), and a
    constant taken from another module is part of the source (and of the generated module's
    hash)."""
    root = package.rpartition(".")[0]
    body = []
    for index, node in enumerate(tree.body):
        if isinstance(node, ast.FunctionDef) or (index == 0 and isinstance(node, ast.Expr)):
            body.append(node)
        elif isinstance(node, ast.Import) or (isinstance(node, ast.ImportFrom) and not node.module.startswith(root + ".")):
            body.append(node)      # math, __future__, the compiled machinery and elements
        elif isinstance(node, (ast.ImportFrom, ast.Assign, ast.AnnAssign)):
            if isinstance(node, ast.ImportFrom):
                names = [alias.asname or alias.name for alias in node.names]
            else:
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                names = [n.id for target in targets for n in ast.walk(target) if isinstance(n, ast.Name)]
            body += [ast.Assign([ast.Name(name, ast.Store())], parse(repr(values[name]), mode="eval").body,
                                lineno=node.lineno)
                     for name in names if _literal(values.get(name, ...))]
    # a function that reads what went (a plain-Python helper of the specs) goes too, and so on
    gone = set(values) - module_bindings(body)
    while True:
        helpers = {node.name for node in body if isinstance(node, ast.FunctionDef) and free_names(node) & gone}
        if not helpers:
            break
        gone |= helpers
        body = [node for node in body if not (isinstance(node, ast.FunctionDef) and node.name in helpers)]
    tree.body = body
    return ast.fix_missing_locations(tree)


@contextlib.contextmanager
def compile_lock(name: str):
    """Held while this process compiles the generated module ``name`` (or loads it): a second
    process that asks for it meanwhile waits for the first's compile and then loads its machine
    code from numba's cache, instead of compiling it beside it. An exclusive lock on
    ``<cache folder>/<name>.lock``, released by the system if the process dies; no lock where
    there is no fcntl (Windows) or the folder cannot be written."""
    try:
        import fcntl
        handle = open(cache_directory() / f"{name}.lock", "w")
    except (ImportError, OSError):
        yield
        return
    with handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        yield


def integration_module() -> str:
    """The name of the compiled copy of the shared machinery (generated and loaded)."""
    return _shared_module(integration, "bushing_integration")


def elements_module() -> str:
    """The name of the compiled copy of the shared elements (generated and loaded)."""
    return _shared_module(elements, "bushing_elements")


def _shared_module(module: types.ModuleType, prefix: str) -> str:
    """The name of the compiled copy of a shared kernel module (generated and loaded): its source
    unchecked (the machinery's step protocol is a template bound in each model's module)."""
    source = (kernel_source(module, None) + "\n\n# ---- appended by fmu_src/kernels/numba_binding.py ----\n"
              + _JIT_KERNELS)
    name = module_name(prefix, source)
    load_generated(name, source, check=False)
    return name


def model_source(model, machinery: str, appendix: str = "") -> str:
    """``model``'s module (a ``BushingModel``'s kernel module), its kernels compiled, the step
    protocol (``integration.step`` and ``step_prepared``, compiled; ``prepare_step`` the
    machinery's ``unprepared_step`` where the module has none) and ``appendix``. Its relative
    imports point at its own package (plain Python: specs, checks) and at the compiled machinery
    ``machinery``; a module outside the contract (module docstring) is a ModelContractError."""
    module = sys.modules[model.kernel_module]
    check_step_kernels(model, module)
    source = kernel_source(module, machinery)
    return (source + "\n\n# ---- appended by fmu_src/kernels/numba_binding.py ----\n" + _JIT_KERNELS
            + f"\nif 'prepare_step' not in globals():\n    from {machinery} import unprepared_step as prepare_step\n"
            + "\n\n" + inspect.getsource(integration.step_prepared) + "\n\n" + inspect.getsource(integration.step)
            + "\n\nstep_prepared = numba.njit(error_model='numpy', cache=True)(step_prepared)"
            + "\nstep = numba.njit(error_model='numpy', cache=True)(step)\n"
            + start_source(model)
            + (_COUPLED_STEP if model.coupled is not None else "") + appendix)


def start_source(model) -> str:
    """``integration.start_state`` as ``start_state``, bound to the model's ``resting_state`` (or
    ``start_relaxed`` under that name, for a model without one), compiled."""
    start = integration.start_state if model.resting_state is not None else integration.start_relaxed
    return ("\n\n" + inspect.getsource(start).replace(f"def {start.__name__}(", "def start_state(", 1)
            + "\n\nstart_state = numba.njit(error_model='numpy', cache=True)(start_state)\n")


_COUPLED_STEP = ("\n\n" + inspect.getsource(integration.step_coupled)
                 + "\n\nstep_coupled = numba.njit(error_model='numpy', cache=True)(step_coupled)\n")
"""The coupled step protocol, bound to the module's ``jump_coupled`` and ``integrate_coupled``
(``definition.CoupledKernels`` checks that they are the model's)."""


COMPILED_IN_FMU = ("jump", "integrate")
"""The kernels an FMU runs compiled one axis at a time (the plain-Python step's fallback for the
message of a failed step). force() is a few multiplications, which plain Python does faster than
numba's dispatch (docs/benchmarks.md, "Figures behind the code's constants"); prepare() and initial_state() run once."""


def _step_axes(params, rows, h, max_substeps, histories, next_histories):
    """One communication step of every axis of one model, in one compiled call: what the FMU's
    ``integration.advance`` and ``force`` do axis by axis. ``params``: each axis's values in spec
    order; ``rows``: each axis's step input and committed state, (x, v, state_x, *state) in the
    kernels' units (mm or rad, per s; state_x the displacement the state belongs to); ``h`` [s];
    ``histories``: each axis's jumping-input history (``integration.JUMP_*``: bit i, the step i
    steps ago jumped), into ``next_histories`` with this step's bit (the FMU keeps them if it
    commits the step). Returns (rows of (*new state, force at x + v*h with velocity v, x + v*h),
    failures, the first axis whose history now holds more than JUMP_COUNT jumps with this step
    one of them, or -1): where any axis fails (a status other than OK, or a force that is not
    finite), the FMU redoes the step one axis at a time, which words the refusal.

    Written here, never called here: its source is compiled in the model's generated module
    (:func:`_fmu_appendix`), where ``prepare``, ``step`` and ``force`` are that model's compiled
    kernels."""
    count, width = rows.shape
    out = np.empty((count, width - 1))
    failures = 0
    crossed = -1
    for i in range(count):
        m = prepare(_VALUES(params[i]))
        x, v, state_x = rows[i, 0], rows[i, 1], rows[i, 2]
        jumped = _displacement_jumped(x, state_x, v, h)
        bits = ((histories[i] << 1) | (1 if jumped else 0)) & ((np.int64(1) << _JUMP_WINDOW) - 1)
        next_histories[i] = bits
        if jumped and crossed < 0:
            jumps = 0
            while bits:
                bits &= bits - 1
                jumps += 1
            if jumps > _JUMP_COUNT:
                crossed = i
        state, used, status = step(m, _STATE(rows[i, 3:]), state_x, x, v, h, max_substeps)
        _STORE(out, i, state)
        x_end = x + v * h
        out[i, width - 3] = force(m, state, x_end, v)
        out[i, width - 2] = x_end
        if status != _OK or not math.isfinite(out[i, width - 3]):
            failures += 1
    return out, failures, crossed


def _step_one(params, state, state_x, x, v, h, max_substeps):
    """One communication step of one axis in one compiled call, as :func:`_step_axes` does it
    for a row: ``params`` its values in spec order, ``state`` its committed state (a tuple).
    Returns (new state, force at x + v*h with velocity v, x + v*h, status)."""
    m = prepare(_VALUES(params))
    state, used, status = step(m, state, state_x, x, v, h, max_substeps)
    x_end = x + v * h
    return state, force(m, state, x_end, v), x_end, status


def row_tuple(name: str, size: int) -> str:
    """A compiled function ``name(row)``: the first ``size`` entries of an array row as a tuple."""
    values = "".join(f"row[{i}], " for i in range(size))
    return f"@{INNER_JIT}\ndef {name}(row):\n    return ({values})\n\n\n"


def _fmu_appendix(model) -> str:
    """The FMU's batched step for ``model`` (:func:`_step_axes`) and its helpers."""
    size = len(model.states)
    stores = "".join(f"    out[i, {j}] = state[{j}]\n" for j in range(size)) or "    pass\n"
    return ("\n\nimport math\nimport numpy as np\nfrom " + integration_module()
            + " import OK as _OK, displacement_jumped as _displacement_jumped, "
            "JUMP_WINDOW as _JUMP_WINDOW, JUMP_COUNT as _JUMP_COUNT\n\n"
            + row_tuple("_VALUES", len(model.specs)) + row_tuple("_STATE", size)
            + f"@{INNER_JIT}\ndef _STORE(out, i, state):\n" + stores + "\n\n"
            + inspect.getsource(_step_axes)
            + "\n\n_step_axes = numba.njit(error_model='numpy', cache=True)(_step_axes)\n\n\n"
            + inspect.getsource(_step_one)
            + "\n\n_step_one = numba.njit(error_model='numpy', cache=True)(_step_one)\n")


def kernel_module(model) -> types.ModuleType:
    """The model's compiled module: its kernels and the FMU's batched step (:func:`_fmu_appendix`),
    loaded, each function compiled at its first call. The one compiled copy of a model's kernels:
    the FMU runs it, and the identification's population loops import their kernels from it."""
    source = model_source(model, integration_module(), _fmu_appendix(model))
    return load_generated(module_name(f"bushing_kernels_{model.name}", source), source)


def compiled_in_fmu(model) -> tuple[str, ...]:
    """The kernels an FMU of ``model`` takes compiled: COMPILED_IN_FMU, and for a model with a
    resting state the two that its start (``integration.start_state``, bound to the module's
    globals) calls, so that the model's kernels are its compiled module's."""
    return COMPILED_IN_FMU + (("initial_state", "resting_state") if model.resting_state is not None else ())


def compiled_model(model):
    """({name: compiled kernel} for ``compiled_in_fmu``, "step_axes" and "step_one", seconds it took) —
    compiling now, or loading numba's cached machine code — or (None, why not) if numba cannot
    be imported."""
    try:
        import numba  # noqa: F401
    except Exception as exc:   # not installed, or broken in this host's Python
        return None, f"numba is not importable here ({type(exc).__name__}: {exc})"
    import numpy as np
    started = time.perf_counter()
    module = kernel_module(model)
    kernels = {name: getattr(module, name) for name in compiled_in_fmu(model)}
    kernels["step_axes"], kernels["step_one"] = module._step_axes, module._step_one
    # compile (or load) now, so that a first step does not wait: the constants and state the
    # plain-Python kernels make are what the FMU passes
    values = model.values({s.name: 1.0 for s in model.specs})
    constants = model.prepare(values)
    state, _ = kernels["jump"](constants, model.initial_state(constants, 0.0), 1e-3)
    kernels["integrate"](constants, state, 1e-3, 0.0, 1e-3, 10)
    kernels["step_axes"](np.array([values]), np.array([[1e-3, 0.0, 0.0, *state]]), 1e-3, 10,
                         np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64))
    kernels["step_one"](np.array(values), tuple(float(value) for value in state), 0.0, 1e-3, 0.0, 1e-3, 10)
    return kernels, time.perf_counter() - started


STEP_ENVIRONMENT = "BUSHING_FMU_STEP"
""""python": an FMU runs its plain-Python kernels although numba is importable; "compiled": it
compiles them in any host (default: only where the host process is a Python interpreter)."""


PROCESS_LINKS = ("/proc/self/exe", "/proc/curproc/file")
"""Where procfs names the running executable (Linux; FreeBSD with procfs mounted)."""


def _kernel32():
    """Windows' kernel32 (a function of its own so that tests can give a stand-in)."""
    return ctypes.WinDLL("kernel32")


def _libc():
    """The C library of the process, on macOS libSystem with ``_NSGetExecutablePath``."""
    return ctypes.CDLL(None)


def _windows_executable(kernel32) -> str:
    """GetModuleFileNameW(NULL): the path of the process's .exe."""
    size = 32768                       # the longest path Windows has
    buffer = ctypes.create_unicode_buffer(size)
    length = kernel32.GetModuleFileNameW(None, buffer, size)
    if not 0 < length < size:
        raise OSError(f"GetModuleFileNameW returned {length}")
    return buffer.value[:length]


def _macos_executable(libc) -> str:
    """_NSGetExecutablePath: the path of the process's executable (asked for its size first)."""
    size = ctypes.c_uint32(0)
    libc._NSGetExecutablePath(None, ctypes.pointer(size))
    buffer = ctypes.create_string_buffer(max(size.value, 1))
    if libc._NSGetExecutablePath(buffer, ctypes.pointer(size)) != 0:
        raise OSError(f"_NSGetExecutablePath needs {size.value} bytes")
    return os.path.realpath(os.fsdecode(buffer.value))


def host_executable() -> tuple[str | None, str]:
    """(the path of this process's executable as the operating system tells it, or None; how it
    was told or why not). Not ``sys.executable``: in a host that embeds Python it is not the
    process's executable (on Windows it is the host's own .exe, on Linux and macOS the first
    ``python3`` on PATH when the host names no program), so only the operating system can say
    whether the process is a Python interpreter."""
    try:
        if sys.platform == "win32":
            return _windows_executable(_kernel32()), "GetModuleFileNameW"
        if sys.platform == "darwin":
            return _macos_executable(_libc()), "_NSGetExecutablePath"
        for link in PROCESS_LINKS:
            try:
                return os.readlink(link), link
            except FileNotFoundError:
                continue
        return None, f"none of {', '.join(PROCESS_LINKS)} exists on {sys.platform}"
    except (OSError, AttributeError, ValueError) as exc:   # no such call, or the call failed
        return None, f"asking {sys.platform} for it failed ({type(exc).__name__}: {exc})"


def _python_host(executable: str) -> bool:
    """Whether ``executable`` (:func:`host_executable`) is a Python interpreter (fmpy,
    libcosimpy, ... run in one), not a C/C++ tool that embeds Python (numba-compiled kernels in
    a C host that embeds libpython, tests/c_host, ended in heap corruption: docs/benchmarks.md,
    "Figures behind the code's constants"; in Python hosts they run clean). By its file name:
    python, python3.12, python.exe, pythonw.exe, and macOS's framework interpreter
    .../Python.app/Contents/MacOS/Python."""
    name = (ntpath.basename(executable) if sys.platform == "win32" else os.path.basename(executable)).lower()
    return name.startswith("python")


def compile_axes(axes) -> tuple[list, dict, str]:
    """An FMU's axes [(axis, model, parameters)] with each model's COMPILED_IN_FMU kernels
    compiled, {model name: its compiled steps (:func:`_step_axes` for several axes,
    :func:`_step_one` for one)}, and a sentence saying which
    step runs and why (the host's executable among it); the axes unchanged and no batched steps
    (the plain-Python step) if numba is not importable or fails, if the host is not a Python
    interpreter or its executable cannot be told (:func:`host_executable`), or if
    $BUSHING_FMU_STEP is "python". The compiled and the plain-Python steps give the same forces
    (tests/fmu_src/fmi/test_fmu_compiled_step.py)."""
    choice = os.environ.get(STEP_ENVIRONMENT, "").lower()
    if choice == "python":
        return list(axes), {}, f"pure-Python step ({STEP_ENVIRONMENT}=python)"
    executable, how = host_executable()
    if executable is None:
        host = f"the host's executable is unknown ({how})"
    else:
        host = f"the host is {executable} ({how})"
    if choice != "compiled":
        if executable is None:
            return list(axes), {}, (f"pure-Python step: {host}, and in a host that is not a Python interpreter "
                                    "numba-compiled kernels have corrupted the heap "
                                    f"({STEP_ENVIRONMENT}=compiled forces them)")
        if not _python_host(executable):
            return list(axes), {}, (f"pure-Python step: the host is not a Python interpreter ({executable}, by "
                                    f"{how}), where numba-compiled kernels have corrupted the heap "
                                    f"({STEP_ENVIRONMENT}=compiled forces them)")
    compiled, seconds = {}, 0.0
    try:
        for _, model, _ in axes:
            if model.name not in compiled:
                kernels, info = compiled_model(model)
                if kernels is None:
                    return list(axes), {}, f"pure-Python step: {info}"
                compiled[model.name], seconds = kernels, seconds + info
    except Exception as exc:   # a broken numba or an unwritable cache must not stop the FMU
        return list(axes), {}, f"pure-Python step: compiling the kernels failed ({type(exc).__name__}: {exc})"
    out = [(axis, dataclasses.replace(model, **{name: compiled[model.name][name] for name in compiled_in_fmu(model)}),
            parameters) for axis, model, parameters in axes]
    batched = {name: (kernels["step_axes"], kernels["step_one"]) for name, kernels in compiled.items()}
    why = f"{STEP_ENVIRONMENT}=compiled" if choice == "compiled" else "a Python interpreter"
    return out, batched, (f"compiled step (numba): {host}, {why}; one call per model for all its axes; "
                          f"{seconds:.2f} s to compile the kernels or load them from {cache_directory()}")
