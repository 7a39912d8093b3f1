"""Build a bushing FMU: ``python build_fmu.py [--model NAME] [--params FILE] [--out DIR] [--native
[--fmi-version 2|3]]``.

Writes ``DIR/<identifier>.fmu`` (FMI 2.0 co-simulation, pythonfmu; with ``--native``: compiled C,
FMI 2.0 or 3.0, co-simulation and model exchange, see ``fmu_src/native``) of the model NAME
(``proposed``, the default: ``BoucWenBushing.fmu``; ``spencer``: ``SpencerBushing``;
``single_bouc_wen``: ``SingleBoucWenBushing``; ``berg``: ``BergBushing``; ``fractional``:
``FractionalBushing``; ``kelvin_voigt``: ``KelvinVoigtBushing``; every model of
``fmu_src/bushing_models``; ``six_axis``: ``SixAxisBushing``, six uncoupled axes each one of the
models, see ``fmu_src/axes.py``) whose parameter start values are the set in FILE, project JSON
or SSP 1.0 ``.ssv`` (default: the model's file in ``data/``: the paper's Table 5 for the proposed
model, the baselines' fits to the synthetic Table 5 tests, an illustrative filled rubber for Berg's
and the fractional model, ``data/params_six_axis_illustrative.json`` for six axes).

What the build adds to pythonfmu's output, and why:
- Unique module names. The slave module is packed as ``boucwen_bushing_<hash>.py`` with its
  library in ``boucwen_bushing_<hash>_lib/``, the hash taken over the packed sources, the
  model and the default parameters: pythonfmu imports packed modules into the host's shared
  ``sys.modules``, so two FMUs with equal module names would silently run the first one's code.
- One class per model: the packed slave module ends with ``class <identifier>(BushingSlave)``,
  which pythonfmu picks (longest hierarchy) and which names the modelIdentifier.
- modelDescription.xml: units on every variable and their UnitDefinitions, the
  InitialUnknowns and the output's direct dependencies (pythonfmu writes none of these), and
  a check with ``fmpy.validation.validate_fmu`` that must find no problem.
- ``needsExecutionTool="true"`` is kept on purpose: the FMU runs Python code and needs a
  Python 3 runtime (libpython) in the host process.
"""
from __future__ import annotations

import argparse
import hashlib
import importlib.resources
import json
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.dom.minidom import parseString
from xml.etree import ElementTree as ET

REPO = Path(__file__).resolve().parent
SLAVE_MODULE = "bushing_slave.py"

sys.path.insert(0, str(REPO))
import fmu_src  # noqa: E402
from fmu_src import __version__, bushing_params  # noqa: E402
from fmu_src.axes import ONE_AXIS, SIX_AXIS_IDENTIFIER  # noqa: E402
from fmu_src.bushing_models import MODEL_CHOICES, MODEL_NAMES, get_model  # noqa: E402
from fmu_src.parameter_files import (parameter_document, read_parameter_set, read_six_axis,  # noqa: E402
                                     six_axis_document)


PACKED_LIBRARY_INIT = '''"""Packed library of the bushing FMU (written by build_fmu.py)."""
from pathlib import Path

from . import axes, bushing_models, compiled_kernels, integration, model_definition, parameter_files, variables

# Compiled here, once per process, while the extracted files surely exist (a host may delete them
# after the first instance); STEP_AXES holds the compiled batched step of each model ({} for the
# pure-Python step); STEP says which step runs (logged by every instance).
AXES, STEP_AXES, STEP = compiled_kernels.compile_axes(
    parameter_files.fmu_axes(Path(__file__).with_name("default_parameters.json")))
'''
SIX_AXIS = "six_axis"
SIX_AXIS_DEFAULT_FILE = "params_six_axis_illustrative.json"


SOURCE_DIR = Path(fmu_src.__file__).resolve().parent
LIBRARY_MODULES = tuple(sorted(path.name for path in SOURCE_DIR.glob("*.py")
                               if path.name not in ("__init__.py", SLAVE_MODULE)))
"""What the pythonfmu FMU packs beside its slave module: every module of fmu_src (the models and
what they share; its __init__ is PACKED_LIBRARY_INIT), so a model module added there is packed too."""


class BuildError(RuntimeError):
    pass


def default_parameter_file(model: str = "proposed") -> Path:
    """The parameter set an FMU of ``model`` gets when no ``--params`` is given: in the
    checkout's data/, or in the installed package ``bushing_data`` (the same files)."""
    name = SIX_AXIS_DEFAULT_FILE if model in (SIX_AXIS, SIX_AXIS_IDENTIFIER) else get_model(model).default_file
    checkout = REPO / "data" / name
    if checkout.is_file():
        return checkout
    try:
        return Path(str(importlib.resources.files("bushing_data") / name))
    except ModuleNotFoundError:
        raise BuildError(f"the default parameter set {name} is neither in {REPO / 'data'} nor installed "
                         "(package bushing_data); reinstall the project or give --params FILE") from None


def model_of_file(params_file: str | Path) -> str:
    """The model a parameter file is for: the one it names (a one-axis set) or ``six_axis``."""
    try:
        return read_parameter_set(params_file).model.name
    except bushing_params.ParameterError as one_axis_error:
        try:
            read_six_axis(params_file)
        except bushing_params.ParameterError:
            raise one_axis_error from None
        return SIX_AXIS


def fmu_axes(params_file: str | Path | None = None, model: str = "proposed"):
    """(identifier, title, axes [(axes.Axis, model on it, parameters)], the defaults document) of
    the FMU of ``model`` with the parameter set in ``params_file`` (default:
    :func:`default_parameter_file`)."""
    six = model in (SIX_AXIS, SIX_AXIS_IDENTIFIER)
    name = SIX_AXIS if six else get_model(model).name
    params_file = Path(params_file) if params_file is not None else default_parameter_file(name)
    source = {"source": f"build_fmu.py --model {name} --params {params_file.name}"}
    if six:
        six_axes = read_six_axis(params_file)
        document = six_axis_document({axis: (one.model.identifier, one.parameters)
                                      for axis, one in six_axes.axes.items()}, source)
        return SIX_AXIS_IDENTIFIER, "six-axis bushing", six_axes.fmu_axes(), document
    bushing = get_model(name)
    parameters = read_parameter_set(params_file, name).parameters
    return (bushing.identifier, f"{bushing.title} model", [(ONE_AXIS, bushing, parameters)],
            parameter_document(parameters, name, source))


def build_native_fmu(params_file: str | Path | None = None, out_dir: str | Path = "dist", model: str = "proposed",
                     fmi_version: int = 2, platforms: tuple[str, ...] | None = None):
    """Build the native FMU: C generated from the model's definition, compiled, no Python needed
    in the host; co-simulation and model exchange in one FMU.

    Parameters
    ----------
    params_file : str or Path, optional
        Parameter file whose values become the start values (default: the model's shipped set).
    out_dir : str or Path
        Directory for ``<Identifier>.fmu`` (created if missing).
    model : str
        ``proposed``, ``spencer``, ``single_bouc_wen``, ``kelvin_voigt`` or ``six_axis``.
    fmi_version : int
        2 or 3.
    platforms : tuple of str, optional
        Binaries to build (default: ``linux64``, and ``win64`` where mingw-w64 is installed);
        the C sources are always included.

    Returns
    -------
    NativeBuild
        Its ``path``, the platforms built and those skipped (with why).

    Raises
    ------
    BuildError
        The FMU fails fmpy's validation; ``ParameterError`` for an invalid parameter file.
    """
    from fmpy.validation import validate_fmu
    from fmu_src.native.build import build_native
    identifier, _, axes, _ = fmu_axes(params_file, model)
    build = build_native(axes, identifier, out_dir, fmi_version, platforms)
    problems = validate_fmu(str(build.path))
    if problems:
        raise BuildError(f"{build.path} fails validation:\n  " + "\n  ".join(problems))
    return build


def build_fmu(params_file: str | Path | None = None, out_dir: str | Path = "dist",
              model: str = "proposed") -> Path:
    """Build the pythonfmu FMU (FMI 2.0 co-simulation; the host needs Python with pythonfmu).

    Parameters
    ----------
    params_file : str or Path, optional
        Parameter file whose values become the start values (default: the model's shipped set,
        ``default_parameter_file``).
    out_dir : str or Path
        Directory for ``<Identifier>.fmu`` (created if missing).
    model : str
        ``proposed``, ``spencer``, ``single_bouc_wen``, ``kelvin_voigt`` or ``six_axis``.

    Returns
    -------
    Path
        The FMU written.

    Raises
    ------
    BuildError
        The FMU fails fmpy's validation; ``ParameterError`` for an invalid parameter file.
    """
    from pythonfmu.builder import FmuBuilder

    identifier, title, axes, defaults_json = fmu_axes(params_file, model)
    defaults_text = json.dumps(defaults_json, indent=2) + "\n"
    slave_text = ((SOURCE_DIR / SLAVE_MODULE).read_text()
                  + f"\n\nclass {identifier}(BushingSlave):\n"
                    f"    \"\"\"The {title} (written by build_fmu.py).\"\"\"\n"
                    f"    version = {__version__!r}\n")

    digest = hashlib.sha256(slave_text.encode())
    for name in LIBRARY_MODULES:
        digest.update((SOURCE_DIR / name).read_bytes())
    digest.update(defaults_text.encode())
    module_name = f"boucwen_bushing_{digest.hexdigest()[:12]}"

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="bushing_build_") as stage:
        stage = Path(stage)
        script = stage / f"{module_name}.py"
        script.write_text(slave_text)
        library = stage / f"{module_name}_lib"
        library.mkdir()
        (library / "__init__.py").write_text(PACKED_LIBRARY_INIT)
        for name in LIBRARY_MODULES:
            shutil.copy2(SOURCE_DIR / name, library / name)
        (library / "default_parameters.json").write_text(defaults_text)

        sys.path.insert(0, str(stage))
        try:
            fmu_path = Path(FmuBuilder.build_FMU(
                script, dest=out_dir, project_files=[library],
                canGetAndSetFMUstate=True, canSerializeFMUstate=True))
        finally:
            sys.path.remove(str(stage))
            for loaded in [m for m in sys.modules if m.startswith(module_name)]:
                del sys.modules[loaded]

    _rewrite_model_description(fmu_path, axes)
    from fmpy.validation import validate_fmu
    problems = validate_fmu(str(fmu_path))
    if problems:
        raise BuildError(f"{fmu_path} fails validation:\n  " + "\n  ".join(problems))
    return fmu_path


def _rewrite_model_description(fmu_path: Path, axes: list) -> None:
    """``axes``: [(axes.Axis, model on it, parameters)], what the packed library reads back from
    the defaults it is given (parameter_files.fmu_axes)."""
    with zipfile.ZipFile(fmu_path) as archive:
        entries = {info.filename: archive.read(info.filename) for info in archive.infolist()}
    root = ET.fromstring(entries["modelDescription.xml"])
    root.set("generationTool", f"boucwen-bushing {__version__} (build_fmu.py) with {root.get('generationTool')}")
    units, starts = {}, {}
    for axis, model, parameters in axes:
        units.update({axis.displacement: axis.displacement_unit, axis.velocity: axis.velocity_unit,
                      axis.output: axis.output_unit})
        units.update({axis.prefix + name: unit for name, unit in model.units.items()})
        units.update({axis.prefix + s.name: axis.state_port(s.unit)[0] for s in model.states})
        starts.update({axis.prefix + name: value for name, value in parameters.items()})
    _add_units(root, units)
    _set_parameter_starts(root, starts)
    _add_model_structure(root, [axis for axis, _, _ in axes])
    text = parseString(ET.tostring(root, encoding="UTF-8")).toprettyxml(indent="  ", encoding="UTF-8")
    entries["modelDescription.xml"] = b"\n".join(line for line in text.splitlines() if line.strip())
    with zipfile.ZipFile(fmu_path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in entries.items():
            archive.writestr(name, data)


def _add_units(root: ET.Element, units: dict[str, str]) -> None:
    units_used = set()
    for variable in root.iter("ScalarVariable"):
        name = variable.get("name")
        unit = units.get(name)
        if unit is None:
            raise BuildError(f"no unit declared for variable {name!r}")
        variable.find("Real").set("unit", unit)
        units_used.add(unit)
    definitions = ET.Element("UnitDefinitions")
    for unit in sorted(units_used):
        element = ET.SubElement(definitions, "Unit", name=unit)
        base = bushing_params.UNIT_DEFINITIONS[unit]
        if base is not None:
            ET.SubElement(element, "BaseUnit", base)
    # FMI 2.0 schema order: CoSimulation, UnitDefinitions, TypeDefinitions, LogCategories, ...
    position = list(root).index(root.find("CoSimulation")) + 1
    root.insert(position, definitions)


def _set_parameter_starts(root: ET.Element, parameters: dict[str, float]) -> None:
    """pythonfmu writes starts with %.16g, which need not round-trip; repr() does."""
    for variable in root.iter("ScalarVariable"):
        if variable.get("name") in parameters:
            variable.find("Real").set("start", repr(parameters[variable.get("name")]))


def _add_model_structure(root: ET.Element, axes) -> None:
    index = {v.get("name"): str(i + 1) for i, v in enumerate(root.iter("ScalarVariable"))}
    structure = root.find("ModelStructure")
    for child in list(structure):
        structure.remove(child)
    # F = k0*y + c0*(c2*v + k2*(x - w) + alpha2*z2)/(c0 + c2) (+ a constant for the
    # baselines): direct feedthrough of its own axis's x and v, and of nothing else (the axes
    # are uncoupled).
    outputs = ET.SubElement(structure, "Outputs")
    for axis in axes:
        ET.SubElement(outputs, "Unknown", index=index[axis.output],
                      dependencies=f"{index[axis.displacement]} {index[axis.velocity]}",
                      dependenciesKind="dependent dependent")
    initial = ET.SubElement(structure, "InitialUnknowns")
    for axis in axes:
        ET.SubElement(initial, "Unknown", index=index[axis.output])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="bushing-build-fmu",
        description="Build a bushing FMU (pythonfmu, FMI 2.0 co-simulation; or --native: compiled C, FMI 2.0 "
                    "or 3.0, co-simulation and model exchange) with a parameter set as its start values.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("--model", choices=(*MODEL_CHOICES, SIX_AXIS), metavar="MODEL",
                        help=f"{', '.join(MODEL_NAMES)} or {SIX_AXIS} (six uncoupled axes, each one of the models); "
                             "default: the model --params is for, else proposed (the paper's eqs. 1-5)")
    parser.add_argument("--params", help="parameter set of the model, project JSON or SSP 1.0 .ssv "
                                         "(paper N-mm-s units); default: the paper's Table 5 for the "
                                         "proposed model, data/params_<model>_fit_synthetic_table5.json for the "
                                         f"others, data/{SIX_AXIS_DEFAULT_FILE} for six_axis")
    parser.add_argument("--out", default="dist", help="output directory (default: dist/ in the working directory)")
    parser.add_argument("--native", action="store_true",
                        help="build the native FMU: compiled C, co-simulation and model exchange, no Python in the "
                             "host (linux64 with the system's C compiler, win64 where mingw-w64 is installed)")
    parser.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                        help="FMI version of the native FMU (default 2; the pythonfmu FMU is FMI 2 only)")
    args = parser.parse_args(argv)
    from fmu_src.native.build import NativeBuildError
    try:
        if args.model is None:
            args.model = model_of_file(args.params) if args.params else "proposed"
        if args.native:
            build = build_native_fmu(args.params, args.out, args.model, args.fmi_version)
            path = build.path
            for platform, why in build.skipped.items():
                print(f"note: no {platform} binary: {why}", file=sys.stderr)
        elif args.fmi_version != 2:
            raise BuildError("--fmi-version 3 needs --native (pythonfmu builds FMI 2.0 FMUs only)")
        else:
            path = build_fmu(args.params, args.out, args.model)
    except (bushing_params.ParameterError, BuildError, NativeBuildError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:   # an output directory that cannot be made or written
        print(f"error: --out {args.out}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
