"""modelDescription.xml of every bushing FMU, written once: the native FMU's (FMI 2.0 or 3.0,
co-simulation and model exchange) and the pythonfmu FMU's (FMI 2.0, co-simulation).

Both read the one variable table (``variables``): the same names, value references, causalities,
units, descriptions and start values; the native FMU adds the states' derivatives, the event
indicators and the time of model exchange. Both declare each output's dependencies from the
activity analysis of the model's kernels (``dependencies``): in co-simulation, the inputs an
output reads at the step's end (x through the jump, v where a dashpot passes it on); with model
exchange as well, the states. What differs between the two FMUs is their :class:`Face`: the
interfaces, the capabilities and the tool that made them.
"""
from __future__ import annotations

import datetime
from xml.dom.minidom import parseString
from xml.etree import ElementTree as ET

from dataclasses import dataclass, field

from .. import __version__
from ..model.units import si_form
from .dependencies import V, X, axis_dependencies, group_dependencies
from .variables import FmuVariable, all_variables, exact_text, fmu_description, fmu_variables, nominal

LOG_CATEGORIES = (("logStatusWarning", "Warnings: values accepted but doubtful (units, the paper's constraints)"),
                  ("logStatusDiscard", "Steps refused"),
                  ("logStatusError", "Errors: values that cannot be used, steps that cannot be taken"),
                  ("logStatusFatal", "Fatal errors"),
                  ("logAll", "Everything else"))
INTERFACES = ("cs", "me")
NATIVE_TOOL = "(build_fmu.py --native)"
"""How the native FMU's description names the tool that made it (after the project's name and version)."""
CAPABILITIES_FMI2 = {"needsExecutionTool": "false", "canBeInstantiatedOnlyOncePerProcess": "false",
                     "canNotUseMemoryManagementFunctions": "false", "canGetAndSetFMUstate": "true",
                     "canSerializeFMUstate": "true", "providesDirectionalDerivative": "true"}


@dataclass(frozen=True)
class Face:
    """How an FMU implements its description: the interfaces it offers (``cs``, ``me``), its FMI 2
    capability flags, how the tool that made it is named (after the project's name and version) and
    the C file it ships (if any)."""
    interfaces: tuple[str, ...]
    tool: str
    capabilities: dict = field(default_factory=lambda: dict(CAPABILITIES_FMI2))
    source_file: str | None = None


def native_face(identifier: str, interfaces=INTERFACES) -> Face:
    """The native FMU's: C compiled for the host, its source shipped, directional derivatives."""
    return Face(tuple(interfaces), NATIVE_TOOL, source_file=f"{identifier}.c")


def pythonfmu_face(pythonfmu_version: str) -> Face:
    """The pythonfmu FMU's: co-simulation in a Python interpreter (pythonfmu 0.7's capabilities:
    no directional derivatives, its own memory management)."""
    capabilities = dict(CAPABILITIES_FMI2, needsExecutionTool="true", canNotUseMemoryManagementFunctions="true")
    del capabilities["providesDirectionalDerivative"]
    return Face(("cs",), f"(build_fmu.py) with PythonFMU {pythonfmu_version}", capabilities)


def _units(root: ET.Element, variables: list[FmuVariable], position: int) -> None:
    definitions = ET.Element("UnitDefinitions")
    for unit in sorted({v.unit for v in variables if v.unit}):
        element = ET.SubElement(definitions, "Unit", name=unit)
        base = si_form(unit)
        if base is not None:
            ET.SubElement(element, "BaseUnit", base)
    root.insert(position, definitions)


def _categories_and_experiment(root: ET.Element) -> None:
    categories = ET.SubElement(root, "LogCategories")
    for name, description in LOG_CATEGORIES:
        ET.SubElement(categories, "Category", name=name, description=description)
    ET.SubElement(root, "DefaultExperiment", startTime="0.0", stopTime="1.0", stepSize="0.001")


def _pretty(root: ET.Element) -> bytes:
    text = parseString(ET.tostring(root, encoding="UTF-8")).toprettyxml(indent="  ", encoding="UTF-8")
    return b"\n".join(line for line in text.splitlines() if line.strip()) + b"\n"


def _common_attributes(identifier: str, token_name: str, token: str, axis_models, version: str, tool: str) -> dict:
    return {"fmiVersion": version, "modelName": identifier, token_name: token,
            "description": fmu_description(axis_models), "author": "Bouc-Wen bushing project", "version": __version__,
            "license": "MIT", "generationTool": f"boucwen-bushing {__version__} {tool}",
            "generationDateAndTime": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "variableNamingConvention": "structured"}


def _dependencies(variables: list[FmuVariable], axis_models, interfaces, groups=()) -> dict[int, list[FmuVariable]]:
    """{value reference of an output or a state's derivative: the knowns it depends on} for an FMU
    with ``interfaces`` (``dependencies.axis_dependencies`` of the axis's model): an output's
    states and inputs in model exchange, its inputs in co-simulation (x through the jump too), the
    union where the FMU has both; a state derivative's states and inputs. A coupled group's
    (``groups``) by ``dependencies.group_dependencies``, across its members."""
    found = {}
    by_model = {}
    grouped = {position: group for group in groups for position in group}
    by_group = {}
    for v in variables:
        if v.kind not in ("output", "derivative"):
            continue
        if v.axis in grouped:
            found[v.value_reference] = _group_knowns(v, variables, axis_models, grouped[v.axis], interfaces, by_group)
            continue
        model = axis_models[v.axis][1]
        if model.name not in by_model:
            by_model[model.name] = axis_dependencies(model)
        dependencies = by_model[model.name]
        if v.kind == "output":
            wanted = (dependencies.output if "me" in interfaces else frozenset()) | \
                (dependencies.cosimulation_output if "cs" in interfaces else frozenset())
        else:
            wanted = dependencies.rates[next(s for s in variables if s.value_reference == v.state).index]
        found[v.value_reference] = [k for k in variables if k.axis == v.axis and (
            (k.kind == "state" and k.index in wanted) or (k.kind == "displacement" and X in wanted)
            or (k.kind == "velocity" and V in wanted))]
    return found


def _group_knowns(v: FmuVariable, variables, axis_models, group, interfaces, cache) -> list[FmuVariable]:
    """The knowns of an output or a state's derivative of a coupled group's member (``_dependencies``)."""
    model = axis_models[group[0]][1]
    if model.name not in cache:
        cache[model.name] = group_dependencies(model)
    dependencies = cache[model.name]
    if v.kind == "output":
        c = group.index(v.axis)
        wanted = (dependencies.output[c] if "me" in interfaces else frozenset()) | \
            (dependencies.cosimulation_output[c] if "cs" in interfaces else frozenset())
    else:
        wanted = dependencies.rates[next(s for s in variables if s.value_reference == v.state).index]
    members = set(group)
    return [k for k in variables if k.axis in members and (
        (k.kind == "state" and k.index in wanted) or (k.kind == "displacement" and (X, group.index(k.axis)) in wanted)
        or (k.kind == "velocity" and (V, group.index(k.axis)) in wanted))]


def _unknown(parent: ET.Element, tag: str, key: str, value: str, knowns: list[FmuVariable], reference) -> None:
    ET.SubElement(parent, tag, {key: value, "dependencies": " ".join(str(reference(k)) for k in knowns),
                                "dependenciesKind": " ".join("dependent" for _ in knowns)})


def fmi2(axis_models, identifier: str, token: str, face: Face, event_indicators: int = 0, groups=()) -> bytes:
    """FMI 2.0 modelDescription.xml of an FMU with ``face`` (``groups``: the coupled groups)."""
    interfaces = face.interfaces
    groups = _coupled(axis_models, groups)
    variables = all_variables(axis_models, groups) if "me" in interfaces else fmu_variables(axis_models, groups)
    attributes = _common_attributes(identifier, "guid", token, axis_models, "2.0", face.tool)
    if "me" in interfaces:
        attributes["numberOfEventIndicators"] = str(event_indicators)
    root = ET.Element("fmiModelDescription", attributes)
    capabilities = {"modelIdentifier": identifier, **face.capabilities}
    for interface in interfaces:
        if interface == "me":
            element = ET.SubElement(root, "ModelExchange", dict(capabilities, completedIntegratorStepNotNeeded="true"))
        else:
            element = ET.SubElement(root, "CoSimulation", dict(
                capabilities, canHandleVariableCommunicationStepSize="true", canInterpolateInputs="false",
                maxOutputDerivativeOrder="0", canRunAsynchronuously="false"))
        if face.source_file:
            ET.SubElement(ET.SubElement(element, "SourceFiles"), "File", name=face.source_file)
    _units(root, variables, len(root))
    _categories_and_experiment(root)
    model_variables = ET.SubElement(root, "ModelVariables")
    index = {v.value_reference: i + 1 for i, v in enumerate(variables)}
    for v in variables:
        element = ET.SubElement(model_variables, "ScalarVariable", name=v.name, valueReference=str(v.value_reference),
                                description=v.description, causality=v.causality, variability=v.variability)
        real = {"unit": v.unit}
        if v.start is not None:
            real["start"] = exact_text(v.start)
        if v.kind == "derivative":
            real["derivative"] = str(index[v.state])
        if v.kind == "state":
            real["nominal"] = exact_text(nominal(v))
        ET.SubElement(element, "Real", real)
    structure = ET.SubElement(root, "ModelStructure")
    outputs = ET.SubElement(structure, "Outputs")
    dependencies = _dependencies(variables, axis_models, interfaces, groups)

    def position(k):
        return index[k.value_reference]
    for v in variables:
        if v.kind == "output":
            _unknown(outputs, "Unknown", "index", str(position(v)), dependencies[v.value_reference], position)
    if "me" in interfaces and any(v.kind == "derivative" for v in variables):
        derivatives = ET.SubElement(structure, "Derivatives")
        for v in variables:
            if v.kind == "derivative":
                _unknown(derivatives, "Unknown", "index", str(position(v)), dependencies[v.value_reference], position)
    initial = ET.SubElement(structure, "InitialUnknowns")
    for v in variables:
        if v.kind == "output" or ("me" in interfaces and v.kind in ("state", "derivative")):
            ET.SubElement(initial, "Unknown", index=str(index[v.value_reference]))
    return _pretty(root)


def _coupled(axis_models, groups) -> tuple:
    """The groups whose model has a coupled form (a Kelvin-Voigt group is its axes as they are)."""
    return tuple(tuple(group) for group in groups if axis_models[group[0]][1].coupled is not None)


def fmi3(axis_models, identifier: str, token: str, groups=()) -> bytes:
    """FMI 3.0 modelDescription.xml of the native FMU, co-simulation and model exchange (``groups``:
    the coupled groups)."""
    groups = _coupled(axis_models, groups)
    variables = all_variables(axis_models, groups)
    root = ET.Element("fmiModelDescription", _common_attributes(identifier, "instantiationToken", token, axis_models,
                                                                "3.0", NATIVE_TOOL))
    capabilities = {"modelIdentifier": identifier, "needsExecutionTool": "false",
                    "canBeInstantiatedOnlyOncePerProcess": "false", "canGetAndSetFMUState": "true",
                    "canSerializeFMUState": "true", "providesDirectionalDerivatives": "true",
                    "providesAdjointDerivatives": "true"}
    ET.SubElement(root, "ModelExchange", dict(capabilities, needsCompletedIntegratorStep="false"))
    ET.SubElement(root, "CoSimulation", dict(capabilities, canHandleVariableCommunicationStepSize="true",
                                             maxOutputDerivativeOrder="0"))
    _units(root, variables, len(root))
    _categories_and_experiment(root)
    model_variables = ET.SubElement(root, "ModelVariables")
    for v in variables:
        attributes = {"name": v.name, "valueReference": str(v.value_reference), "description": v.description,
                      "causality": v.causality, "variability": v.variability, "unit": v.unit}
        if v.start is not None:
            attributes["start"] = exact_text(v.start)
        if v.kind == "derivative":
            attributes["derivative"] = str(v.state)
        if v.kind == "state":
            attributes["nominal"] = exact_text(nominal(v))
        ET.SubElement(model_variables, "Float64", attributes)
    structure = ET.SubElement(root, "ModelStructure")
    dependencies = _dependencies(variables, axis_models, INTERFACES, groups)

    def reference(k):
        return k.value_reference
    for v in variables:
        if v.kind == "output":
            _unknown(structure, "Output", "valueReference", str(v.value_reference), dependencies[v.value_reference],
                     reference)
    for v in variables:
        if v.kind == "derivative":
            _unknown(structure, "ContinuousStateDerivative", "valueReference", str(v.value_reference),
                     dependencies[v.value_reference], reference)
    for v in variables:
        if v.kind in ("output", "state", "derivative"):
            ET.SubElement(structure, "InitialUnknown", valueReference=str(v.value_reference))
    for v in variables:
        if v.kind == "indicator":
            ET.SubElement(structure, "EventIndicator", valueReference=str(v.value_reference))
    return _pretty(root)


def build_description(identifier: str) -> bytes:
    """FMI 3.0 sources/buildDescription.xml: the one C99 translation unit."""
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    configuration = ET.SubElement(root, "BuildConfiguration", modelIdentifier=identifier)
    files = ET.SubElement(configuration, "SourceFileSet", language="C99")
    ET.SubElement(files, "SourceFile", name=f"{identifier}.c")
    return _pretty(root)
