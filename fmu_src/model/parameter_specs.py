"""Parameters of every bushing model: their specification (name, unit, meaning, allowed
range), the units the FMU and parameter files declare, and validation.

Units are the paper's N-mm-s units so that its tables can be typed in verbatim:
stiffnesses k and the Bouc-Wen gains A in N/mm, dampings c in N*s/mm, beta and gamma
in N^(1-n)/mm (so that beta*|z|^n is in N/mm with z in N), alpha and n dimensionless.
Each model's own parameters are in its module (``proposed_model`` ...).

Validation never raises: it returns human-readable problems, each naming the parameter,
its value, its unit and what is allowed, so that the FMU can log them with an FMI status
and the identification can raise them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from .units import UnitError, si_form

UNIT_SYSTEM = "N-mm-s"

TEMPERATURE_ROLES = ("viscous", "elastic", "friction", "none")
"""How a temperature law may change a parameter (``ParameterSpec.temperature``)."""


# The rules' words (``str.format`` templates), which the FMUs' runtimes log too (``fmi.runtime_messages``).
NOT_FINITE = "{name} = {value} [{unit}] must be a finite number"
OUT_OF_RANGE = "{name} = {value} [{unit}] must be {allowed}{why}"
"""``why``: the spec's reason in parentheses after a space, or nothing."""
CONSTRAINT_BROKEN = "{expression} = {value}{unit} must be {condition} ({why})"
"""``unit``: a space and the constraint's unit, or nothing; ``condition``: '> 0', '>= 1' …"""
CONSTRAINT_DOUBTFUL = "{expression} = {value}{unit} violates {why} {expression} {condition}"


@dataclass(frozen=True)
class ParameterSpec:
    """A parameter's name, unit, meaning and allowed range: ``minimum`` and ``maximum`` (None: no
    bound on that side), both exclusive if ``exclusive``, with ``why`` the range is what it is.
    Values outside are refused everywhere: by the FMU, by parameter files and by the
    identification. ``bound_powers`` = (p, q): how the parameter enters the force an FMU warns
    above (``BushingModel.plausible_force_bound``): |value| * travel^p * velocity^q; None: by its
    unit (a stiffness (1, 0), a damping (0, 1), anything else not at all)."""
    name: str
    unit: str
    description: str
    minimum: float | None = None
    exclusive: bool = False
    why: str = ""
    maximum: float | None = None
    bound_powers: tuple[int, int] | None = None
    temperature: str = ""
    """How a temperature law (``options.wlf``) changes the parameter: ``viscous`` (a rate's
    coefficient: times the time-temperature shift a_T), ``elastic`` (a stiffness or a static
    force: times the law's elastic factor), ``friction`` (a sliding level: times its friction
    factor), ``none`` (unchanged); "" (default): by its unit (``temperature_role``)."""

    def __post_init__(self):
        try:
            si_form(self.unit)
        except UnitError as exc:
            raise UnitError(f"parameter {self.name}: {exc}") from None
        if self.temperature not in TEMPERATURE_ROLES + ("",):
            raise ValueError(f"parameter {self.name}: temperature role {self.temperature!r} is not one of "
                             f"{', '.join(TEMPERATURE_ROLES)}")

    @property
    def temperature_role(self) -> str:
        """Its ``temperature`` role, or the one its unit implies: N.s/mm a dashpot (viscous); N/mm,
        N/mm^3 and N/mm^e a stiffness (elastic); N a sliding level (friction); anything else none
        (a displacement, an exponent, a shape; a fractional coefficient, whose shift would be
        a_T^alpha, and a fluid's mass)."""
        if self.temperature:
            return self.temperature
        if self.unit == "N.s/mm":
            return "viscous"
        if self.unit == "N/mm" or self.unit.startswith("N/mm^"):
            return "elastic"
        return "friction" if self.unit == "N" else "none"

    @property
    def allowed(self) -> str:
        """The allowed range in words: '> 0', '>= 0', 'in (0, 1)', '<= 5' or 'any finite value'."""
        if self.minimum is None and self.maximum is None:
            return "any finite value"
        if self.maximum is None:
            return f"{'>' if self.exclusive else '>='} {self.minimum:g}"
        if self.minimum is None:
            return f"{'<' if self.exclusive else '<='} {self.maximum:g}"
        brackets = "()" if self.exclusive else "[]"
        return f"in {brackets[0]}{self.minimum:g}, {self.maximum:g}{brackets[1]}"

    def range_error(self, value: float) -> str | None:
        """What is wrong with a finite ``value``, or None if it is in range."""
        above = self.minimum is None or (value > self.minimum if self.exclusive else value >= self.minimum)
        below = self.maximum is None or (value < self.maximum if self.exclusive else value <= self.maximum)
        if above and below:
            return None
        return OUT_OF_RANGE.format(name=self.name, value=value, unit=self.unit, allowed=self.allowed,
                                   why=f" ({self.why})" if self.why else "")


@dataclass(frozen=True)
class Constraint:
    """A condition on several parameters, sum(coefficient * parameter) > bound (``strict``) or
    >= bound, with what breaking it means: an ``error`` (the equations cannot take the set) or a
    warning (simulable but doubtful), and ``why`` in words. Declared here rather than written as
    code, so that the FMUs, the native one's C included, check the same conditions."""
    terms: tuple[tuple[str, float], ...]
    bound: float
    strict: bool
    error: bool
    unit: str
    why: str

    @property
    def expression(self) -> str:
        """The left side in words: 'c0 + c2', 'beta2 - gamma2', 'A1'."""
        text = ""
        for i, (name, coefficient) in enumerate(self.terms):
            if coefficient not in (1.0, -1.0):
                raise ValueError(f"a constraint's coefficients are +1 or -1, not {coefficient}")
            text += (name if coefficient > 0 else f"-{name}") if i == 0 else \
                f" {'+' if coefficient > 0 else '-'} {name}"
        return text

    def value(self, p: Mapping[str, float]) -> float:
        total = 0.0
        for name, coefficient in self.terms:
            total += coefficient * p[name]
        return total

    def message(self, p: Mapping[str, float]) -> str | None:
        """What is wrong with the finite set ``p``, or None if it meets the condition."""
        value = self.value(p)
        if value > self.bound if self.strict else value >= self.bound:
            return None
        fields = dict(expression=self.expression, value=value, unit=f" {self.unit}" if self.unit else "",
                      condition=f"{'>' if self.strict else '>='} {self.bound:g}", why=self.why)
        return (CONSTRAINT_BROKEN if self.error else CONSTRAINT_DOUBTFUL).format(**fields)


SPRING = dict(minimum=0.0, why="a negative spring is unstable")
DAMPING = dict(minimum=0.0, why="a negative dashpot adds energy")
WEIGHT = dict(minimum=0.0, why="a negative weight turns the hysteresis loop inside out")
GAIN = dict(minimum=0.0, why="a negative initial stiffness of the hysteresis is unstable")
EXPONENT = dict(minimum=0.0, exclusive=True, why="exponent of |z|")


class ParameterError(ValueError):
    """A parameter set that the model cannot simulate; the message lists every problem."""


def number_errors(params: Mapping[str, float], units: Mapping[str, str], model_label: str = "") -> list[str]:
    """Missing names, non-numbers and NaN/Inf among ``params`` (``units``: name -> unit of
    every parameter the model needs); shared by every model."""
    missing = [name for name in units if name not in params]
    if missing:
        return [f"missing parameters{model_label}: {', '.join(missing)}"]
    errors = []
    for name, unit in units.items():
        value = params[name]
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            errors.append(f"{name} = {value!r} is not a number (unit {unit})")
        elif not math.isfinite(value):
            errors.append(NOT_FINITE.format(name=name, value=value, unit=unit))
    return errors


def range_errors(p: Mapping[str, float], specs: tuple[ParameterSpec, ...]) -> list[str]:
    """Every value of ``p`` (finite floats) outside its spec's allowed range."""
    return [error for spec in specs if (error := spec.range_error(p[spec.name])) is not None]


def constraint_messages(p: Mapping[str, float], constraints: tuple[Constraint, ...]) -> tuple[list[str], list[str]]:
    """(errors, warnings) of the finite set ``p`` against ``constraints``."""
    broken = [(c, message) for c in constraints if (message := c.message(p)) is not None]
    return [m for c, m in broken if c.error], [m for c, m in broken if not c.error]
