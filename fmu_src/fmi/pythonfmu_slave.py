"""pythonfmu adapter: the FMI 2.0 co-simulation face of the bushing models.

A thin layer: it declares the variables of its axes (one axis of one model of
``registry``, or the six axes of ``SixAxisBushing``, each one of the models; see
``axes``), converts SI ports to the kernels' units, validates every value it is given and steps
each axis's model through ``integration``. Nothing here knows the equations, and this error
policy is the same for every model and every axis.

The FMU's class is a subclass of :class:`BushingSlave` named after the FMI identifier, which
build_fmu.py appends to the packed copy of this module (pythonfmu takes the class with the
longest hierarchy), so every model has its own modelIdentifier.

Error policy. pythonfmu 0.7 knows three outcomes of a call: fmi2OK, fmi2Discard (do_step
returns False) and fmi2Fatal (any Python exception); it cannot return fmi2Error.
- Start values with which the simulation cannot start (a parameter outside its range) are
  logged at exitInitializationMode with category ``logStatusError``; if they are still invalid
  at the first doStep, it fails with fmi2Fatal (an exception) and the reasons also go to stderr
  (pythonfmu passes log messages only with debug logging on), so that every master stops
  visibly: fmpy raises, libcosim reports a failed step. (exitInitializationMode itself does not
  fail: libcosim aborts the process on that.)
- During the run, a setter stores the value and logs a problem at once; a doStep that cannot
  succeed (a parameter made invalid, a non-finite input, overflow, too many substeps, on any
  axis) logs the reason, naming the axis, and returns False: fmi2Discard, with the committed
  state of every axis untouched, so the master can fix the value and step again.
An output is never NaN or Inf: it falls back to the last finite value.

Packaging. Inside an FMU this module is renamed to a name unique to the build, and its
siblings live in the package ``<that name>_lib``, so several FMUs of this project (even
with different code or defaults) can share one Python interpreter without running each
other's modules.
"""
import atexit
import ctypes
import importlib
import math
import os
import sys
import threading
from dataclasses import dataclass
from functools import partial

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status

# pythonfmu 0.7 re-executes this module's source at every instantiation (in the cached
# module's namespace), possibly after the host deleted the first extracted copy of the FMU
# (fmpy's simulate_fmu does). So module-level code here must touch no files: the packed
# library, imported once and then cached, reads the default parameters.
if __package__:
    from . import axes, runtime_messages, variables
    from ..model import integration
    AXES = None   # only an FMU built by build_fmu.py has axes, models and defaults
    GROUPS = ()
    STEP_AXES = {}
    STEP = None
else:
    _library = importlib.import_module(__name__ + "_lib")
    axes = _library.axes
    integration = _library.integration
    runtime_messages = _library.runtime_messages
    variables = _library.variables
    AXES = _library.AXES   # [(axes.Axis, BushingModel on that axis, default parameters)]
    GROUPS = _library.GROUPS   # coupled groups: tuples of positions in AXES
    STEP_AXES = _library.STEP_AXES   # {model name: compiled step of all its axes}; {} for pure Python
    STEP = _library.STEP   # which step runs: compiled (numba) or pure Python, and why
# numpy only where the compiled step runs (numba needs it anyway); the plain-Python step needs none
np = importlib.import_module("numpy") if STEP_AXES else None


MESSAGES = runtime_messages.MESSAGES   # the runtime policy's words, shared with the native FMU
TEXTS = runtime_messages.TEXTS

# Jumping inputs (integration.JUMP_*, which say why; logging only, the force is the same)
JUMP_WINDOW, JUMP_COUNT = integration.JUMP_WINDOW, integration.JUMP_COUNT
_JUMP_MASK = (1 << JUMP_WINDOW) - 1


def _inputs_text(*members) -> str:
    """The inputs of ``members`` (``_AxisState``) in a message, port units (``runtime_messages.INPUTS``)."""
    return ", ".join(runtime_messages.INPUTS.format(
        displacement=a.axis.displacement, x=a.x, x_unit=a.axis.displacement_unit, velocity=a.axis.velocity, v=a.v,
        v_unit=a.axis.velocity_unit) for a in members)


class InitializationError(RuntimeError):
    """Start values with which the simulation cannot start (fmi2Fatal at the first doStep)."""


_EXIT_ORDERED = set()   # the export libraries (paths) whose exit order_library_exit has put right


def order_library_exit(resources: str | None, identifier: str) -> None:
    """Empty the export library's interpreter guard at the Python host's exit, before the process
    exit destroys it (Linux; the library is the FMU's ``binaries/linux64/<identifier>.so``).

    pythonfmu 0.7's export library keeps a ``std::shared_ptr<PyState>`` that two exit paths
    release: the C++ static destructor, then the library's ``__attribute__((destructor))``
    (``finalizePythonInterpreter``), which assigns nullptr to the already destroyed pointer and
    so decrements a counter in freed memory (valgrind: an invalid access in
    finalizePythonInterpreter, 8 bytes into a block freed at exit). That write corrupts malloc's
    free lists, and the host aborts at exit ("corrupted double-linked list", in a later free).
    Called first, from Python's atexit, ``finalizePythonInterpreter`` leaves the pointer empty
    and both exit paths find nothing to release. Only where the host started Python on the
    process's main thread: pythonfmu starts it on a thread of its own otherwise, and its guard
    must then finish it."""
    if not sys.platform.startswith("linux") or not resources or threading.main_thread().native_id != os.getpid():
        return
    library = os.path.join(os.path.dirname(os.path.abspath(resources)), "binaries", "linux64", identifier + ".so")
    if library in _EXIT_ORDERED:
        return
    try:
        loaded = ctypes.CDLL(library, mode=os.RTLD_NOLOAD)   # the host's copy, kept loaded by this handle
        finalize = loaded.finalizePythonInterpreter
    except (OSError, AttributeError):      # not loaded from there, or another export library
        return
    _EXIT_ORDERED.add(library)
    atexit.register(finalize)


class _AxisState:
    """One axis of the slave: its model, parameters as set, inputs, and committed state (in the
    kernels' units: mm or rad, N or N.mm)."""

    def __init__(self, axis, model, defaults):
        self.axis = axis
        self.model = model
        # the axis's unit factors and travel limit, read at every step (plain attributes: fast)
        self.to_kernel, self.from_kernel, self.travel_limit = axis.to_kernel, axis.from_kernel, axis.plausible_travel
        # the model's parameters and its mounting's (offset, preload: 0 where the defaults have none)
        self.values = {spec.name: float(defaults.get(spec.name, 0.0)) for spec in model.fmu_specs}
        self.units = model.fmu_units
        self.offset, self.preload = model.mounting(self.values)   # kernel units, as last set
        self.preload_port = self.preload * self.from_kernel      # of the parameters in force
        self.x = 0.0                   # port displacement as set (m or rad)
        self.v = 0.0                   # port velocity as set (m/s or rad/s)
        self.constants = None          # model.prepare of the parameters in force
        self.parameters_changed = True
        self.state_x = 0.0             # kernel displacement the committed state belongs to
        self.x_now = -self.offset      # the model's displacement: x as last set less the offset, else x_k + v_k*h
        self.last_output = 0.0         # last finite output, port units (N or N.m)
        self.output_is_current = False  # last_output belongs to the current inputs and state
        self.travel_warned = False     # the implausible-travel warning is given once
        self.output_bound = math.inf   # port units; above it the output is implausible (warned once)
        self.output_warned = False
        self.stale_output_logged = False   # the stale-output error is given once per episode
        self.last_errors = []          # the parameter errors of the last validation
        self.params_row = None         # the parameters in force as an array (a compiled step's)
        self.jump_history = 0          # bit i: the step i steps ago started with a jump (JUMP_*;
                                       # for an axis of a compiled batch: the batch's array)
        self.unit = None               # the unit it is stepped in (``_Unit``): itself alone or its group


@dataclass(slots=True)
class _Batch:
    """The single-axis units of one model stepped in one compiled call (``numba_binding._step_axes``)."""
    step: object                  # the compiled step of all the batch's axes
    members: list                 # their axes (_AxisState), each a unit of one
    params: object                # their parameter rows in force (an array), None: rebuilt at the next step
    histories: object             # each axis's jumping-input history (JUMP_*; an int64 array)
    next_histories: object        # the next step's, written by the compiled step (swapped when committed)


class _AxisKernels:
    """One axis's model kernels in the shape of a coupled form (``definition.CoupledKernels``):
    displacements, velocities, jumps and forces as 1-tuples, so that a single axis's output and
    initial state are a unit's (its step calls the scalar kernels: ``_AxisUnit.advance``)."""

    def __init__(self, model):
        self.model = model

    def initial_state(self, constants, x):
        return self.model.initial_state(constants, x[0])

    def jump(self, constants, state, jump):
        return integration.apply_displacement_jump(self.model, constants, state, jump[0]), integration.OK

    def force(self, constants, state, x, v):
        return (self.model.force(constants, state, x[0], v[0]),)


class _Unit:
    """The axes stepped as one: a single axis (its model's kernels on 1-vectors, ``_AxisKernels``)
    or a coupled group (``axes.Coupling``: one model's coupled form, ``definition.CoupledKernels``,
    on the vector of its members' displacements, padded with 0 to three components). The state is
    the unit's; each member keeps its ports, parameters, mounting and output. A group's members'
    parameters must be equal (checked at every change)."""

    def __init__(self, members, kernels, width, state_size, label):
        self.members = members
        self.model = members[0].model
        self.kernels = kernels
        self.width = width                # components of its displacement vector: 1, or 3 for a group
        self.label = label                # how messages name it ("axis rz: ", "the ... group (...): ")
        self.state = tuple(0.0 for _ in range(state_size))
        self.state_x = (0.0,) * width     # kernel displacement vector the state belongs to
        self.constants = None
        self.usable = False
        self.errors = []                  # why its members' parameters cannot make one set, if so
        self.step_one = None              # a single axis's compiled step (STEP_AXES), if compiled
        for a in members:
            a.unit = self

    def inputs(self):
        """The members' model displacements and velocities as vectors [mm or rad, per s]."""
        x, v = [0.0] * self.width, [0.0] * self.width
        for c, a in enumerate(self.members):
            x[c], v[c] = a.x_now, a.v * a.to_kernel
        return tuple(x), tuple(v)

    def advance(self, h):
        """(new state, displacement vector at the end, the members' outputs [port units] there, or
        () if the step failed, the step's status) of a step of h [s] from the committed state to
        the members' current inputs, with the kernels (plain Python); raises ArithmeticError or
        ValueError where it overflows."""
        x, v = self.inputs()
        state, _, status = self.kernels.step(self.constants, self.state, self.state_x, x, v, h,
                                             integration.DEFAULT_MAX_SUBSTEPS)
        x_end = tuple(x[i] + v[i] * h for i in range(self.width))
        if status != integration.OK:
            return state, x_end, (), status
        return state, x_end, self.outputs(self.kernels.force(self.constants, state, x_end, v)), status

    def outputs(self, forces):
        """The members' outputs [port units] of the kernels' force vector."""
        return tuple(forces[c] * a.from_kernel + a.preload_port for c, a in enumerate(self.members))

    def record(self, stepped, steps, state, x_end, outputs):
        """A step to commit: (unit, new state, displacement vector at the end) in ``stepped``, and
        each member's (axis, displacement at the end, output, False: its jumps not yet counted,
        None: its state is the unit's) in ``steps``."""
        stepped.append((self, state, x_end))
        steps += [(a, x_end[c], outputs[c], False, None) for c, a in enumerate(self.members)]


class _AxisUnit(_Unit):
    """A single axis as a unit of one: its model's kernels on 1-vectors (``_AxisKernels``), the
    vectors written out (the FMU's most common unit, stepped every communication step)."""

    def __init__(self, a):
        self.axis_state = a
        super().__init__([a], _AxisKernels(a.model), 1, len(a.model.states), a.axis.label)

    @property
    def state_x(self):
        """(its axis's committed displacement,): kept on the axis alone."""
        return (self.axis_state.state_x,)

    @state_x.setter
    def state_x(self, value):
        self.axis_state.state_x = value[0]

    def record(self, stepped, steps, state, x_end, outputs):
        """The step in ``steps`` alone, its state with it (:meth:`_Unit.record`)."""
        steps.append((self.axis_state, x_end[0], outputs[0], False, state))

    def inputs(self):
        a = self.axis_state
        return (a.x_now,), (a.v * a.to_kernel,)

    def advance(self, h):
        a, model = self.axis_state, self.model    # the model's scalar kernels, called directly
        x, v = a.x_now, a.v * a.to_kernel
        state, _, status = model.step(self.constants, self.state, a.state_x, x, v, h, integration.DEFAULT_MAX_SUBSTEPS)
        x_end = x + v * h
        if status != integration.OK:
            return state, (x_end,), (), status
        return state, (x_end,), (model.force(self.constants, state, x_end, v) * a.from_kernel + a.preload_port,), status

    def outputs(self, forces):
        a = self.axis_state
        return (forces[0] * a.from_kernel + a.preload_port,)


class BushingSlave(Fmi2Slave):
    author = "Bouc-Wen bushing project"
    description = variables.fmu_description(AXES)
    version = None  # the project's version, written into each FMU's class by build_fmu.py
    license = "MIT"
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=1.0, step_size=1e-3)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        if AXES is None:
            raise RuntimeError("the bushing slave runs inside an FMU built by build_fmu.py")
        order_library_exit(self.resources, type(self).__name__)
        self._axes = [_AxisState(axis, model, defaults) for axis, model, defaults in AXES]
        # The units stepped: each coupled group whose model has a coupled form (Kelvin-Voigt's is
        # its axes as they are) and every other axis alone, the single axes first.
        groups = [[self._axes[i] for i in positions] for positions in GROUPS]
        groups = [members for members in groups if members[0].model.coupled is not None]
        grouped = {id(a) for members in groups for a in members}
        self._units = [_AxisUnit(a) for a in self._axes if id(a) not in grouped]
        for unit in self._units:
            unit.step_one = STEP_AXES[unit.model.name][1] if unit.model.name in STEP_AXES else None
        for members in groups:
            name = axes.group_name(tuple(a.axis.name for a in members))
            self._units.append(_Unit(members, members[0].model.coupled, 3, members[0].model.coupled.size,
                                     f"the {name} group ({', '.join(a.axis.name for a in members)}): "))
        # The compiled step of all single axes of a model in one call, where a model has two or
        # more: per model its step, units and parameter rows (rebuilt on a change). For a single
        # axis the arrays cost more than the two calls into numba they save (docs/benchmarks.md,
        # "Figures behind the code's constants").
        by_model = {}
        for unit in self._units:
            if unit.step_one is not None:
                by_model.setdefault(unit.model.name, []).append(unit)
        self._batches = [_Batch(STEP_AXES[name][0], [unit.members[0] for unit in units], None,
                                np.zeros(len(units), dtype=np.int64), np.zeros(len(units), dtype=np.int64))
                         for name, units in by_model.items() if len(units) > 1]
        batched = {id(a.unit) for batch in self._batches for a in batch.members}
        self._unbatched = [unit for unit in self._units if id(unit) not in batched]
        self._initial_state_pending = True  # set at exit of initialization, or first valid step
        self._parameters_changed = True     # some axis's parameters were set since the last check
        self._parameters_usable = False
        self._jump_warned = False           # the jumping-inputs warning is given once per instance
        for variable in variables.fmu_variables(AXES, GROUPS):
            self._register(variable)
        # Which step runs is logged at the exit of initialization mode, not here: pythonfmu 0.7
        # passes an instance's queued messages on after each call, and when an instance is freed
        # with messages still queued its destructor hands them to a logger it has already
        # destroyed (Fmi2Component's members die in reverse order), which crashes the host.
        self._step_logged = False

    def _register(self, variable):
        """Register one variable of the FMU's table (``variables``), with its getter and setter."""
        a = self._axes[variable.axis]
        kind, name, index = variable.kind, variable.name, variable.index
        if kind == "parameter":
            spec_name = a.model.fmu_specs[index].name
            getter, setter = self._parameter_getter(a, spec_name), self._parameter_setter(a, spec_name)
        elif kind == "displacement":
            getter, setter = partial(getattr, a, "x"), partial(self._set_displacement, a)
        elif kind == "velocity":
            getter, setter = partial(getattr, a, "v"), partial(self._set_velocity, a)
        elif kind == "output":
            getter, setter = partial(self._output, a), None
        else:                       # a state of its unit's (a coupled group's: a component of it)
            scale, unit = variable.scale, a.unit
            getter, setter = (lambda: unit.state[index] * scale), None
        self.register_variable(Real(name, causality=getattr(Fmi2Causality, variable.causality),
                                    variability=getattr(Fmi2Variability, variable.variability),
                                    description=variable.description, getter=getter, setter=setter))

    # ---------------------------------------------------------------- variable access
    @staticmethod
    def _outputs_stale(a):
        """An input or parameter of axis ``a`` changed: its output, and every member's of its coupled
        group (the group's force vector turns with each member's displacement), is computed anew."""
        for member in a.unit.members:
            member.output_is_current = False

    @staticmethod
    def _parameter_getter(a, name):
        return lambda: a.values[name]

    def _parameter_setter(self, a, name):
        def set_parameter(value):
            a.values[name] = value
            a.parameters_changed = self._parameters_changed = True
            self._outputs_stale(a)
            if not math.isfinite(value):
                self._say("PARAMETER_SET_NOT_FINITE", label=a.axis.label, name=name, value=value,
                          unit=a.units[name])
            elif name == "offset":
                # the model's displacement moves with the offset (a displacement jump if it
                # changes during the run, which the dashpots carry)
                a.offset = value
                a.x_now = a.x * a.to_kernel - value
        return set_parameter

    def _set_displacement(self, a, value):
        axis = a.axis
        a.x = value
        a.x_now = value * a.to_kernel - a.offset
        self._outputs_stale(a)
        if not math.isfinite(value):
            self._say("INPUT_SET_NOT_FINITE", port=axis.displacement, value=value, unit=axis.displacement_unit)
        elif abs(value) > a.travel_limit and not a.travel_warned:
            a.travel_warned = True
            self._say("ROTATION_BEYOND_SMALL_ANGLES" if axis.rotational else "DISPLACEMENT_BEYOND_TRAVEL",
                      port=axis.displacement, value=value, limit=axis.plausible_travel)

    def _set_velocity(self, a, value):
        a.v = value
        self._outputs_stale(a)
        if not math.isfinite(value):
            self._say("INPUT_SET_NOT_FINITE", port=a.axis.velocity, value=value, unit=a.axis.velocity_unit)

    def _output(self, a):
        """The axis's output at the current time and displacement. If its unit's displacement was
        set away from the one of the committed state, it includes the model's instantaneous
        response to that jump (a coupled group's force vector: every member's output at once)."""
        if a.output_is_current:
            return a.last_output
        unit = a.unit
        reason = TEXTS["PARAMETERS_INVALID"]
        if self._refresh_unit(unit):
            kernels = unit.kernels
            x, v = unit.inputs()
            try:
                state, status = unit.state, integration.OK
                if x != unit.state_x:
                    state, status = kernels.jump(unit.constants, state, tuple(x[i] - unit.state_x[i]
                                                                              for i in range(unit.width)))
                forces = kernels.force(unit.constants, state, x, v)
            except (ArithmeticError, ValueError):
                status, forces = integration.NOT_FINITE, (math.nan,) * unit.width
            if status == integration.OK and all(math.isfinite(f) for f in forces):
                for member, output in zip(unit.members, unit.outputs(forces)):
                    member.last_output = output
                    member.output_is_current = True
                    member.stale_output_logged = False
                return a.last_output
            reason = TEXTS["NOT_FINITE_AT_INPUTS"]
        return self._stale_output(a, reason)

    def _stale_output(self, a, reason):
        """The axis's last finite output, after saying once (until a current one can be computed
        again) why it cannot be computed now."""
        if not a.stale_output_logged:
            a.stale_output_logged = True
            self._say("OUTPUT_NOT_COMPUTABLE", output=a.axis.output, reason=reason, value=a.last_output,
                      unit=a.axis.output_unit)
        return a.last_output

    def _refresh_unit(self, unit) -> bool:
        """Its members' parameters refreshed (``_refresh_parameters``) and equal: a group carries one
        parameter set (its members' offset and preload may differ); True if usable, else the
        difference is logged."""
        changed = any(a.parameters_changed for a in unit.members)
        usable = all([self._refresh_parameters(a) for a in unit.members])
        if changed or unit.constants is None:
            first = unit.members[0]
            differing = [name for name in unit.model.parameter_names
                         if any(a.values[name] != first.values[name] for a in unit.members[1:])]
            unit.errors = []
            if usable and differing:
                values = "; ".join(", ".join(f"{a.axis.name}.{name} = {a.values[name]}" for a in unit.members)
                                   + f" [{first.units[name]}]" for name in differing)
                unit.errors = [MESSAGES["GROUP_PARAMETERS_DIFFER"].text(label=unit.label, values=values)]
                self._error(unit.errors[0])
            if usable and len(unit.members) > 1:   # a coupled group starts relaxed: it holds no force at rest
                for a in unit.members:
                    if a.model.held_force(a.values) != 0.0:
                        unit.errors.append(MESSAGES["GROUP_HELD_FORCE_NOT_ZERO"].text(
                            label=unit.label, axis=a.axis.name, value=repr(a.values["held_force"]),
                            unit=a.units["held_force"]))
                        self._error(unit.errors[-1])
            unit.usable = usable and not unit.errors
            unit.constants = first.constants if unit.usable else None
        return unit.usable

    # ---------------------------------------------------------------- FMI life cycle
    def exit_initialization_mode(self):
        # Never raise here: libcosim aborts the whole process on a failed exitInitializationMode,
        # while it reports a failed step. Invalid start values are logged now and fail the first step.
        if not self._step_logged:
            self.log(STEP, Fmi2Status.ok, "logAll")
            self._step_logged = True
        usable = [self._refresh_unit(unit) for unit in self._units]
        if all(usable) and all(math.isfinite(a.x_now) for a in self._axes):
            self._set_initial_state()

    def _fail_to_start(self):
        """The first doStep with start values that cannot run: fail visibly in every master.
        pythonfmu 0.7 can return no fmi2Error: a Python exception is its only way to fail a call
        other than fmi2Discard, and it makes fmi2Fatal (fmpy raises, libcosim reports a failed
        step). fmi2Discard would not do: fmpy ends the run silently on it. pythonfmu passes log
        messages to the host only with debug logging on, so the reasons also go to stderr."""
        reasons = [a.axis.label + error for a in self._axes for error in a.last_errors] \
            + [error for unit in self._units for error in unit.errors] or [TEXTS["PARAMETERS_INVALID"]]
        for message in reasons:
            print(f"{self.instance_name}: {message}", file=sys.stderr)
        self._say("CANNOT_START", reasons="; ".join(reasons))
        # pythonfmu 0.7 releases the instance, its class and its log queue once when an
        # exception is raised and once more when the instance is freed (PySlaveInstance's
        # cleanPyObject, twice): freeing a failed instance then corrupts memory and crashes the
        # host (libcosim at its exit; tests/fmu_src/fmi/test_fmu_bad_values.py). One extra reference each,
        # never given back, absorbs the second release: a few kB leaked per failed instance.
        for kept in (self, type(self), self._get_log_queue()):
            ctypes.pythonapi.Py_IncRef(ctypes.py_object(kept))
        raise InitializationError("; ".join(reasons))

    def _set_initial_state(self):
        """Each unit at relaxed equilibrium at its current displacement (its model's initial_state;
        a coupled group's at its members' displacement vector), an axis alone holding its
        ``held_force`` beyond that where it is not 0 (``BushingModel.holding_state``)."""
        for unit in self._units:
            x, _ = unit.inputs()
            if isinstance(unit, _AxisUnit):
                a = unit.axis_state
                unit.state = unit.model.holding_state(unit.constants, x[0], a.model.held_force(a.values))
            else:
                unit.state = unit.kernels.initial_state(unit.constants, x)
            unit.state_x = x
            for a in unit.members:
                a.state_x = a.x_now
                a.output_is_current = False
        self._initial_state_pending = False

    def do_step(self, current_time, step_size):
        if not 0.0 < step_size < math.inf:
            return self._say("STEP_SIZE_INVALID", value=step_size)
        if self._parameters_changed or not self._parameters_usable:
            self._parameters_changed = False
            self._parameters_usable = all([self._refresh_unit(unit) for unit in self._units])
        if not self._parameters_usable:
            if self._initial_state_pending:   # never started: nothing a master can do in the run
                self._fail_to_start()
            return self._say("STEP_PARAMETERS_INVALID", reason=TEXTS["PARAMETERS_INVALID"])
        # one sum is finite if every input is (and a huge but finite sum just takes the long way)
        if not math.isfinite(sum([a.x for a in self._axes] + [a.v for a in self._axes])):
            for a in self._axes:
                axis = a.axis
                if not (math.isfinite(a.x) and math.isfinite(a.v)):
                    name, value, unit = ((axis.displacement, a.x, axis.displacement_unit) if not math.isfinite(a.x)
                                         else (axis.velocity, a.v, axis.velocity_unit))
                    return self._say("STEP_INPUT_NOT_FINITE", port=name, value=value, unit=unit)
        if self._initial_state_pending:  # the values at initialization could not be used
            self._set_initial_state()
        # every unit first, then commit all: a refusal leaves every axis as it was
        compiled = self._step_compiled(step_size) if self._batches else None
        # None: no compiled call, or an axis failed in it: every unit one by one (for the message)
        stepped, steps, crossings = compiled if compiled is not None else ([], [], ())
        for unit in (self._unbatched if compiled is not None else self._units):
            if not self._step_unit(unit, current_time, step_size, stepped, steps):
                return False
        for batch, crossed in crossings:   # the compiled step counted its axes' jumps: keep them
            batch.histories, batch.next_histories = batch.next_histories, batch.histories
            if crossed >= 0 and not self._jump_warned:
                self._warn_jumping(batch.members[crossed], current_time, step_size, int(batch.histories[crossed]))
        for a, x_end, output, jumps_counted, state in steps:
            if abs(output) > a.output_bound and not a.output_warned:
                self._warn_implausible(a, output, current_time + step_size)
            if not (jumps_counted or self._jump_warned):
                jumped = integration.displacement_jumped(a.x_now, a.state_x, a.v * a.to_kernel, step_size)
                a.jump_history = ((a.jump_history << 1) | jumped) & _JUMP_MASK
                if jumped and a.jump_history.bit_count() > JUMP_COUNT:
                    self._warn_jumping(a, current_time, step_size, a.jump_history)
            a.state_x = a.x_now = x_end
            a.last_output = output
            a.output_is_current = True
            if state is not None:   # a unit of one's state (a group's is committed below)
                a.unit.state = state
        for unit, state, x_end in stepped:
            unit.state, unit.state_x = state, x_end
        return True

    def _step_unit(self, unit, current_time, step_size, stepped, steps) -> bool:
        """One unit's step, recorded (``_Unit.record``) in ``stepped`` (a group's new state) and
        ``steps`` (each member's displacement at the end and output, its jumps not yet counted);
        False after logging why it cannot be taken."""
        if unit.step_one is not None:   # a single axis compiled: one call (the same kernels as below)
            a = unit.members[0]
            state, output, x_end, status = unit.step_one(a.params_row, unit.state, a.state_x, a.x_now,
                                                         a.v * a.to_kernel, step_size, integration.DEFAULT_MAX_SUBSTEPS)
            output = output * a.from_kernel + a.preload_port
            if status == integration.OK and math.isfinite(output):
                steps.append((a, x_end, output, False, state))
                return True
        label = unit.label
        try:
            state, x_end, outputs, status = unit.advance(step_size)
        except (ArithmeticError, ValueError) as exc:
            status, outputs, label = integration.NOT_FINITE, (), label + f"the step overflowed ({exc}); "
        if self._step_refused(status, outputs, label, unit.members, current_time, step_size):
            return False
        unit.record(stepped, steps, state, x_end, outputs)
        return True

    def _step_refused(self, status, outputs, label, members, current_time, step_size) -> bool:
        """Whether the step of a unit's ``members`` (one axis, or a coupled group's) failed (``status``, a
        kernel's, or an output not finite); if so, why is logged, naming the inputs."""
        if status == integration.OK and all(math.isfinite(output) for output in outputs):
            return False
        inputs = _inputs_text(*members)
        if status == integration.TOO_MANY_SUBSTEPS:
            self._say("STEP_TOO_MANY_SUBSTEPS", time=current_time, label=label, h=step_size,
                      max_substeps=integration.DEFAULT_MAX_SUBSTEPS, inputs=inputs)
        elif status != integration.OK:
            self._say("STEP_NOT_FINITE", time=current_time, label=label, inputs=inputs)
        else:
            a, output = next((a, output) for a, output in zip(members, outputs) if not math.isfinite(output))
            self._say("STEP_OUTPUT_NOT_FINITE", time=current_time, label=label, output=a.axis.output, value=output,
                      unit=a.axis.output_unit, inputs=inputs)
        return True

    def _step_compiled(self, step_size):
        """(stepped, steps, [(batch, the first axis whose jumps crossed JUMP_COUNT or -1)]): every
        batched unit's step (as :meth:`_step_unit` appends it, its jumps counted) in one compiled
        call per model (``numba_binding._step_axes``, the same kernels and arithmetic as
        :meth:`_step_unit`, and the same jump count as :meth:`do_step`'s); None if any axis's step
        fails, so that the unit-by-unit step redoes it and words the refusal."""
        stepped, steps, crossings = [], [], []
        for batch in self._batches:
            members = batch.members
            if batch.params is None:
                batch.params = np.array([a.model.values(a.values) for a in members])
            rows = np.array([(a.x_now, a.v * a.to_kernel, a.state_x, *a.unit.state) for a in members])
            out, failures, crossed = batch.step(batch.params, rows, step_size, integration.DEFAULT_MAX_SUBSTEPS,
                                                batch.histories, batch.next_histories)
            if failures:
                return None
            crossings.append((batch, crossed))
            for a, row in zip(members, out.tolist()):   # (*state, force, x + v*h)
                steps.append((a, row[-1], row[-2] * a.from_kernel + a.preload_port, True, tuple(row[:-2])))
        return stepped, steps, crossings

    def _warn_jumping(self, a, current_time, step_size, history):
        """Warn, once per instance, that more than JUMP_COUNT of the axis's last JUMP_WINDOW steps
        started with a displacement jump (``history``, JUMP_*; this step is one of them, not yet
        committed)."""
        mismatch = abs(a.x_now - a.state_x)
        travel = abs(a.v * a.to_kernel) * step_size
        count = history.bit_count()
        self._jump_warned = True
        axis = a.axis
        self._say("DISPLACEMENT_JUMPS", label=axis.label, port=axis.displacement, count=count, window=JUMP_WINDOW,
                  time=current_time, mismatch=mismatch / a.to_kernel, unit=axis.displacement_unit,
                  velocity=axis.velocity, travel=travel / a.to_kernel)

    def _warn_implausible(self, a, output, time):
        """Warn, once per axis, of an output above the plausible bound (units most likely wrong)."""
        a.output_warned = True
        axis = a.axis
        kind = "ROTATIONAL" if axis.rotational else "TRANSLATIONAL"
        self._say("OUTPUT_IMPLAUSIBLE", output=axis.output, value=output, unit=axis.output_unit, time=time,
                  bound=a.output_bound, quantity=TEXTS["QUANTITY_" + kind], motion=TEXTS["MOTION_" + kind],
                  inputs=_inputs_text(a), units=TEXTS["UNITS_" + kind])

    def _refresh_parameters(self, a) -> bool:
        """Validate and prepare an axis's parameters once after they change, logging errors and
        warnings; True if the parameters in force are usable."""
        if a.parameters_changed:
            a.parameters_changed = False
            errors, warnings = a.model.validate(a.values)
            a.last_errors = errors
            for message in errors:
                self._error(a.axis.label + message)
            if errors:
                a.constants = None
            else:
                for message in warnings:
                    self.log(f"{a.axis.label}accepted, but {message}", Fmi2Status.warning, "logStatusWarning")
                if a.axis.rotational:   # 1 rad and the plausible angular velocity, in N.mm -> N.m
                    bound = a.model.plausible_force_bound(a.values, 1.0, axes.PLAUSIBLE_ANGULAR_VELOCITY_RAD_S)
                else:
                    bound = a.model.plausible_force_bound(a.values)
                a.output_bound = bound * a.axis.from_kernel
                a.constants = a.model.constants(a.values)
                a.preload_port = a.model.mounting(a.values)[1] * a.from_kernel
                if np is not None:
                    a.params_row = np.array(a.model.values(a.values))
            for batch in self._batches:
                batch.params = None
        return a.constants is not None

    def _error(self, message):
        self.log(message, Fmi2Status.error, "logStatusError")

    def _say(self, key, /, **fields) -> bool:
        """Log the runtime policy's message ``key`` (``runtime_messages.MESSAGES``) with ``fields``
        filled in, at its level; False, a refused step's answer."""
        message = MESSAGES[key]
        if message.level == "warning":
            self.log(message.text(**fields), Fmi2Status.warning, "logStatusWarning")
        else:
            self._error(message.text(**fields))
        return False

    # ---------------------------------------------------------------- FMU state
    # pythonfmu's default state holds the registered variables only; each axis's committed
    # state, its reported displacement and its last output must travel with it too.
    def _get_fmu_state(self):
        return {
            "axes": [{"parameters": dict(a.values), "x": a.x, "v": a.v, "state_x": a.state_x, "x_now": a.x_now,
                      "last_output": a.last_output} for a in self._axes],
            "units": [{"state": list(unit.state), "state_x": list(unit.state_x)} for unit in self._units],
            "initial_state_pending": self._initial_state_pending,
        }

    def _set_fmu_state(self, state):
        for a, saved in zip(self._axes, state["axes"]):
            a.values.update(saved["parameters"])
            a.offset = a.model.mounting(a.values)[0]
            a.x, a.v = saved["x"], saved["v"]
            a.state_x, a.x_now = saved["state_x"], saved["x_now"]
            a.last_output = saved["last_output"]
            a.output_is_current = False
            a.parameters_changed = True
        for unit, saved in zip(self._units, state["units"]):
            unit.state, unit.state_x = tuple(saved["state"]), tuple(saved["state_x"])
            unit.constants = None     # refreshed with its members' restored parameters
            self._refresh_unit(unit)
        self._parameters_changed = True
        self._initial_state_pending = state["initial_state_pending"]

