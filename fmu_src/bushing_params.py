"""The 16 parameters of the proposed bushing model: names, units, validation, files.

Units are the paper's N-mm-s units so that its tables can be typed in verbatim:
stiffnesses k and the Bouc-Wen gains A in N/mm, dampings c in N*s/mm, beta and gamma
in N^(1-n)/mm (so that beta*|z|^n is in N/mm with z in N), alpha and n dimensionless.

Validation never raises: it returns human-readable problems, each naming the parameter,
its value, its unit and what is allowed, so that the FMU can log them with an FMI status
and the identification can raise them.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping
from xml.etree import ElementTree as ET

MODEL_NAME = "BoucWenBushing"
UNIT_SYSTEM = "N-mm-s"


@dataclass(frozen=True)
class ParameterSpec:
    name: str
    unit: str
    description: str


PARAMETER_SPECS: tuple[ParameterSpec, ...] = (
    ParameterSpec("c0", "N.s/mm", "dashpot in series with the right block; roll-off at low velocity"),
    ParameterSpec("k0", "N/mm", "spring from the left plate y to ground; main static stiffness"),
    ParameterSpec("c1", "N.s/mm", "dashpot between x and y; relaxation of the impact force"),
    ParameterSpec("k1", "N/mm", "spring between x and y (standard solid)"),
    ParameterSpec("c2", "N.s/mm", "dashpot between x and w; viscous damping at large velocity"),
    ParameterSpec("k2", "N/mm", "spring between x and w; stiffness at large velocity"),
    ParameterSpec("alpha1", "1", "weight of the hysteretic force z1 on the left plate"),
    ParameterSpec("alpha2", "1", "weight of the hysteretic force z2 on the right plate"),
    ParameterSpec("beta1", "N^(1-n1)/mm", "Bouc-Wen shape parameter of z1 (eq. 1)"),
    ParameterSpec("beta2", "N^(1-n2)/mm", "Bouc-Wen shape parameter of z2 (eq. 2)"),
    ParameterSpec("gamma1", "N^(1-n1)/mm", "Bouc-Wen shape parameter of z1 (eq. 1)"),
    ParameterSpec("gamma2", "N^(1-n2)/mm", "Bouc-Wen shape parameter of z2 (eq. 2)"),
    ParameterSpec("n1", "1", "Bouc-Wen exponent of z1 (smoothness of the transition)"),
    ParameterSpec("n2", "1", "Bouc-Wen exponent of z2"),
    ParameterSpec("A1", "N/mm", "Bouc-Wen initial stiffness of z1"),
    ParameterSpec("A2", "N/mm", "Bouc-Wen initial stiffness of z2"),
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
}
SSV_NAMESPACES = {"ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
                  "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon"}


class ParameterError(ValueError):
    """A parameter set that the model cannot simulate; the message lists every problem."""


def validate_parameters(params: Mapping[str, float]) -> tuple[list[str], list[str]]:
    """Check a parameter set (paper units).

    Returns ``(errors, warnings)``. Errors make the model unusable (NaN/Inf, c1 <= 0,
    c0 + c2 <= 0, n <= 0, negative stiffness); warnings are the paper's identification
    constraints (A >= 1, beta >= 0, beta1 + gamma1 > 0, beta2 - gamma2 > 0), which the
    equations do not need but a fitted bushing should satisfy.
    """
    errors: list[str] = []
    warnings: list[str] = []
    missing = [name for name in PARAMETER_NAMES if name not in params]
    if missing:
        errors.append(f"missing parameters: {', '.join(missing)}")
        return errors, warnings
    p = {name: params[name] for name in PARAMETER_NAMES}
    for name, value in p.items():
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            errors.append(f"{name} = {value!r} is not a number (unit {PARAMETER_UNITS[name]})")
        elif not math.isfinite(value):
            errors.append(f"{name} = {value} [{PARAMETER_UNITS[name]}] must be a finite number")
    if errors:
        return errors, warnings

    if not p["c1"] > 0:
        errors.append(f"c1 = {p['c1']} N.s/mm must be > 0 (it divides eq. 3)")
    if not p["c0"] + p["c2"] > 0:
        errors.append(f"c0 + c2 = {p['c0'] + p['c2']} N.s/mm must be > 0 (it divides eq. 4)")
    for name in ("n1", "n2"):
        if not p[name] > 0:
            errors.append(f"{name} = {p[name]} must be > 0 (exponent of |z| in eqs. 1-2)")
    for name in ("k0", "k1", "k2"):
        if p[name] < 0:
            errors.append(f"{name} = {p[name]} N/mm must be >= 0 (a negative spring is unstable)")

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
    for name in ("c0", "c2"):
        if p[name] < 0:
            warnings.append(f"{name} = {p[name]} N.s/mm is a negative damping (unphysical)")
    return errors, warnings


def check_parameters(params: Mapping[str, float]) -> dict[str, float]:
    """Return the 16 parameters as floats, or raise ParameterError listing every error."""
    errors, _ = validate_parameters(params)
    if errors:
        raise ParameterError("invalid bushing parameters: " + "; ".join(errors))
    unknown = sorted(set(params) - set(PARAMETER_NAMES))
    if unknown:
        raise ParameterError(f"unknown parameter names {unknown}; allowed: {', '.join(PARAMETER_NAMES)}")
    return {name: float(params[name]) for name in PARAMETER_NAMES}


def load_parameter_file(path: str | Path) -> dict[str, float]:
    """Read a parameter set (paper units) from the project's JSON format or an SSP 1.0
    ParameterValues file (``.ssv``).

    JSON: ``{"model": "BoucWenBushing", "units": "N-mm-s", "parameters": {16 names: values},
    "fit": {...provenance...}}``. SSV: one ``ssv:Real`` per parameter, whose ``unit``, when
    given, must be the parameter's unit.
    """
    path = Path(path)
    if not path.exists():
        raise ParameterError(f"parameter file {path} does not exist")
    if path.suffix.lower() == ".ssv":
        return _load_ssv(path)
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise ParameterError(f"parameter file {path} is not valid JSON: {exc}") from None
    if not isinstance(document, dict) or "parameters" not in document:
        raise ParameterError(f"parameter file {path} has no 'parameters' object")
    units = document.get("units", UNIT_SYSTEM)
    if units != UNIT_SYSTEM:
        raise ParameterError(f"parameter file {path} declares units {units!r}; only {UNIT_SYSTEM!r} is supported")
    model = document.get("model", MODEL_NAME)
    if model != MODEL_NAME:
        raise ParameterError(f"parameter file {path} is for model {model!r}, not {MODEL_NAME!r}")
    try:
        return check_parameters(document["parameters"])
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from None


def _load_ssv(path: Path) -> dict[str, float]:
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise ParameterError(f"parameter file {path} is not valid XML: {exc}") from None
    values = {}
    for parameter in root.iterfind("ssv:Parameters/ssv:Parameter", SSV_NAMESPACES):
        name = parameter.get("name")
        real = parameter.find("ssv:Real", SSV_NAMESPACES)
        if real is None:
            raise ParameterError(f"{path}: parameter {name!r} is not an ssv:Real")
        unit = real.get("unit")
        if unit is not None and name in PARAMETER_UNITS and unit != PARAMETER_UNITS[name]:
            raise ParameterError(f"{path}: parameter {name} has unit {unit!r}; "
                                 f"expected {PARAMETER_UNITS[name]!r} (the paper's N-mm-s units)")
        try:
            values[name] = float(real.get("value"))
        except (TypeError, ValueError):
            raise ParameterError(f"{path}: parameter {name} = {real.get('value')!r} is not a number") from None
    try:
        return check_parameters(values)
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from None


def save_ssv(path: str | Path, params: Mapping[str, float], name: str = MODEL_NAME) -> None:
    """Write an SSP 1.0 ParameterValues file with the 16 parameters and their units (beta and
    gamma, in N^(1-n)/mm, carry none: SSP units need integer SI exponents)."""
    values = check_parameters(params)
    ssv, ssc = SSV_NAMESPACES["ssv"], SSV_NAMESPACES["ssc"]
    ET.register_namespace("ssv", ssv)
    ET.register_namespace("ssc", ssc)
    root = ET.Element(f"{{{ssv}}}ParameterSet", version="1.0", name=name)
    parameters = ET.SubElement(root, f"{{{ssv}}}Parameters")
    # SSP requires a BaseUnit for every unit, which N^(1-n)/mm (beta, gamma) cannot have:
    # those values go without a unit attribute rather than with a false one.
    expressible = {name: unit for name, unit in PARAMETER_UNITS.items() if UNIT_DEFINITIONS[unit] is not None}
    for parameter_name in PARAMETER_NAMES:
        element = ET.SubElement(parameters, f"{{{ssv}}}Parameter", name=parameter_name)
        real = ET.SubElement(element, f"{{{ssv}}}Real", value=repr(values[parameter_name]))
        if parameter_name in expressible:
            real.set("unit", expressible[parameter_name])
    units = ET.SubElement(root, f"{{{ssv}}}Units")
    for unit in sorted(set(expressible.values())):
        element = ET.SubElement(units, f"{{{ssc}}}Unit", name=unit)
        ET.SubElement(element, f"{{{ssc}}}BaseUnit", UNIT_DEFINITIONS[unit])
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="UTF-8", xml_declaration=True)


def parameter_document(params: Mapping[str, float], provenance: Mapping | None = None) -> dict:
    """The JSON document written by :func:`save_parameter_file`."""
    return {
        "model": MODEL_NAME,
        "units": UNIT_SYSTEM,
        "parameters": {name: float(params[name]) for name in PARAMETER_NAMES},
        "fit": dict(provenance or {}),
    }


def save_parameter_file(path: str | Path, params: Mapping[str, float], provenance: Mapping | None = None) -> None:
    check_parameters(params)
    Path(path).write_text(json.dumps(parameter_document(params, provenance), indent=2) + "\n", encoding="utf-8")
