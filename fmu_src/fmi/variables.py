"""The variables of a bushing FMU, declared once: the pythonfmu slave registers them and the
native FMU's generator writes them, in the same order, so both FMUs have the same names, value
references, causalities, units and descriptions.

Per axis (``axes``), in this order: the model's parameters (spec order) and its mounting's
(``BushingModel.mounting_specs``: offset, preload), the displacement and velocity inputs, the
output, then the model's states as the model names them (``StateSpec``).
A value reference is the variable's position in the list (pythonfmu numbers them so). The
native FMU adds, after all of them, the derivative of each state for model exchange
(:func:`derivative_variables`).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..model.definition import HELD_FORCE_SPEC
from ..model.registry import DEFAULT_MODEL, get_model


NOMINAL_DISPLACEMENT = {"m": 1e-3, "rad": 1e-2}
"""Nominal values of displacement states (a bushing's travel: millimetres, or 0.6 degrees), so
that a host's error control sees them at their size in m or rad."""
NOMINAL_FORCE = {"N": 1000.0, "N.m": 1.0}
"""Nominal values of hysteretic-force states: a kilonewton (a newton metre on rotational axes)."""
NOMINAL_VELOCITY = {"m/s": 0.1, "rad/s": 1.0}
"""Nominal values of velocity states (a hydraulic mount's fluid column: 100 mm/s, 1 rad/s)."""


@dataclass(frozen=True)
class FmuVariable:
    name: str
    value_reference: int
    causality: str          # parameter, input, output, local
    variability: str        # tunable, fixed (read at the start only), continuous
    unit: str
    description: str
    axis: int               # position of the axis in the FMU's axes
    kind: str               # parameter, displacement, velocity, output, state, derivative, indicator
    index: int              # the parameter's position in BushingModel.fmu_specs; the state's in the kernels' tuple
    scale: float = 1.0      # port value = scale * kernel value (states and their derivatives)
    start: float | None = None
    state: int = -1         # derivatives: the value reference of their state


def fmu_variables(axis_models, groups=()) -> list[FmuVariable]:
    """The variables of an FMU whose axes are ``axis_models`` [(axes.Axis, model on that axis,
    parameters)], parameters starting at those values, the inputs at 0. ``groups``: the coupled
    groups (tuples of positions in ``axis_models``): a member's states are its component of the
    group's coupled state (``CoupledKernels.states``, component c of vector i at 3*i + c), named as
    the axis's own would be."""
    out: list[FmuVariable] = []
    component = {position: c for group in groups for c, position in enumerate(group)
                 if axis_models[group[0]][1].coupled is not None}

    def add(**fields):
        out.append(FmuVariable(value_reference=len(out), **fields))

    for position, (axis, model, parameters) in enumerate(axis_models):
        for index, spec in enumerate(model.fmu_specs):    # the model's, then its mounting's (default 0)
            # the held force is read once, at the start: fixed (set before initialization ends)
            variability = "fixed" if spec.name == HELD_FORCE_SPEC.name else "tunable"
            add(name=axis.prefix + spec.name, causality="parameter", variability=variability, unit=spec.unit,
                description=f"{axis.label}{spec.description} [{spec.unit}]", axis=position, kind="parameter",
                index=index, start=float(parameters.get(spec.name, 0.0)))
        what = "rotation" if axis.rotational else "displacement"
        add(name=axis.displacement, causality="input", variability="continuous", unit=axis.displacement_unit,
            description=(f"relative {what} of I with respect to J about/along {axis.name[-1]} "
                         f"[{axis.displacement_unit}]" if axis.name else
                         "relative displacement of the bushing (upper plate minus base) [m]"),
            axis=position, kind="displacement", index=0, start=0.0)
        add(name=axis.velocity, causality="input", variability="continuous", unit=axis.velocity_unit,
            description=f"relative velocity d{axis.displacement}/dt [{axis.velocity_unit}]", axis=position,
            kind="velocity", index=0, start=0.0)
        add(name=axis.output, causality="output", variability="continuous", unit=axis.output_unit,
            description=(f"{'moment' if axis.rotational else 'force'} on J along/about {axis.name[-1]}, positive "
                         f"for a positive {axis.displacement} [{axis.output_unit}]" if axis.name else
                         "bushing force, positive for positive x (force on the base) [N]"),
            axis=position, kind="output", index=0)
        coupled = position in component
        part = " (this axis's component of the coupled group's)" if coupled else ""
        for state in (model.coupled.states if coupled else model.states):
            unit, scale = axis.state_port(state.unit)
            add(name=axis.prefix + state.name, causality="local", variability="continuous", unit=unit,
                description=f"{axis.label}internal state: {state.meaning}{part} [{unit}]", axis=position,
                kind="state", index=3 * state.index + component[position] if coupled else state.index, scale=scale)
    return out


def derivative_variables(variables: list[FmuVariable]) -> list[FmuVariable]:
    """``der(<state>)`` for every state of ``variables``, numbered after them: the rates a host's
    integrator reads in model exchange (FMI's naming of a derivative)."""
    states = [v for v in variables if v.kind == "state"]
    return [FmuVariable(f"der({s.name})", len(variables) + i, "local", "continuous", f"{s.unit}/s",
                        f"rate of {s.name} [{s.unit}/s]", s.axis, "derivative", s.index, s.scale,
                        state=s.value_reference)
            for i, s in enumerate(states)]


def indicator_variables(first_reference: int, axis_models, groups=()) -> list[FmuVariable]:
    """``<axis.>event.<switch>`` for every switch of every axis (``BushingModel.switch_specs``):
    the quantities whose sign change is a state event, the event indicators of model exchange
    (FMI 3 declares them as variables), numbered from ``first_reference``. A coupled group's
    switches (``CoupledKernels.switch_specs``, of the group as a whole) are its first member's."""
    out = []
    grouped = {position: group for group in groups for position in group
               if axis_models[group[0]][1].coupled is not None}
    for position, (axis, model, _) in enumerate(axis_models):
        if position in grouped and grouped[position][0] != position:
            continue
        for switch in (model.coupled.switch_specs if position in grouped else model.switch_specs):
            unit, scale = axis.state_port(switch.unit)
            out.append(FmuVariable(f"{axis.prefix}event.{switch.name}", first_reference + len(out), "local",
                                   "continuous", unit, f"{axis.label}event indicator: {switch.meaning} (its sign "
                                   f"changes at a switch) [{unit}]", position, "indicator", switch.index, scale))
    return out


def fmu_description(axis_models) -> str:
    """The FMU's description (its modelDescription's), for ``axis_models`` as above (None: not built)."""
    if axis_models is None or len(axis_models) == 1:
        model = get_model(DEFAULT_MODEL) if axis_models is None else axis_models[0][1]
        return model.description or (f"Bushing, one axis: the {model.title} baseline model of the Bouc-Wen bushing "
                                     "project. Ports in SI, parameters in N-mm-s units.")
    return ("Six-axis rubber bushing between markers I and J (uncoupled axes, small rotations; "
            "inputs and outputs in J's axes): " + ", ".join(f"{axis.name} {model.title}" for axis, model, _ in axis_models)
            + ". Ports in SI; translational parameters in N-mm-s units, rotational in N.mm, rad, s.")


def all_variables(axis_models, groups=()) -> list[FmuVariable]:
    """The variables of an FMU with model exchange (the native FMU): :func:`fmu_variables`, then
    the states' derivatives, the event indicators and the time (FMI 3 requires the independent
    variable)."""
    variables = fmu_variables(axis_models, groups)
    variables += derivative_variables(variables)
    variables += indicator_variables(len(variables), axis_models, groups)
    return variables + [FmuVariable("time", len(variables), "independent", "continuous", "s",
                                    "simulation time [s]", 0, "time", 0)]


NOMINAL_TEMPERATURE_K = 300.0
"""A temperature state's nominal value [K]: a solver's scale for its error (a rubber near room
temperature)."""


def nominal(variable: FmuVariable) -> float:
    """A state's nominal value (1.0 for the other variables and for dimensionless states; a
    temperature's NOMINAL_TEMPERATURE_K)."""
    if variable.kind != "state" or variable.unit == "1":
        return 1.0
    if variable.unit == "K":
        return NOMINAL_TEMPERATURE_K
    return {**NOMINAL_DISPLACEMENT, **NOMINAL_VELOCITY, **NOMINAL_FORCE}[variable.unit]


def exact_text(value: float) -> str:
    """The shortest text that reads back as ``value`` (a start value in the model description, a
    constant in the generated C); ValueError for a value no FMU can start from."""
    if value != value or value in (float("inf"), float("-inf")):
        raise ValueError(f"{value} cannot be a start value")
    text = repr(float(value))
    return text if any(c in text for c in ".e") else text + ".0"
