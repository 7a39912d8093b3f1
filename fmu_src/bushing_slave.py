"""pythonfmu adapter: the FMI 2.0 co-simulation face of the bushing models.

A thin layer: it declares the variables of one model of ``bushing_models`` (the proposed
one, or a baseline), converts SI ports to the paper's N-mm-s units, validates every value it
is given and steps the model's own kernels through ``integration``. Nothing here knows the
equations, and this error policy is the same for every model.

The FMU's class is a subclass of :class:`BushingSlave` named after the model's FMI
identifier, which build_fmu.py appends to the packed copy of this module (pythonfmu takes
the class with the longest hierarchy), so every model has its own modelIdentifier.

Error policy. pythonfmu 0.7 knows three outcomes of a call: fmi2OK, fmi2Discard (do_step
returns False) and fmi2Fatal (any Python exception); it cannot return fmi2Error.
- Start values with which the simulation cannot start (a parameter outside its range) are
  logged at exitInitializationMode with category ``logStatusError``; if they are still invalid
  at the first doStep, it fails with fmi2Fatal (an exception) and the reasons also go to stderr
  (pythonfmu passes log messages only with debug logging on), so that every master stops
  visibly: fmpy raises, libcosim reports a failed step. (exitInitializationMode itself does not
  fail: libcosim aborts the process on that.)
- During the run, a setter stores the value and logs a problem at once; a doStep that cannot
  succeed (a parameter made invalid, a non-finite input, overflow, too many substeps) logs the
  reason and returns False: fmi2Discard, with the committed state untouched, so the master can
  fix the value and step again.
The output F is never NaN or Inf: it falls back to the last finite force.

Packaging. Inside an FMU this module is renamed to a name unique to the build, and its
siblings live in the package ``<that name>_lib``, so several FMUs of this project (even
with different code or defaults) can share one Python interpreter without running each
other's modules.
"""
import ctypes
import importlib
import math
import sys

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status

# pythonfmu 0.7 re-executes this module's source at every instantiation (in the cached
# module's namespace), possibly after the host deleted the first extracted copy of the FMU
# (fmpy's simulate_fmu does). So module-level code here must touch no files: the packed
# library, imported once and then cached, reads the default parameters.
if __package__:
    from . import integration, model_definition
    MODEL = None  # only an FMU built by build_fmu.py has a model and defaults
    DEFAULT_PARAMETERS = None
else:
    _library = importlib.import_module(__name__ + "_lib")
    integration = _library.integration
    model_definition = _library.model_definition
    MODEL = _library.MODEL
    DEFAULT_PARAMETERS = _library.DEFAULT_PARAMETERS

MM_PER_M = 1000.0
PLAUSIBLE_TRAVEL_M = model_definition.PLAUSIBLE_TRAVEL_MM / MM_PER_M
"""|x| beyond this is far outside any rubber bushing's travel: most likely millimetres
entered where metres are expected. It is warned about, not refused."""


class InitializationError(RuntimeError):
    """Start values with which the simulation cannot start (fmi2Fatal at the first doStep)."""


def _description(model) -> str:
    if model is None or model.name == "proposed":
        return ("Nonlinear rubber bushing, one axis: the modified Spencer/Bouc-Wen model of "
                "'New nonlinear bushing model for general excitations using Bouc-Wen hysteretic "
                "model' (eqs. 1-5). Ports in SI, parameters in the paper's N-mm-s units.")
    return (f"Bushing, one axis: the {model.title} baseline model of the Bouc-Wen bushing project. "
            "Ports in SI, parameters in N-mm-s units.")


class BushingSlave(Fmi2Slave):
    author = "Bouc-Wen bushing project"
    description = _description(MODEL)
    version = None  # the project's version, written into each FMU's class by build_fmu.py
    license = "MIT"
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=1.0, step_size=1e-3)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        if MODEL is None:
            raise RuntimeError("the bushing slave runs inside an FMU built by build_fmu.py")
        for name in MODEL.parameter_names:
            setattr(self, name, DEFAULT_PARAMETERS[name])
        self.x = 0.0  # m
        self.v = 0.0  # m/s
        self._constants = None         # MODEL.prepare of the parameters in force (paper units)
        self._parameters_changed = True
        self._state = tuple(0.0 for _ in MODEL.states)  # committed state, mm and N
        self._state_x_mm = 0.0         # displacement the committed state belongs to
        self._x_now_mm = 0.0           # current displacement: x as last set, else x_k + v_k*h
        self._last_force = 0.0         # N, last finite force
        self._force_is_current = False  # _last_force belongs to the current inputs and state
        self._initial_state_pending = True  # set at exit of initialization, or first valid step
        self._travel_warned = False    # the implausible-travel warning is given once
        self._force_bound = math.inf   # N, above it the force is implausible (warned once)
        self._force_warned = False
        self._stale_force_logged = False   # the stale-force error is given once per episode
        self._last_errors = []         # the parameter errors of the last validation

        for spec in MODEL.specs:
            self.register_variable(Real(
                spec.name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable,
                description=f"{spec.description} [{spec.unit}]",
                setter=self._parameter_setter(spec.name)))
        self.register_variable(Real(
            "x", causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
            description="relative displacement of the bushing (upper plate minus base) [m]",
            setter=self._set_displacement))
        self.register_variable(Real(
            "v", causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
            description="relative velocity dx/dt [m/s]", setter=self._set_velocity))
        self.register_variable(Real(
            "F", causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
            description="bushing force, positive for positive x (force on the base) [N]",
            getter=self._force))
        for state in MODEL.states:
            scale = 1.0 / MM_PER_M if state.unit == "m" else 1.0
            self.register_variable(Real(
                state.name, causality=Fmi2Causality.local, variability=Fmi2Variability.continuous,
                description=f"internal state: {state.meaning} [{state.unit}]",
                getter=self._state_getter(state.index, scale)))

    # ---------------------------------------------------------------- variable access
    def _parameter_setter(self, name):
        def set_parameter(value):
            setattr(self, name, value)
            self._parameters_changed = True
            self._force_is_current = False
            if not math.isfinite(value):
                self._error(f"parameter {name} = {value} [{MODEL.units[name]}] is not "
                            "a finite number; the next doStep will be refused until it is")
        return set_parameter

    def _set_displacement(self, value):
        self.x = value
        self._x_now_mm = value * MM_PER_M
        self._force_is_current = False
        if not math.isfinite(value):
            self._error(f"input x = {value} m is not a finite number; the next doStep will be refused")
        elif abs(value) > PLAUSIBLE_TRAVEL_M and not self._travel_warned:
            self._travel_warned = True
            self.log(f"input x = {value} m exceeds {PLAUSIBLE_TRAVEL_M} m, far beyond a bushing's travel; "
                     "the FMU takes metres (2 mm is x = 0.002)", Fmi2Status.warning, "logStatusWarning")

    def _set_velocity(self, value):
        self.v = value
        self._force_is_current = False
        if not math.isfinite(value):
            self._error(f"input v = {value} m/s is not a finite number; the next doStep will be refused")

    def _state_getter(self, index, scale):
        return lambda: self._state[index] * scale

    def _force(self):
        """F at the current time and displacement. If x was set away from the displacement of
        the committed state, F includes the model's instantaneous response to that jump."""
        if self._force_is_current:
            return self._last_force
        if self._refresh_parameters():
            try:
                state = self._state
                if self._x_now_mm != self._state_x_mm:
                    state = integration.apply_displacement_jump(MODEL, self._constants, state,
                                                                self._x_now_mm - self._state_x_mm)
                force = MODEL.force(self._constants, state, self._x_now_mm, self.v * MM_PER_M)
            except (ArithmeticError, ValueError):
                force = math.nan
            if math.isfinite(force):
                self._last_force = force
                self._force_is_current = True
                self._stale_force_logged = False
                return force
            reason = f"the force at x = {self.x} m, v = {self.v} m/s is not finite ({force})"
        else:
            reason = "the parameters are invalid (see the errors above)"
        if not self._stale_force_logged:   # once until a current force can be computed again
            self._stale_force_logged = True
            self._error(f"F cannot be computed: {reason}; F keeps its last finite value {self._last_force} N")
        return self._last_force

    # ---------------------------------------------------------------- FMI life cycle
    def exit_initialization_mode(self):
        # Never raise here: libcosim aborts the whole process on a failed exitInitializationMode,
        # while it reports a failed step. Invalid start values are logged now and fail the first step.
        if self._refresh_parameters() and math.isfinite(self._x_now_mm):
            self._set_initial_state()

    def _fail_to_start(self):
        """The first doStep with start values that cannot run: fail visibly in every master.
        pythonfmu 0.7 can return no fmi2Error: a Python exception is its only way to fail a call
        other than fmi2Discard, and it makes fmi2Fatal (fmpy raises, libcosim reports a failed
        step). fmi2Discard would not do: fmpy ends the run silently on it. pythonfmu passes log
        messages to the host only with debug logging on, so the reasons also go to stderr."""
        reasons = self._last_errors or ["the parameters are invalid"]
        for message in reasons:
            print(f"{self.instance_name}: {message}", file=sys.stderr)
        self._error("the simulation cannot start: " + "; ".join(reasons))
        # pythonfmu 0.7 releases the instance, its class and its log queue once when an
        # exception is raised and once more when the instance is freed (PySlaveInstance's
        # cleanPyObject, twice): freeing a failed instance then corrupts memory and crashes the
        # host (libcosim at its exit; tests/test_fmu_bad_values.py). One extra reference each,
        # never given back, absorbs the second release: a few kB leaked per failed instance.
        for kept in (self, type(self), self._get_log_queue()):
            ctypes.pythonapi.Py_IncRef(ctypes.py_object(kept))
        raise InitializationError("; ".join(reasons))

    def _set_initial_state(self):
        """Relaxed equilibrium at the current displacement (the model's initial_state)."""
        self._state = MODEL.initial_state(self._constants, self._x_now_mm)
        self._state_x_mm = self._x_now_mm
        self._force_is_current = False
        self._initial_state_pending = False

    def do_step(self, current_time, step_size):
        if not 0.0 < step_size < math.inf:
            return self._refuse(f"communication step size {step_size} s must be a finite number > 0")
        if not self._refresh_parameters():
            if self._initial_state_pending:   # never started: nothing a master can do in the run
                self._fail_to_start()
            return self._refuse("doStep refused: the parameters are invalid (see the errors above)")
        if not (math.isfinite(self.x) and math.isfinite(self.v)):
            name, value, unit = ("x", self.x, "m") if not math.isfinite(self.x) else ("v", self.v, "m/s")
            return self._refuse(f"doStep refused: input {name} = {value} {unit} is not a finite number")
        if self._initial_state_pending:  # the values at initialization could not be used
            self._set_initial_state()
        x_mm = self._x_now_mm
        v_mm = self.v * MM_PER_M
        try:
            state, _ = integration.advance(MODEL, self._constants, self._state, self._state_x_mm, x_mm, v_mm,
                                           step_size)
        except integration.StepError as exc:
            return self._refuse(f"doStep at t = {current_time} s refused: {exc}")
        x_end = x_mm + v_mm * step_size
        force = MODEL.force(self._constants, state, x_end, v_mm)
        if not math.isfinite(force):
            return self._refuse(f"doStep at t = {current_time} s refused: the force would be {force} N "
                                f"(x = {self.x} m, v = {self.v} m/s); check the units of the inputs")
        if abs(force) > self._force_bound and not self._force_warned:
            self._force_warned = True
            self.log(f"F = {force:.4g} N at t = {current_time + step_size} s exceeds {self._force_bound:.3g} N, the "
                     f"force of all the bushing's springs and dashpots at {PLAUSIBLE_TRAVEL_M:g} m and "
                     f"{model_definition.PLAUSIBLE_VELOCITY_MM_S / MM_PER_M:g} m/s: check the units of "
                     f"the inputs (x = {self.x} m, v = {self.v} m/s; the FMU takes metres)",
                     Fmi2Status.warning, "logStatusWarning")
        self._state = state
        self._state_x_mm = self._x_now_mm = x_end
        self._last_force = force
        self._force_is_current = True
        return True

    def _refresh_parameters(self) -> bool:
        """Validate and compile the parameters once after they change, logging errors and
        warnings; True if the parameters in force are usable."""
        if self._parameters_changed:
            self._parameters_changed = False
            values = {name: getattr(self, name) for name in MODEL.parameter_names}
            errors, warnings = MODEL.validate(values)
            self._last_errors = errors
            for message in errors:
                self._error(message)
            if errors:
                self._constants = None
            else:
                for message in warnings:
                    self.log(f"accepted, but {message}", Fmi2Status.warning, "logStatusWarning")
                self._force_bound = MODEL.plausible_force_bound(values)
                self._constants = MODEL.constants(values)
        return self._constants is not None

    def _error(self, message):
        self.log(message, Fmi2Status.error, "logStatusError")

    def _refuse(self, message) -> bool:
        self._error(message)
        return False

    # ---------------------------------------------------------------- FMU state
    # pythonfmu's default state holds the registered variables only; the committed ODE
    # state, the reported displacement and the last force must travel with it too.
    def _get_fmu_state(self):
        return {
            "parameters": {name: getattr(self, name) for name in MODEL.parameter_names},
            "x": self.x, "v": self.v,
            "state": list(self._state),
            "state_x_mm": self._state_x_mm,
            "x_now_mm": self._x_now_mm,
            "last_force": self._last_force,
            "initial_state_pending": self._initial_state_pending,
        }

    def _set_fmu_state(self, state):
        for name, value in state["parameters"].items():
            setattr(self, name, value)
        self.x = state["x"]
        self.v = state["v"]
        self._state = tuple(state["state"])
        self._state_x_mm = state["state_x_mm"]
        self._x_now_mm = state["x_now_mm"]
        self._last_force = state["last_force"]
        self._force_is_current = False
        self._initial_state_pending = state["initial_state_pending"]
        self._parameters_changed = True
        self._refresh_parameters()
