"""Parameter sets on disk: the project's JSON and SSP 1.0 ParameterValues (``.ssv``), both ways.

JSON: ``{"model": "<FMI identifier>", "units": "N-mm-s", "parameters": {name: value},
"fit": {...provenance...}}``. An ensemble (the parameter sets a fit cannot tell apart) is the
same document with ``"ensemble": [{name: value}, ...]`` added; its ``parameters`` are the
best member, so every reader of parameter files takes an ensemble file too. SSV: an ``ssv:ParameterSet`` named after the model's FMI
identifier, one ``ssv:Real`` per parameter with its unit where SSP can express it (beta and
gamma, in N^(1-n)/mm, carry none: SSP units need integer SI exponents). Values are written
with ``repr`` and read back bit for bit.

Every read is validated against the model: missing or unknown names, non-numbers, NaN and a
unit other than the parameter's raise ``ParameterError`` naming the file, the parameter and
what is allowed.

Six axes (``SixAxisBushing``, see ``axes``): ``{"model": "SixAxisBushing", "units": "N-mm-s",
"axes": {"x": {"model": "BoucWenBushing", "parameters": {...}}, ..., "rz": {"model":
"KelvinVoigtBushing", "parameters": {...}}}}``, every one of the six axes present, rotational
axes in N.mm, rad, s; as SSV one ParameterSet named ``SixAxisBushing`` with the FMU's names
``x.k0`` ..., each axis's model told by its parameter names. Errors name the axis.

For fmpy users: ``simulate_fmu(fmu, start_values=load_parameters("bushing.ssv"), ...)``.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping
from xml.etree import ElementTree as ET

from .fmi.runtime_messages import MESSAGES
from .fmi.axes import ONE_AXIS, SIX_AXES, SIX_AXIS_IDENTIFIER, SIX_AXIS_NAMES, Coupling, model_on_axis
from .model.registry import BushingModel, DEFAULT_MODEL, MODELS, get_model
from .model.parameter_specs import UNIT_SYSTEM, ParameterError
from .model.units import UnitError, si_form

SSV_NAMESPACES = {"ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
                  "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon"}


@dataclass
class ParameterSet:
    model: BushingModel
    parameters: dict[str, float]     # the model's units (paper N-mm-s)
    provenance: dict = field(default_factory=dict)


@dataclass
class ParameterEnsemble:
    model: BushingModel
    members: list[dict[str, float]]   # the first is the best fit
    provenance: dict = field(default_factory=dict)


def load_parameters(path: str | Path, model: str | None = None) -> dict[str, float]:
    """The parameters in ``path`` (JSON or .ssv), checked against ``model`` if given (a
    command-line name such as ``"spencer"`` or an FMI identifier); without it, the model the
    file names (default: the proposed one)."""
    return read_parameter_set(path, model).parameters


def read_parameter_set(path: str | Path, model: str | None = None) -> ParameterSet:
    """Read and validate one parameter set.

    Parameters
    ----------
    path : str or Path
        A JSON parameter file (as ``save_parameters`` or a fit writes it) or an SSP 1.0
        ``.ssv`` ParameterValues file. Values are in the paper's N-mm-s units.
    model : str, optional
        The model it must be for (name such as ``"spencer"`` or FMI identifier); default: the
        model the file names, else the proposed one.

    Returns
    -------
    ParameterSet
        The model, the validated values and the file's provenance (a fit's record).

    Raises
    ------
    ParameterError
        A missing file, another model, or a value out of its allowed range (named, with its
        unit and range).
    """
    path = Path(path)
    if not path.exists():
        raise ParameterError(f"parameter file {path} does not exist")
    expected = get_model(model) if model is not None else None
    if path.suffix.lower() == ".ssv":
        found, values, provenance = _read_ssv(path, expected)
    else:
        found, values, provenance = _read_json(path)
    if expected is not None and found is not expected:
        raise ParameterError(f"parameter file {path} is for the {found.name} model ({found.identifier}), "
                             f"not {expected.name} ({expected.identifier})")
    try:
        return ParameterSet(found, found.check(values), provenance)
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from None


def read_ensemble(path: str | Path, model: str | None = None) -> ParameterEnsemble:
    """Read an ensemble: the parameter sets a fit could not tell apart, best first.

    Parameters
    ----------
    path : str or Path
        An ensemble file (``fit --ensemble``, ``save_ensemble``); a parameter file (JSON or
        ``.ssv``) reads as an ensemble of its one set.
    model : str, optional
        The model it must be for; default: the model the file names.

    Returns
    -------
    ParameterEnsemble
        The model, the members (each validated like ``read_parameter_set``) and the provenance.

    Raises
    ------
    ParameterError
        An invalid member (numbered), or a first member that differs from the file's best set.
    """
    path = Path(path)
    best = read_parameter_set(path, model)
    if path.suffix.lower() == ".ssv":
        return ParameterEnsemble(best.model, [best.parameters], best.provenance)
    members = _json_document(path).get("ensemble")
    if members is None:
        return ParameterEnsemble(best.model, [best.parameters], best.provenance)
    if not isinstance(members, list) or not members or not all(isinstance(m, dict) for m in members):
        raise ParameterError(f"{path}: 'ensemble' must be a non-empty list of parameter objects")
    checked = []
    for number, member in enumerate(members, start=1):
        try:
            checked.append(best.model.check(member))
        except ParameterError as exc:
            raise ParameterError(f"{path}, ensemble member {number}: {exc}") from None
    if checked[0] != best.parameters:
        raise ParameterError(f"{path}: the first ensemble member differs from 'parameters' (the best fit, which "
                             "build_fmu.py uses); an edited file? Make them the same")
    return ParameterEnsemble(best.model, checked, best.provenance)


def save_ensemble(path: str | Path, members, model: str = DEFAULT_MODEL, provenance: Mapping | None = None) -> Path:
    """Write an ensemble as JSON: the best member as the file's parameter set, all members after.

    Parameters
    ----------
    path : str or Path
        A ``.json`` file (SSP holds one set only: ``.ssv`` is refused).
    members : iterable of mappings
        Parameter sets in the paper's N-mm-s units, the best first.
    model : str
        The model's name or FMI identifier (default ``"proposed"``).
    provenance : mapping, optional
        What made the ensemble (a fit's record).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    ParameterError
        An ``.ssv`` path, no members, or an invalid member.
    """
    path = Path(path)
    if path.suffix.lower() == ".ssv":
        raise ParameterError(f"{path}: an ensemble is written as JSON (.json), SSP holds one parameter set")
    members = list(members)
    if not members:
        raise ParameterError("an ensemble needs at least one parameter set")
    document = parameter_document(members[0], model, provenance)
    document["ensemble"] = [get_model(model).check(member) for member in members]
    path.write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
    return path


def _json_document(path: Path) -> dict:
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise ParameterError(f"parameter file {path} is not valid JSON: {exc}") from None
    if not isinstance(document, dict):
        raise ParameterError(f"parameter file {path} is not a JSON object")
    return document


def _read_json(path: Path):
    document = _json_document(path)
    if not isinstance(document.get("parameters"), dict):
        raise ParameterError(f"parameter file {path} has no 'parameters' object")
    units = document.get("units", UNIT_SYSTEM)
    if units != UNIT_SYSTEM:
        raise ParameterError(f"parameter file {path} declares units {units!r}; only {UNIT_SYSTEM!r} is supported")
    model = get_model(document.get("model", MODELS[DEFAULT_MODEL].identifier))
    return model, document["parameters"], dict(document.get("fit", {}))


def _read_ssv(path: Path, expected: BushingModel | None):
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise ParameterError(f"parameter file {path} is not valid XML: {exc}") from None
    raw: dict[str, tuple[str | None, str | None]] = {}
    for parameter in root.iterfind("ssv:Parameters/ssv:Parameter", SSV_NAMESPACES):
        name = parameter.get("name")
        real = parameter.find("ssv:Real", SSV_NAMESPACES)
        if real is None:
            raise ParameterError(f"{path}: parameter {name!r} is not an ssv:Real")
        raw[name] = (real.get("value"), real.get("unit"))
    model = _model_of_ssv(root.get("name"), set(raw)) or expected or MODELS[DEFAULT_MODEL]
    return model, _ssv_values(raw, model, f"{path}", " (the paper's N-mm-s units)"), {}


def _ssv_values(raw: Mapping[str, tuple[str | None, str | None]], model: BushingModel, where: str,
                units_note: str = "") -> dict[str, float]:
    """{name: (value text, unit or None)} as floats, each unit checked against ``model``'s;
    ParameterError starts with ``where`` (the file, and the axis)."""
    values = {}
    for name, (text, unit) in raw.items():
        units = model.fmu_units
        if unit is not None and name in units and unit != units[name]:
            raise ParameterError(f"{where}: parameter {name} has unit {unit!r}; expected "
                                 f"{units[name]!r}{units_note}")
        try:
            values[name] = float(text)
        except (TypeError, ValueError):
            raise ParameterError(f"{where}: parameter {name} = {text!r} is not a number") from None
    return values


def _model_of_ssv(set_name: str | None, names: set[str]) -> BushingModel | None:
    """The model a ParameterSet is for: by its name (our files use the FMI identifier), else
    the model whose parameter names it holds exactly; None if neither tells. A model with options
    (``BoucWenBushing_Maxwell_Wlf``) goes by its identifier."""
    for model in MODELS.values():
        if set_name == model.identifier:
            return model
    if set_name and "_" in set_name:
        try:
            return get_model(set_name)
        except ParameterError:       # not an identifier: the names decide
            pass
    for model in MODELS.values():     # its own parameters, and the mounting's where given
        if set(model.parameter_names) <= names <= set(model.fmu_units):
            return model
    return None


def parameter_document(params: Mapping[str, float], model: str = DEFAULT_MODEL,
                       provenance: Mapping | None = None) -> dict:
    """The JSON document :func:`save_parameters` writes (validated)."""
    bushing = get_model(model)
    return {"model": bushing.identifier, "units": UNIT_SYSTEM, "parameters": bushing.check(params),
            "fit": dict(provenance or {})}


def save_parameters(path: str | Path, params: Mapping[str, float], model: str = DEFAULT_MODEL,
                    provenance: Mapping | None = None) -> Path:
    """Write a validated parameter set, which ``build_fmu.py --params`` and every reader take.

    Parameters
    ----------
    path : str or Path
        ``.ssv``: SSP 1.0 ParameterValues (values and units only); anything else: JSON with the
        model, the unit system and ``provenance``.
    params : mapping of str to float
        The model's parameters in the paper's N-mm-s units.
    model : str
        The model's name or FMI identifier (default ``"proposed"``).
    provenance : mapping, optional
        What made the set (a fit's record), stored under ``"fit"`` in JSON.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    ParameterError
        A missing, unknown or out-of-range parameter (nothing is written).
    """
    path = Path(path)
    if path.suffix.lower() == ".ssv":
        _write_ssv(path, params, get_model(model))
    else:
        text = json.dumps(parameter_document(params, model, provenance), indent=2) + "\n"
        path.write_text(text, encoding="utf-8")
    return path


def _write_ssv(path: Path, params: Mapping[str, float], model: BushingModel) -> None:
    write_ssv_values(path, model.identifier, model.check(params), model.fmu_units)


def _si_form_if_any(unit: str) -> dict[str, str] | None:
    try:
        return si_form(unit)
    except UnitError:
        return None


def write_ssv_values(path: Path, set_name: str, values: Mapping[str, float], units: Mapping[str, str]) -> None:
    """One ssv:ParameterSet of ``values`` (names in order) with their ``units`` (a unit that
    ``units.si_form`` cannot express in SI base units, or cannot read, such as another FMU's
    ``degC``, is left out, never written wrong)."""
    ssv, ssc = SSV_NAMESPACES["ssv"], SSV_NAMESPACES["ssc"]
    ET.register_namespace("ssv", ssv)
    ET.register_namespace("ssc", ssc)
    root = ET.Element(f"{{{ssv}}}ParameterSet", version="1.0", name=set_name)
    parameters = ET.SubElement(root, f"{{{ssv}}}Parameters")
    # SSP requires a BaseUnit for every unit, which N^(1-n)/mm (beta, gamma) cannot have:
    # those values go without a unit attribute rather than with a false one.
    expressible = {name: unit for name, unit in units.items() if _si_form_if_any(unit) is not None}
    for name, value in values.items():
        element = ET.SubElement(parameters, f"{{{ssv}}}Parameter", name=name)
        real = ET.SubElement(element, f"{{{ssv}}}Real", value=repr(value))
        if name in expressible:
            real.set("unit", expressible[name])
    units = ET.SubElement(root, f"{{{ssv}}}Units")
    for unit in sorted(set(expressible.values())):
        element = ET.SubElement(units, f"{{{ssc}}}Unit", name=unit)
        ET.SubElement(element, f"{{{ssc}}}BaseUnit", si_form(unit))
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="UTF-8", xml_declaration=True)


# ---------------------------------------------------------------------------- six axes
@dataclass
class SixAxisSet:
    """The six axes of a ``SixAxisBushing``: each axis's model (with the axis's units, see
    ``axes.model_on_axis``) and parameters, in the order x, y, z, rx, ry, rz, and which of them
    are coupled (``axes.Coupling``; checked by :func:`check_groups`)."""
    axes: dict[str, ParameterSet]
    provenance: dict = field(default_factory=dict)
    coupling: Coupling = field(default_factory=Coupling)

    def fmu_groups(self) -> tuple[tuple[int, ...], ...]:
        """The coupled groups as positions in :meth:`fmu_axes` (x = 0 ... rz = 5)."""
        return tuple(tuple(SIX_AXIS_NAMES.index(name) for name in group) for group in self.coupling.groups)

    def flat(self) -> dict[str, float]:
        """The FMU's parameter names and values: {"x.k0": ..., "rz.c": ...}."""
        return {f"{axis}.{name}": value for axis, one in self.axes.items() for name, value in one.parameters.items()}

    def fmu_axes(self) -> list:
        """[(axes.Axis, model on that axis, parameters)] in the order x, y, z, rx, ry, rz."""
        return [(axis, self.axes[axis.name].model, self.axes[axis.name].parameters) for axis in SIX_AXES]


def read_six_axis(path: str | Path) -> SixAxisSet:
    """A six-axis parameter file (JSON or .ssv), every axis validated like a one-axis set;
    ParameterError names the file and the axis."""
    path = Path(path)
    if not path.exists():
        raise ParameterError(f"parameter file {path} does not exist")
    if path.suffix.lower() == ".ssv":
        return _read_six_axis_ssv(path)
    document = _json_document(path)
    if document.get("model") != SIX_AXIS_IDENTIFIER or not isinstance(document.get("axes"), dict):
        raise ParameterError(f"parameter file {path} is not a six-axis file: it needs \"model\": "
                             f"\"{SIX_AXIS_IDENTIFIER}\" and an \"axes\" object with {', '.join(SIX_AXIS_NAMES)}")
    units = document.get("units", UNIT_SYSTEM)
    if units != UNIT_SYSTEM:
        raise ParameterError(f"parameter file {path} declares units {units!r}; only {UNIT_SYSTEM!r} is supported "
                             "(rotational axes in N.mm, rad, s)")
    found = document["axes"]
    _check_axis_names(path, set(found))
    try:
        coupling = Coupling.of(document.get("coupling"))
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from None
    axes = {}
    for axis in SIX_AXES:
        entry = found[axis.name]
        if not isinstance(entry, dict) or not isinstance(entry.get("parameters"), dict) or "model" not in entry:
            raise ParameterError(f"{path}, axis {axis.name}: needs a \"model\" (one of "
                                 f"{', '.join(m.identifier for m in MODELS.values())}) and a \"parameters\" object")
        try:
            model = model_on_axis(get_model(entry["model"]), axis)
            axes[axis.name] = ParameterSet(model, model.check(entry["parameters"]))
        except ParameterError as exc:
            raise ParameterError(f"{path}, axis {axis.name}: {exc}") from None
    check_groups(coupling, axes, f"{path}: ")
    return SixAxisSet(axes, dict(document.get("fit", {})), coupling)


def check_groups(coupling: Coupling, axes: Mapping[str, ParameterSet], where: str = "") -> None:
    """Refuse a coupled group whose axes carry different models or parameters (their mounting may
    differ: an offset and a preload per axis), or a parameter that a coupled model requires to be 0
    (``CoupledKernels.zero_parameters``), or a held force at rest (a group starts relaxed);
    ParameterError names the group, the axes, the values and what is allowed."""
    for kind, group in coupling.named_groups:
        sets = {name: axes[name] for name in group}
        label = f"{where}the {kind} group ({', '.join(group)})"
        models = {name: one.model.name for name, one in sets.items()}
        if len(set(models.values())) > 1:
            listed = ", ".join(f"{axis}: {model}" for axis, model in models.items())
            raise ParameterError(f"{label} carries different models ({listed}); the axes of a group carry one model "
                                 "and one parameter set")
        model = sets[group[0]].model
        differing = [name for name in model.parameter_names
                     if len({one.parameters[name] for one in sets.values()}) > 1]
        if differing:
            values = ["; ".join(", ".join(f"{axis}.{name} = {sets[axis].parameters[name]!r}" for axis in group)
                                + f" [{model.units[name]}]" for name in differing)]
            raise ParameterError(f"{label}: {values[0]} differ; the axes of a group carry one parameter set (their "
                                 "offset and preload may differ)")
        for name in (model.coupled.zero_parameters if model.coupled is not None else ()):
            value = sets[group[0]].parameters[name]
            if value != 0.0:
                raise ParameterError(MESSAGES["GROUP_PARAMETER_NOT_ZERO"].text(
                    label=f"{label}: ", name=name, value=repr(value), unit=model.units[name]))
        for axis in (group if model.coupled is not None else ()):   # a group of a model without a
            held = model.held_force(sets[axis].parameters)              # coupled form runs its axes alone
            if held != 0.0:
                raise ParameterError(MESSAGES["GROUP_HELD_FORCE_NOT_ZERO"].text(
                    label=f"{label}: ", axis=axis, value=repr(held), unit=model.fmu_units["held_force"]))


def _check_axis_names(path: Path, names: set[str]) -> None:
    missing = [name for name in SIX_AXIS_NAMES if name not in names]
    unknown = sorted(names - set(SIX_AXIS_NAMES))
    if missing or unknown:
        raise ParameterError(f"{path}: " + "; ".join(
            ([f"missing axes {', '.join(missing)}"] if missing else [])
            + ([f"unknown axes {', '.join(unknown)}"] if unknown else []))
            + f" (the six axes are {', '.join(SIX_AXIS_NAMES)})")


def _read_six_axis_ssv(path: Path) -> SixAxisSet:
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise ParameterError(f"parameter file {path} is not valid XML: {exc}") from None
    grouped: dict[str, dict[str, tuple[str | None, str | None]]] = {}
    for parameter in root.iterfind("ssv:Parameters/ssv:Parameter", SSV_NAMESPACES):
        name = parameter.get("name") or ""
        real = parameter.find("ssv:Real", SSV_NAMESPACES)
        if real is None:
            raise ParameterError(f"{path}: parameter {name!r} is not an ssv:Real")
        axis, _, short = name.partition(".")
        if not short:
            raise ParameterError(f"{path}: parameter {name!r} is not named <axis>.<name> (x.k0, rz.c, ...)")
        grouped.setdefault(axis, {})[short] = (real.get("value"), real.get("unit"))
    _check_axis_names(path, set(grouped))
    axes = {}
    for axis in SIX_AXES:
        raw = grouped[axis.name]
        base = _model_of_ssv(None, set(raw))
        if base is None:
            raise ParameterError(f"{path}, axis {axis.name}: its parameters {', '.join(sorted(raw))} are not those of "
                                 "any model (" + "; ".join(f"{m.name}: {', '.join(m.parameter_names)}"
                                                            for m in MODELS.values()) + ")")
        model = model_on_axis(base, axis)
        values = _ssv_values(raw, model, f"{path}, axis {axis.name}")
        try:
            axes[axis.name] = ParameterSet(model, model.check(values))
        except ParameterError as exc:
            raise ParameterError(f"{path}, axis {axis.name}: {exc}") from None
    return SixAxisSet(axes, {})


def six_axis_document(axes: Mapping[str, tuple[str, Mapping[str, float]]], provenance: Mapping | None = None,
                      coupling=None) -> dict:
    """The JSON document of six axes, ``axes`` = {axis: (model name or identifier, parameters)}
    (validated, each in its axis's units), with ``coupling`` (``axes.Coupling`` or what
    ``Coupling.of`` takes; written where any group is coupled, checked by :func:`check_groups`)."""
    path = Path("<six-axis set>")
    _check_axis_names(path, set(axes))
    coupling = Coupling.of(coupling)
    document = {"model": SIX_AXIS_IDENTIFIER, "units": UNIT_SYSTEM, "axes": {}, "fit": dict(provenance or {})}
    if coupling.groups:
        document["coupling"] = coupling.as_json()
    sets = {}
    for axis in SIX_AXES:
        name, params = axes[axis.name]
        try:
            model = model_on_axis(get_model(name), axis)
            sets[axis.name] = ParameterSet(model, model.check(params))
            document["axes"][axis.name] = {"model": model.identifier, "parameters": sets[axis.name].parameters}
        except ParameterError as exc:
            raise ParameterError(f"axis {axis.name}: {exc}") from None
    check_groups(coupling, sets)
    return document


def save_six_axis(path: str | Path, axes: Mapping[str, tuple[str, Mapping[str, float]]],
                  provenance: Mapping | None = None, coupling=None) -> Path:
    """Write six axes (see :func:`six_axis_document`): ``.ssv`` as SSP 1.0 ParameterValues with
    the FMU's names (``x.k0``), else JSON. SSP holds values only: a coupled set is refused as
    ``.ssv`` (its coupling is the JSON file's, which ``build_fmu.py --params`` builds the FMU with;
    the values of an ``.ssv`` apply to such an FMU as start values)."""
    path = Path(path)
    document = six_axis_document(axes, provenance, coupling)
    if path.suffix.lower() == ".ssv" and "coupling" in document:
        raise ParameterError(f"{path}: SSP parameter values cannot hold the coupling "
                             f"({Coupling.of(coupling).describe()}); write the coupled set as .json")
    if path.suffix.lower() == ".ssv":
        values, units = {}, {}
        for axis in SIX_AXES:
            entry = document["axes"][axis.name]
            model = model_on_axis(get_model(entry["model"]), axis)
            for name, value in entry["parameters"].items():
                values[f"{axis.name}.{name}"] = value
                units[f"{axis.name}.{name}"] = model.fmu_units[name]
        write_ssv_values(path, SIX_AXIS_IDENTIFIER, values, units)
    else:
        path.write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
    return path


def fmu_axes(path: str | Path) -> list:
    """What an FMU runs with the JSON parameter file ``path`` (its packed defaults):
    [(axes.Axis, model on that axis, parameters)], one entry for a one-axis file, six for a
    six-axis file."""
    if _json_document(Path(path)).get("model") == SIX_AXIS_IDENTIFIER:
        return read_six_axis(path).fmu_axes()
    one = read_parameter_set(path)
    return [(ONE_AXIS, one.model, one.parameters)]


def fmu_groups(path: str | Path) -> tuple[tuple[int, ...], ...]:
    """The coupled groups of the FMU with the JSON parameter file ``path``, as positions in
    :func:`fmu_axes` (none for a one-axis file)."""
    if _json_document(Path(path)).get("model") == SIX_AXIS_IDENTIFIER:
        return read_six_axis(path).fmu_groups()
    return ()
