"""The 16 parameters of the proposed bushing model: names, units, validation.

Units are the paper's N-mm-s units so that its tables can be typed in verbatim:
stiffnesses k and the Bouc-Wen gains A in N/mm, dampings c in N*s/mm, beta and gamma
in N^(1-n)/mm (so that beta*|z|^n is in N/mm with z in N), alpha and n dimensionless.

Validation never raises: it returns human-readable problems, each naming the parameter,
its value, its unit and what is allowed, so that the FMU can log them with an FMI status
and the identification can raise them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

MODEL_NAME = "BoucWenBushing"
UNIT_SYSTEM = "N-mm-s"


@dataclass(frozen=True)
class ParameterSpec:
    """A parameter's name, unit, meaning and allowed range: ``minimum`` (inclusive unless
    ``exclusive``; None: any finite value), with ``why`` the range is what it is. Values outside
    are refused everywhere: by the FMU, by parameter files and by the identification."""
    name: str
    unit: str
    description: str
    minimum: float | None = None
    exclusive: bool = False
    why: str = ""

    @property
    def allowed(self) -> str:
        """The allowed range in words: '> 0', '>= 0' or 'any finite value'."""
        if self.minimum is None:
            return "any finite value"
        return f"{'>' if self.exclusive else '>='} {self.minimum:g}"

    def range_error(self, value: float) -> str | None:
        """What is wrong with a finite ``value``, or None if it is in range."""
        if self.minimum is None or (value > self.minimum if self.exclusive else value >= self.minimum):
            return None
        return f"{self.name} = {value} [{self.unit}] must be {self.allowed}" + (f" ({self.why})" if self.why else "")


SPRING = dict(minimum=0.0, why="a negative spring is unstable")
DAMPING = dict(minimum=0.0, why="a negative dashpot adds energy")
WEIGHT = dict(minimum=0.0, why="a negative weight turns the hysteresis loop inside out")
GAIN = dict(minimum=0.0, why="a negative initial stiffness of the hysteresis is unstable")
EXPONENT = dict(minimum=0.0, exclusive=True, why="exponent of |z|")


PARAMETER_SPECS: tuple[ParameterSpec, ...] = (
    ParameterSpec("c0", "N.s/mm", "dashpot in series with the right block; roll-off at low velocity", **DAMPING),
    ParameterSpec("k0", "N/mm", "spring from the left plate y to ground; main static stiffness", **SPRING),
    ParameterSpec("c1", "N.s/mm", "dashpot between x and y; relaxation of the impact force",
                  minimum=0.0, exclusive=True, why="it divides eq. 3"),
    ParameterSpec("k1", "N/mm", "spring between x and y (standard solid)", **SPRING),
    ParameterSpec("c2", "N.s/mm", "dashpot between x and w; viscous damping at large velocity", **DAMPING),
    ParameterSpec("k2", "N/mm", "spring between x and w; stiffness at large velocity", **SPRING),
    ParameterSpec("alpha1", "1", "weight of the hysteretic force z1 on the left plate", **WEIGHT),
    ParameterSpec("alpha2", "1", "weight of the hysteretic force z2 on the right plate", **WEIGHT),
    ParameterSpec("beta1", "N^(1-n1)/mm", "Bouc-Wen shape parameter of z1 (eq. 1)"),
    ParameterSpec("beta2", "N^(1-n2)/mm", "Bouc-Wen shape parameter of z2 (eq. 2)"),
    ParameterSpec("gamma1", "N^(1-n1)/mm", "Bouc-Wen shape parameter of z1 (eq. 1)"),
    ParameterSpec("gamma2", "N^(1-n2)/mm", "Bouc-Wen shape parameter of z2 (eq. 2)"),
    ParameterSpec("n1", "1", "Bouc-Wen exponent of z1 (smoothness of the transition)", **EXPONENT),
    ParameterSpec("n2", "1", "Bouc-Wen exponent of z2", **EXPONENT),
    ParameterSpec("A1", "N/mm", "Bouc-Wen initial stiffness of z1", **GAIN),
    ParameterSpec("A2", "N/mm", "Bouc-Wen initial stiffness of z2", **GAIN),
)
PARAMETER_NAMES: tuple[str, ...] = tuple(spec.name for spec in PARAMETER_SPECS)
PARAMETER_UNITS: dict[str, str] = {spec.name: spec.unit for spec in PARAMETER_SPECS}

UNIT_DEFINITIONS: dict[str, dict[str, str] | None] = {
    # name -> SI base-unit exponents and factor (value_SI = factor * value), as FMI and SSP
    # write them; None: no SI form.
    "m": {"m": "1"},
    "m/s": {"m": "1", "s": "-1"},
    "N": {"kg": "1", "m": "1", "s": "-2"},
    "N/mm": {"kg": "1", "s": "-2", "factor": "1000"},
    "N.s/mm": {"kg": "1", "s": "-1", "factor": "1000"},
    "1": {},
    # beta*|z|^n must be in N/mm, so beta and gamma carry N^(1-n)/mm: a non-integer power
    # that a BaseUnit cannot express. Declared by name only.
    "N^(1-n1)/mm": None,
    "N^(1-n2)/mm": None,
    # the baseline models (bushing_models)
    "mm": {"m": "1", "factor": "0.001"},
    "N^(1-n)/mm": None,
}


class ParameterError(ValueError):
    """A parameter set that the model cannot simulate; the message lists every problem."""


def number_errors(params: Mapping[str, float], units: Mapping[str, str], model_label: str = "") -> list[str]:
    """Missing names, non-numbers and NaN/Inf among ``params`` (``units``: name -> unit of
    every parameter the model needs); shared by every model of ``bushing_models``."""
    missing = [name for name in units if name not in params]
    if missing:
        return [f"missing parameters{model_label}: {', '.join(missing)}"]
    errors = []
    for name, unit in units.items():
        value = params[name]
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            errors.append(f"{name} = {value!r} is not a number (unit {unit})")
        elif not math.isfinite(value):
            errors.append(f"{name} = {value} [{unit}] must be a finite number")
    return errors


def range_errors(p: Mapping[str, float], specs: tuple[ParameterSpec, ...]) -> list[str]:
    """Every value of ``p`` (finite floats) outside its spec's allowed range."""
    return [error for spec in specs if (error := spec.range_error(p[spec.name])) is not None]


def constraint_checks(p: Mapping[str, float]) -> tuple[list[str], list[str]]:
    """(errors, warnings) of the proposed model beyond each value's range (``PARAMETER_SPECS``,
    checked by ``bushing_models``), for a complete set of finite floats.

    Error: c0 + c2 = 0 (it divides eq. 4). Warnings: the paper's identification constraints
    (A >= 1, beta >= 0, beta1 + gamma1 > 0, beta2 - gamma2 > 0), which the equations do not
    need but a fitted bushing should satisfy.
    """
    errors: list[str] = []
    warnings: list[str] = []
    if not p["c0"] + p["c2"] > 0:
        errors.append(f"c0 + c2 = {p['c0'] + p['c2']} N.s/mm must be > 0 (it divides eq. 4)")

    for name in ("A1", "A2"):
        if p[name] < 1:
            warnings.append(f"{name} = {p[name]} N/mm violates the paper's constraint {name} >= 1")
    for name in ("beta1", "beta2"):
        if p[name] < 0:
            warnings.append(f"{name} = {p[name]} violates the paper's constraint {name} >= 0")
    if not p["beta1"] + p["gamma1"] > 0:
        warnings.append(f"beta1 + gamma1 = {p['beta1'] + p['gamma1']} violates the paper's constraint "
                        "beta1 + gamma1 > 0")
    if not p["beta2"] - p["gamma2"] > 0:
        warnings.append(f"beta2 - gamma2 = {p['beta2'] - p['gamma2']} violates the paper's constraint "
                        "beta2 - gamma2 > 0")
    return errors, warnings
