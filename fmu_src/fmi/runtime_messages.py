"""The FMUs' runtime policy in words: every message both runtimes log, defined once.

The pythonfmu slave fills a message with :meth:`Message.text`; the native FMU's C calls the macro
``BW_MESSAGE_<NAME>(inst, field, ...)`` that ``native.messages_header`` generates from the same template
(``bushing_messages.h``, written beside the generated model), its arguments the template's fields
in the order they first appear. A field is ``{name}`` (text: in C a ``const char *``, a number
formatted as Python's ``repr`` by ``bw_format_double``), ``{name:d}`` (an ``int``) or
``{name:g}``, ``{name:.3g}`` … (a ``double``, printf's and Python's ``g`` agree).

Levels: ``error`` and ``warning`` are logged (``logStatusError``, ``logStatusWarning``); a
``refusal`` is an error that refuses the call (``fmi2Discard`` in C, ``doStep`` returns False in
the slave). ``TEXTS`` are fixed words that fill fields (reasons, a rotational axis's words).

The parameter rules' words belong to the model contract (``model.parameter_specs``) and the
coupled groups' to ``parameter_files``' checks; they are taken from there, not written again.
"""
from __future__ import annotations

import string
from dataclasses import dataclass

from ..model.parameter_specs import (CONSTRAINT_BROKEN, CONSTRAINT_DOUBTFUL, NOT_FINITE, OUT_OF_RANGE)

LEVELS = ("error", "warning", "refusal")

_CHECK_UNITS = "check the units of the inputs (the FMU takes metres and m/s)"
_REFUSED_AT = "doStep at t = {time} s refused: "

TEXTS = {
    "PARAMETERS_INVALID": "the parameters are invalid (see the errors above)",
    "NOT_FINITE_AT_INPUTS": "it is not finite at the inputs set (check their units: the FMU takes metres and m/s)",
    "FIX_AND_INSTANTIATE": "fix the values above and instantiate again",
    "QUANTITY_ROTATIONAL": "moment", "QUANTITY_TRANSLATIONAL": "force",
    "MOTION_ROTATIONAL": "rotation and angular velocity", "MOTION_TRANSLATIONAL": "travel and speed",
    "UNITS_ROTATIONAL": "radians", "UNITS_TRANSLATIONAL": "metres",
}
"""Fixed words that fill fields, ``BW_TEXT_<NAME>`` in C."""


@dataclass(frozen=True)
class Message:
    """One message: its ``level`` (``LEVELS``) and its ``template`` (``str.format`` fields)."""
    level: str
    template: str

    def __post_init__(self):
        if self.level not in LEVELS:
            raise ValueError(f"level {self.level!r}: one of {', '.join(LEVELS)}")

    @property
    def fields(self) -> tuple[str, ...]:
        """The template's field names in the order they first appear (the C macro's arguments)."""
        names = []
        for _, name, _, _ in string.Formatter().parse(self.template):
            if name is not None and name not in names:
                names.append(name)
        return tuple(names)

    def text(self, **fields) -> str:
        """The message with ``fields`` filled in (exactly the template's)."""
        if set(fields) != set(self.fields):
            raise TypeError(f"fields {sorted(fields)}: the message takes {list(self.fields)}")
        return self.template.format(**fields)

    def c_format(self) -> tuple[str, tuple[str, ...]]:
        """(printf format, the fields in the order printf takes them: a repeated field repeats)."""
        format_, arguments = "", []
        for literal, name, spec, _ in string.Formatter().parse(self.template):
            format_ += literal.replace("%", "%%")
            if name is None:
                continue
            if spec and spec[-1] not in "dg":
                raise ValueError(f"field {{{name}:{spec}}}: C takes text, d or g fields")
            format_ += "%" + spec if spec else "%s"
            arguments.append(name)
        return format_, tuple(arguments)


MESSAGES = {
    # parameters, as set and as checked (the checks' words are the model contract's)
    "PARAMETER_SET_NOT_FINITE": Message("error", "{label}parameter {name} = {value} [{unit}] is not a finite "
                                                 "number; the next doStep will be refused until it is"),
    "PARAMETER_NOT_FINITE": Message("error", "{label}" + NOT_FINITE),
    "PARAMETER_OUT_OF_RANGE": Message("error", "{label}" + OUT_OF_RANGE),
    "CONSTRAINT_BROKEN": Message("error", "{label}" + CONSTRAINT_BROKEN),
    "CONSTRAINT_DOUBTFUL": Message("warning", "{label}accepted, but " + CONSTRAINT_DOUBTFUL),
    "GROUP_PARAMETERS_DIFFER": Message("error", "{label}{values} differ: the axes of a coupled group carry one "
                                                "parameter set (set them alike)"),
    "GROUP_PARAMETER_NOT_ZERO": Message("error", "{label}{name} = {value} [{unit}] must be 0 in a coupled group (it "
                                                 "has no direction in the plane); give the axes an offset and a "
                                                 "preload instead"),
    "GROUP_HELD_FORCE_NOT_ZERO": Message("error", "{label}{axis}.held_force = {value} [{unit}] must be 0 in a "
                                                  "coupled group: the group starts relaxed (an axis alone starts "
                                                  "holding it)"),
    # inputs as set
    "INPUT_SET_NOT_FINITE": Message("error", "input {port} = {value} {unit} is not a finite number; the next doStep "
                                             "will be refused"),
    "ROTATION_BEYOND_SMALL_ANGLES": Message(
        "warning", "input {port} = {value} rad exceeds {limit:g} rad: the bushing takes rotations as small angles "
                   "(each component of the rotation vector about its own axis), which is approximate beyond about "
                   "20 degrees"),
    "DISPLACEMENT_BEYOND_TRAVEL": Message(
        "warning", "input {port} = {value} m exceeds {limit:g} m, far beyond a bushing's travel; the FMU takes "
                   "metres (2 mm is {port} = 0.002)"),
    "OUTPUT_NOT_COMPUTABLE": Message("error", "{output} cannot be computed: {reason}; {output} keeps its last finite "
                                              "value {value} {unit}"),
    # starting and stepping
    "CANNOT_START": Message("error", "the simulation cannot start: {reasons}"),
    "STEP_SIZE_INVALID": Message("refusal", "communication step size {value} s must be a finite number > 0"),
    "STEP_PARAMETERS_INVALID": Message("refusal", "doStep refused: {reason}"),
    "STEP_INPUT_NOT_FINITE": Message("refusal", "doStep refused: input {port} = {value} {unit} is not a finite "
                                                "number"),
    "STEP_TOO_MANY_SUBSTEPS": Message(
        "refusal", _REFUSED_AT + "{label}the step of {h:g} s would need more than {max_substeps:d} substeps "
                   "({inputs}); " + _CHECK_UNITS + " or shorten the communication step"),
    "STEP_NOT_FINITE": Message(
        "refusal", _REFUSED_AT + "{label}the step gave a non-finite state or force ({inputs}); " + _CHECK_UNITS
                   + " and the parameters"),
    "STEP_OUTPUT_NOT_FINITE": Message(
        "refusal", _REFUSED_AT + "{label}{output} would be {value:g} {unit} ({inputs}); check the units of the "
                   "inputs"),
    "OUTPUT_IMPLAUSIBLE": Message(
        "warning", "{output} = {value:.4g} {unit} at t = {time} s exceeds {bound:.3g} {unit}, the {quantity} of all "
                   "the bushing's springs and dashpots at the largest plausible {motion}: check the units of the "
                   "inputs ({inputs}; the FMU takes {units})"),
    "DISPLACEMENT_JUMPS": Message(
        "warning", "{label}the displacement input {port} jumps in {count:d} of the last {window:d} steps (at t = "
                   "{time:.6g} s by {mismatch:.3g} {unit} per step against |{velocity}|*h = {travel:.3g} {unit}): "
                   "{velocity} is probably not the time derivative of the sampled {port}, and the dashpots carry "
                   "every jump; build the input with identification.fmu_input (a continuous path, {velocity} = the "
                   "secant velocity of {port}) or set {velocity} = ({port}(t + h) - {port}(t))/h"),
    # the native FMU's derivatives and event indicators (``where``: the FMI function and ': ', or nothing)
    "NOT_COMPUTABLE": Message("error", "{where}the {what} cannot be computed: {reason}"),
    "JUMP_NOT_DIFFERENTIABLE": Message("error", "{where}{label}{what} cannot be differentiated: the displacement "
                                                "jump from the committed state cannot be taken (check the units of "
                                                "{ports}: metres)"),
    "DERIVATIVE_NOT_FINITE": Message("error", "{where}the derivative of {name} is not finite ({value:g}): "
                                              "check the units of the inputs and the states set"),
    "RATE_DERIVATIVE_NOT_FINITE": Message("error", "{where}{label}the derivative of the rate of state {index:d} is "
                                                   "not finite ({value:g}): check the units of the inputs and the "
                                                   "states set"),
}
"""Every message of both runtimes' policy, by name (``BW_MESSAGE_<NAME>`` in C)."""

INPUTS = "{displacement} = {x} {x_unit}, {velocity} = {v} {v_unit}"
"""One axis's inputs in a refusal or warning (``inputs``; a group's members joined by ', ')."""
