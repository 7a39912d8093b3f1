"""What a bushing model is: ``BushingModel``, the one definition that the FMU, the compiled path
of the identification and the tests all read.

A model module (``proposed_model`` and its siblings) gives its names, units, bounds and
meanings (``ParameterSpec``), its internal states (``StateSpec``), the checks beyond each
value's range, its default parameter file, and its equations as five kernels:

    prepare(p) -> constants               p: the parameter values, a tuple in ``specs`` order
    initial_state(constants, x0) -> state     relaxed equilibrium at displacement x0 [mm]
    jump(constants, state, jump_mm) -> (state, status)
    prepare_step(constants, h) -> step constants    (optional) what depends on the step size alone
    integrate(step constants, state, x, v, h, max_substeps) -> (state, substeps, status)
    force(constants, state, x, v) -> F [N]
    derivatives(constants, state, x, v) -> d(state)/dt
    switches(constants, state, x, v) -> the quantities whose sign selects the equations' branch
    update(constants, state, x, v) -> state     (optional) the state after an event
    resting_state(constants, x0, force) -> state   (optional) at rest at x0 [mm] holding force [N]

A state is a tuple of floats (the kernels' order; ``states`` names them for the FMU; empty
for a model without state). Over a step the displacement is x + v*t [mm] for 0 <= t <= h [s]
with v [mm/s] constant; ``jump`` is the model's exact response to an instantaneous
displacement jump, and ``force`` is the force at displacement x with velocity v, positive for
positive x. ``integrate`` takes the step's constants ``prepare_step(constants, h)`` where the module defines
that kernel (the fractional model's relaxation modes' decay over h), else the constants
themselves. ``derivatives``, ``switches`` and ``update`` are for a host that integrates the state itself
(FMI model exchange: the states' derivatives, the event indicators, and the change of the state
at an event, for a model whose state jumps there: a friction element's reversal). The step protocol that
every path runs is ``integration.step`` (``BushingModel.step``).
Kernels are plain float arithmetic that raise nothing and return status codes
(``integration.OK`` ...), so that ``identification/forward/population.py`` compiles the same
source with numba (every function the module defines) and ``native/python_to_c.py`` translates
it into C. The shared machinery they step with is ``integration``.

Beside the equations a model module declares how the fit searches its parameters
(``SearchBox``, read by ``identification.fitting.search_space``) and how plots draw it
(``plot_style``); the registry (``registry``) finds the module by its name, ``*_model``.
"""
from __future__ import annotations

import sys
import types
from dataclasses import dataclass, field, replace
from typing import Callable, Mapping

from . import integration
from .search_coordinates import CoordinateKind
from .parameter_specs import (Constraint, ParameterError, ParameterSpec, constraint_messages, number_errors,
                              range_errors)

PLAUSIBLE_TRAVEL_MM = 100.0
PLAUSIBLE_VELOCITY_MM_S = 1000.0
"""Beyond a rubber bushing's travel and speed in service: the FMU warns above them (most likely
millimetres entered where metres are expected), and :meth:`BushingModel.plausible_force_bound`
is the force there."""
STIFFNESS_UNITS = ("N/mm", "N.mm/rad")
DAMPING_UNITS = ("N.s/mm", "N.mm.s/rad")

MOUNTING_SPECS = (
    ParameterSpec("offset", "mm", "displacement where the model sits at its own zero: F = model(x - offset) + "
                  "preload, as MSC Adams' BUSHING takes it"),
    ParameterSpec("preload", "N", "force added to the model's: F = model(x - offset) + preload", bound_powers=(0, 0),
                  temperature="none"),
)
"""How an axis mounts its model: every model on every axis takes them (0 and 0: the model as it
is, bit for bit). A model with a parameter of the same name (Kelvin-Voigt's preload, the same
constant force) keeps its own; on a rotational axis they are in rad and N.mm."""

HELD_FORCE_SPEC = ParameterSpec(
    "held_force", "N", "force the axis holds at rest when the run starts, beyond its relaxed force at the "
    "start displacement: its friction element stuck, the slider deflected (what the test before left in the "
    "device); 0: relaxed", bound_powers=(0, 0))
"""The start a model that can hold a force at rest (``BushingModel.resting_state``) takes on an
FMU's axis, after the mounting: the FMU starts that axis in ``BushingModel.holding_state``; 0 is
the relaxed start, bit for bit. An axis of a coupled group starts relaxed and takes 0 only."""


class ModelContractError(ValueError):
    """A model module outside the contract of the compiled path (the message names the module,
    the line and what is allowed)."""


STEP_KERNELS = ("jump", "integrate")
"""The model kernels ``integration.step`` and ``step_prepared`` call by their global names (their
``prepare_step`` is the module's own or the machinery's ``unprepared_step``, by construction);
``integration.start_state`` calls ``resting_state`` and ``initial_state`` so, for a model with a
resting state."""


def check_step_kernels(model, module: types.ModuleType) -> None:
    """Raise ModelContractError unless the globals of ``module`` that the step protocol calls
    (:data:`STEP_KERNELS`) are ``model``'s kernels of those names: the protocol is bound to the
    module's globals by name, so a model whose ``jump`` is another function would step with the
    wrong one."""
    names = STEP_KERNELS + (("resting_state", "initial_state") if model.resting_state is not None else ())
    for name in names:
        if vars(module).get(name) is not getattr(model, name):
            raise ModelContractError(
                f"{module.__name__}: the step protocol calls its global {name!r}, which is "
                f"{vars(module).get(name)!r}, not the model {model.name!r}'s {name} kernel "
                f"{getattr(model, name)!r}; name the kernels jump, integrate (and resting_state, "
                "initial_state) in the module that defines them")


@dataclass(frozen=True)
class StateSpec:
    """An internal state exposed by the FMU: entry ``index`` of the model's state tuple (or of
    the ``switches`` tuple, for a switch)."""
    name: str
    index: int
    unit: str      # "N", "m", "m/s" or "1" at the FMU (the kernels work in mm)
    meaning: str


@dataclass(frozen=True)
class SearchCoordinate:
    """One coordinate of the box the fit searches: ``kind`` (a ``search_coordinates.CoordinateKind``,
    such as ``STIFFNESS`` or ``TIME_CONSTANT``, or a model's own) maps it to the parameter, scaled
    by the data's reference stiffness k_ref [N/mm], damping c_ref [N.s/mm], force F_ref [N] and
    amplitude x_ref [mm]; ``low`` and ``high`` bound the coordinate (a kind may tighten them from
    the data). The other fields are what some kinds read."""
    parameter: str
    kind: CoordinateKind
    low: float
    high: float
    exponent: str = ""                  # shape, shape_sum: the block's n; a fractional coefficient: its alpha
    over: tuple[str, ...] = ()          # time_constant, slower: the stiffnesses the dashpot works against
    partner: str = ""                   # shape_sum: the block's beta-like parameter; slower: the faster dashpot
    sign: float = 1.0                   # shape_sum: coordinate = partner' + sign*parameter'


@dataclass(frozen=True)
class SlowLoop:
    """A progressive spring k0*x + k3*x^3 and Berg's friction (limit Ff_max, half-travel x2) in
    parallel with a model's rate-dependent part, which the fit estimates from the data's slowest
    sine loop for some of its starts (``identification.fitting.loop_start``). ``spring``: the names of
    the spring's linear and cubic stiffness; ``friction_limit``, ``travel``: the friction's;
    ``friction_alone``: (name, value) of every other parameter at a value that leaves the model's
    force the friction alone (its limit 1 N and the spring 0 are set by the loop), so that the
    model itself computes the friction's shape."""
    spring: tuple[str, str]
    friction_limit: str
    travel: str
    friction_alone: tuple[tuple[str, float], ...]

    @property
    def names(self) -> tuple[str, ...]:
        """The parameters the loop gives starts for."""
        return (*self.spring, self.friction_limit, self.travel)

    def friction_only(self, travel_mm: float) -> dict[str, float]:
        """The model's parameters for the friction alone, of limit 1 N and half-travel ``travel_mm``."""
        return {**dict(self.friction_alone), self.spring[0]: 0.0, self.spring[1]: 0.0, self.friction_limit: 1.0,
                self.travel: float(travel_mm)}


@dataclass(frozen=True)
class TrackStart:
    """A fluid column (an inertia track of mass ``mass``, damping ``damping``) that resonates
    against a bulge stiffness ``stiffness`` and a chamber stiffness ``compliance``, in parallel with
    a static spring ``static``, behind a decoupler of free travel ``travel`` ("" if none): the fit
    reads their starts off a dynamic-stiffness table's resonance (``identification.fitting.table_start``).
    A free decoupler plate also names its cage's ``engagement`` width, the ``cage``'s stiffness and
    the plate's ``centring`` stiffness ("" where the decoupler has none)."""
    static: str
    stiffness: str
    compliance: str
    mass: str
    damping: str
    travel: str = ""
    engagement: str = ""
    cage: str = ""
    centring: str = ""


@dataclass(frozen=True)
class LinearForce:
    """A model whose force is linear in its parameters: F = sum of parameter * regressor over
    ``regressors`` ((parameter, "displacement" [mm] or "velocity" [mm/s]) pairs), with the
    parameters of ``held`` ((name, value) pairs) at their values. The fit takes it by linear least
    squares within the parameters' ranges, not by a search."""
    regressors: tuple[tuple[str, str], ...]
    held: tuple[tuple[str, float], ...] = ()


@dataclass(frozen=True)
class SearchBox:
    """Where the fit searches a model: its ``coordinates`` (one per free parameter), the
    Bouc-Wen weights held at 1 (``unit_weights``: each block's alpha, which the force does not
    identify apart from its A, beta and gamma), the parameters held at 0 (``zeros``) and at other
    values (``held``: (name, value) pairs), the spring and friction a slow loop gives starts for
    (``loop_start``, a :class:`SlowLoop`, or None) and the fluid track a data sheet gives starts
    for (``table_start``, a :class:`TrackStart`, or None)."""
    coordinates: tuple[SearchCoordinate, ...]
    unit_weights: tuple[str, ...] = ()
    zeros: tuple[str, ...] = ()
    loop_start: SlowLoop | None = None
    table_start: TrackStart | None = None
    held: tuple[tuple[str, float], ...] = ()


@dataclass(frozen=True)
class CoupledKernels:
    """A model's coupled form: the same parameters acting on a displacement vector (a group of
    axes: the plane of a radial bushing, or 3-space), with isotropic hysteresis that is the
    one-axis model along any line (``integration``'s coupled blocks).

    Its kernels mirror the one-axis ones with 3-vectors (tuples) for x, v, a jump and the force:

        initial_state(constants, x0) -> state       x0 [mm], a 3-vector
        jump(constants, state, jump) -> (state, status)
        integrate(step constants, state, x, v, h, max_substeps) -> (state, substeps, status)
        force(constants, state, x, v) -> F, a 3-vector [N]
        derivatives(constants, state, x, v) -> d(state)/dt
        switches(constants, state, x, v) -> the quantities whose sign selects a branch
        update(constants, state, x, v) -> state     (optional) the state after an event

    taking the one-axis model's ``prepare`` (and ``prepare_step``) constants. A plane path has a
    zero third component, and its state's third components stay 0. The state is flat: component
    c of the vector state ``states[i]`` is entry 3*i + c (``StateSpec.index`` is i).
    ``zero_parameters``: parameters that have no direction in the plane (Spencer's x0), which a
    coupled group requires to be 0."""
    states: tuple[StateSpec, ...]
    initial_state: Callable
    jump: Callable
    integrate: Callable
    force: Callable
    derivatives: Callable
    switches: Callable
    switch_specs: tuple[StateSpec, ...] = ()
    update: Callable | None = None
    zero_parameters: tuple[str, ...] = ()
    step: Callable = field(init=False, repr=False, compare=False)
    """step(constants, state, state_x, x, v, h, max_substeps) -> (state, substeps, status): the
    step protocol ``integration.step_coupled`` bound to these kernels."""

    def __post_init__(self):
        # as BushingModel's step: the protocol's code with the kernel module's globals, which the
        # compiled module (numba_binding) binds by name
        module = sys.modules[self.integrate.__module__]
        for name, kernel in (("jump_coupled", self.jump), ("integrate_coupled", self.integrate)):
            if vars(module).get(name) is not kernel:
                raise ModelContractError(f"{module.__name__}: the coupled step protocol calls its global {name!r}, "
                                         f"which is not the coupled {name.split('_')[0]} kernel {kernel!r}")
        namespace = dict(module.__dict__)
        namespace.setdefault("prepare_step", integration.unprepared_step)
        object.__setattr__(self, "step", types.FunctionType(integration.step_coupled.__code__, namespace,
                                                            "step_coupled"))

    @property
    def size(self) -> int:
        """Floats in the flat state."""
        return 3 * len(self.states)


@dataclass(frozen=True)
class BushingModel:
    """One bushing model: its names, parameters (paper units, N-mm-s), FMU states and the
    kernels that every path runs (the pythonfmu FMU, numba, the native FMU's C). Each model
    module defines one as ``MODEL``; ``fmu_src.model.registry.get_model(name)`` finds it.
    The kernels' conventions (arguments, units, status codes) are those of
    ``docs/adding_a_model.md``; ``step`` (bound when the model is defined) is the step protocol
    ``integration.step`` over them."""
    name: str                    # command-line name: proposed, spencer, berg, ... (registry)
    identifier: str              # FMI modelIdentifier and the "model" of parameter files
    title: str
    specs: tuple[ParameterSpec, ...]
    states: tuple[StateSpec, ...]
    default_file: str            # parameter set in data/ used as the FMU's defaults
    prepare: Callable
    initial_state: Callable
    jump: Callable
    integrate: Callable
    force: Callable
    derivatives: Callable
    switches: Callable
    constraints: tuple[Constraint, ...] = ()
    """Conditions on several parameters beyond each value's range (errors or warnings)."""
    switch_specs: tuple[StateSpec, ...] = ()
    """What ``switches`` returns, in order (index: the position in its tuple; unit "m/s" or "N"
    on a translational axis): the native FMU's event indicators."""
    update: Callable | None = None
    """update(constants, state, x, v) -> state: the state after an event at displacement x [mm]
    and velocity v [mm/s] (model exchange's discrete-state update), for a model whose state
    changes there, such as a friction element reversing where v has changed sign; None: an event
    changes nothing. ``integrate`` and ``jump`` make the same change themselves, in co-simulation."""
    search: SearchBox | None = None
    """Where the fit searches (None: the model is fitted by linear least squares, ``linear``)."""
    linear: LinearForce | None = None
    """For a model whose force is linear in its parameters (Kelvin-Voigt): which, against what;
    the fit solves for them by linear least squares instead of searching."""
    description: str = ""
    """The one-axis FMU's description (its modelDescription's); empty: one made from the title."""
    plot_style: tuple[str, str] = ("k", "-")
    """(matplotlib colour, line style) of the model in comparison plots."""
    rank: int = 100
    """Position in listings (the command line's choices, ``compare``'s columns): lower first."""
    settling_s: float = 0.0
    """The time [s] a sine from rest takes to settle, at least (0: a few cycles do): the fit's
    fixed loop on a dynamic-stiffness table runs each row this long or its cycles, whichever is
    more (``identification.fitting.objectives.PreparedTable``)."""
    coupled: CoupledKernels | None = None
    """The model on a displacement vector (a coupled group of axes); None: it has none (it acts
    on each axis alone: Kelvin-Voigt, whose linear elements couple nothing)."""
    rotational: bool = False
    """On a rotational axis (``axes.model_on_axis``): its units read rad for mm, N.mm for N."""
    static_spring: tuple[str, ...] = ()
    """The parameters of the spring that carries the model's static force in parallel (k0, and a
    cubic k3): what a measured backbone replaces (``derived``: held at 0). Empty: the backbone adds
    to the model's force (a static spring that also carries hysteresis, as the paper's k0)."""
    base: "BushingModel | None" = field(default=None, repr=False, compare=False)
    """A derived model's base (``derived``: the model with options); None for a registered model."""
    options: object = None
    """A derived model's ``derived.Options``; None for a registered model."""
    resting_state: Callable | None = None
    """resting_state(constants, x0, force) -> state: the state at rest at displacement x0 [mm]
    that holds ``force`` [N] (a friction element stuck, its slider deflected: the force a test
    before left in the device), for a model whose elements can hold a force at rest; the nearest
    it can hold where it cannot hold that much. None: it holds none (a run starts relaxed).
    ``start_state`` chooses between it and ``initial_state``."""
    conditions: tuple[tuple[str, str], ...] = ()
    """(parameter, the ``Measurement`` field that sets it): the parameters a test's own conditions
    set (a temperature law's ``temperature`` from a test's ``temperature_K``); the forward model
    takes them from each test that carries them (``population.conditioned``)."""
    step: Callable = field(init=False, repr=False, compare=False)
    """step(constants, state, state_x, x, v, h, max_substeps) -> (state, substeps, status): the
    step protocol of ``integration.step`` bound to this model's ``jump`` and ``integrate``."""
    start_state: Callable = field(init=False, repr=False, compare=False)
    """start_state(constants, x0, rest_force) -> state: ``integration.start_state`` bound to this
    model's ``resting_state`` and ``initial_state`` (``start_relaxed`` without a resting state):
    at rest holding ``rest_force`` [N], NaN relaxed."""

    def __post_init__(self):
        # integration.step's code with the globals of the module that defines the kernels in use
        # (a model module, or a compiled copy of it): one definition of the protocol for all.
        # A module without a prepare_step of its own steps with its constants as they are.
        check_step_kernels(self, sys.modules[self.kernel_module])
        namespace = dict(sys.modules[self.kernel_module].__dict__)
        namespace.setdefault("prepare_step", integration.unprepared_step)
        namespace["step_prepared"] = types.FunctionType(integration.step_prepared.__code__, namespace, "step_prepared")
        object.__setattr__(self, "step", types.FunctionType(integration.step.__code__, namespace, "step"))
        start = integration.start_state if self.resting_state is not None else integration.start_relaxed
        object.__setattr__(self, "start_state", types.FunctionType(start.__code__, namespace, start.__name__))

    @property
    def prepare_step(self) -> Callable:
        """prepare_step(constants, h) -> the step's constants, which ``integrate`` takes: the model
        module's own (what depends on the step size alone, computed once per h by a caller that
        steps many times), else the constants as they are."""
        return self.step.__globals__["prepare_step"]

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(spec.name for spec in self.specs)

    @property
    def mounting_specs(self) -> tuple[ParameterSpec, ...]:
        """The mounting's parameters this model takes besides its own (``MOUNTING_SPECS`` but a name
        the model has itself; ``HELD_FORCE_SPEC`` after them for a model with a ``resting_state``),
        in the units of its axis."""
        units = {"mm": "rad", "N": "N.mm"} if self.rotational else {}
        held = (HELD_FORCE_SPEC,) if self.resting_state is not None else ()
        return tuple(replace(spec, unit=units.get(spec.unit, spec.unit)) for spec in MOUNTING_SPECS + held
                     if spec.name not in self.parameter_names)

    @property
    def fmu_specs(self) -> tuple[ParameterSpec, ...]:
        """Every parameter an FMU's axis of this model has: the model's, then its mounting's."""
        return self.specs + self.mounting_specs

    @property
    def fmu_units(self) -> dict[str, str]:
        """The unit of every parameter an FMU's axis of this model has (:attr:`fmu_specs`)."""
        return {spec.name: spec.unit for spec in self.fmu_specs}

    def mounting(self, params: Mapping[str, float]) -> tuple[float, float]:
        """(offset [mm or rad], preload [N or N.mm]) of a parameter set: 0 where not given, and the
        preload 0 where the model has its own (its force holds it)."""
        names = {spec.name for spec in self.mounting_specs}
        return (float(params.get("offset", 0.0)) if "offset" in names else 0.0,
                float(params.get("preload", 0.0)) if "preload" in names else 0.0)

    def held_force(self, params: Mapping[str, float]) -> float:
        """The force [N or N.mm] a parameter set's axis holds at rest at its start beyond its
        relaxed force (``HELD_FORCE_SPEC``): 0 where not given or the model holds none."""
        return float(params.get("held_force", 0.0)) if self.resting_state is not None else 0.0

    def holding_state(self, constants, x0: float, held: float):
        """The state a run starts from at rest at ``x0`` [mm or rad] holding ``held`` [N or N.mm]
        beyond the relaxed force there (its force at rest, v = 0): relaxed (``initial_state``)
        where ``held`` is 0, else the ``resting_state`` of that force. What both FMUs start an
        axis in (the native C calls the same three kernels in this order)."""
        if held == 0.0:
            return self.initial_state(constants, x0)
        return self.resting_state(constants, x0, self.relaxed_force(constants, x0) + held)

    def relaxed_force(self, constants, x0: float) -> float:
        """The force [N or N.mm] at rest (v = 0) at ``x0`` [mm or rad] from the relaxed state there
        (``initial_state``)."""
        return self.force(constants, self.initial_state(constants, x0), x0, 0.0)

    @property
    def units(self) -> dict[str, str]:
        return {spec.name: spec.unit for spec in self.specs}

    @property
    def kernel_module(self) -> str:
        """The module whose source defines the kernels (what the compiled path compiles)."""
        return self.integrate.__module__

    def validate(self, params: Mapping[str, float]) -> tuple[list[str], list[str]]:
        """(errors, warnings) for a parameter set of this model, never raising. Errors make it
        unusable (missing, non-numbers, NaN, what the equations cannot take); warnings are
        physically doubtful but simulable values."""
        mounting = {spec.name: spec.unit for spec in self.mounting_specs if spec.name in params}
        errors = number_errors(params, {**self.units, **mounting}, f" of the {self.name} model")
        if errors:
            return errors, []
        values = {name: float(params[name]) for name in self.parameter_names}
        errors, warnings = constraint_messages(values, self.constraints)
        return range_errors(values, self.specs) + errors, warnings

    def check(self, params: Mapping[str, float]) -> dict[str, float]:
        """The parameters as floats in spec order, then the mounting's where given (``offset``,
        ``preload``), or ParameterError listing every problem (unknown names included)."""
        errors, _ = self.validate(params)
        allowed = [spec.name for spec in self.fmu_specs]
        unknown = sorted(set(params) - set(allowed))
        if unknown:
            errors.append(f"unknown parameter names {unknown} for the {self.name} model; "
                          f"allowed: {', '.join(allowed)}")
        if errors:
            raise ParameterError(f"invalid {self.name} parameters: " + "; ".join(errors))
        return {name: float(params[name]) for name in allowed if name in params}

    def values(self, params: Mapping[str, float]) -> tuple[float, ...]:
        """The values in spec order, the ``p`` of :meth:`prepare` (no validation)."""
        return tuple(float(params[name]) for name in self.parameter_names)

    def constants(self, params: Mapping[str, float]):
        """``prepare`` of a parameter mapping."""
        return self.prepare(self.values(params))

    def force_offset(self, params: Mapping[str, float]) -> float:
        """The constant part of the force [N] (a preload, Spencer's spring offset): the force at
        rest at x = 0 from the relaxed initial state there."""
        return self.relaxed_force(self.constants(params), 0.0)

    def plausible_force_bound(self, params: Mapping[str, float], travel: float = PLAUSIBLE_TRAVEL_MM,
                              velocity: float = PLAUSIBLE_VELOCITY_MM_S) -> float:
        """A force [N] no bushing with these parameters should reach in service: every spring
        and Bouc-Wen gain of the model (A weighted by its alpha), every dashpot and every other
        force term (``ParameterSpec.bound_powers``) in parallel, at ``travel`` [mm] and
        ``velocity`` [mm/s], plus the constant force. Above it the inputs are most likely in the
        wrong units (millimetres in the metre port). On a rotational axis (``axes``): rad, rad/s
        and N.mm."""
        total = 0.0
        for spec in self.fmu_specs:
            powers = self.bound_powers(spec)
            if powers is not None:
                weight = abs(params.get(self.gain_weight(spec.name), 1.0))
                total += abs(params.get(spec.name, 0.0)) * weight * travel ** powers[0] * velocity ** powers[1]
        return total + abs(self.force_offset(params))

    @staticmethod
    def bound_powers(spec: ParameterSpec) -> tuple[int, int] | None:
        """(p, q): ``spec`` adds |value| * travel^p * velocity^q to the plausible force bound;
        None: nothing (``ParameterSpec.bound_powers``, else by its unit)."""
        if spec.bound_powers is not None:
            return spec.bound_powers
        if spec.unit in STIFFNESS_UNITS:
            return (1, 0)
        if spec.unit in DAMPING_UNITS:
            return (0, 1)
        return None

    @staticmethod
    def gain_weight(name: str) -> str:
        """The parameter a stiffness counts with in the plausible bound: a Bouc-Wen gain A<i>
        with its alpha<i> (a name no model has, so weight 1, for the others)."""
        return "alpha" + name[1:] if name.startswith("A") else ""
