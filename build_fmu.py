"""Build a bushing FMU: ``python build_fmu.py [--model NAME] [--params FILE] [--out DIR] [--native
[--fmi-version 2|3] [--platforms all|P,Q]]``; or the release bundle: ``python build_fmu.py --release
[--out DIR] [--allow-missing-platforms]`` (:func:`build_release`: every model's native FMU, FMI 2 and
3, for Linux (x86_64, aarch64), Windows (x86_64) and macOS (x86_64, arm64), with its default set;
the sets as ``.ssv``, README.txt, SHA256SUMS), which a user without a compiler applies a parameter
set to as start values.

Writes ``DIR/<identifier>.fmu`` (FMI 2.0 co-simulation, pythonfmu; with ``--native``: compiled C,
FMI 2.0 or 3.0, co-simulation and model exchange, see ``fmu_src/fmi/native``) of the model NAME
(``proposed``, the default: ``BoucWenBushing.fmu``; ``spencer``: ``SpencerBushing``;
``single_bouc_wen``: ``SingleBoucWenBushing``; ``berg``: ``BergBushing``; ``fractional``:
``FractionalBushing``; ``kelvin_voigt``: ``KelvinVoigtBushing``; every model of
``fmu_src/model/registry.py``; ``six_axis``: ``SixAxisBushing``, six uncoupled axes each one of the
models, see ``fmu_src/fmi/axes.py``) whose parameter start values are the set in FILE, project JSON
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
import time
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree as ET

REPO = Path(__file__).resolve().parent
SLAVE_MODULE = "fmi/pythonfmu_slave.py"

sys.path.insert(0, str(REPO))
import fmu_src  # noqa: E402
from fmu_src import __version__  # noqa: E402
from fmu_src.model import parameter_specs  # noqa: E402
from fmu_src.fmi import model_description  # noqa: E402
from fmu_src.fmi.axes import ONE_AXIS, SIX_AXIS_IDENTIFIER, SIX_AXIS_NAMES, Coupling  # noqa: E402
from fmu_src.model.registry import MODEL_CHOICES, MODEL_NAMES, get_model  # noqa: E402
from fmu_src.parameter_files import (parameter_document, read_parameter_set, read_six_axis,  # noqa: E402
                                     save_parameters, save_six_axis, six_axis_document)


PACKED_LIBRARY_INIT = '''"""Packed library of the bushing FMU (written by build_fmu.py)."""
from pathlib import Path

from . import parameter_files
from .fmi import axes, variables
from .kernels import numba_binding
from .model import integration

# Compiled here, once per process, while the extracted files surely exist (a host may delete them
# after the first instance); STEP_AXES holds the compiled batched step of each model ({} for the
# pure-Python step); STEP says which step runs (logged by every instance).
AXES, STEP_AXES, STEP = numba_binding.compile_axes(
    parameter_files.fmu_axes(Path(__file__).with_name("default_parameters.json")))
GROUPS = parameter_files.fmu_groups(Path(__file__).with_name("default_parameters.json"))
'''
SIX_AXIS = "six_axis"
SIX_AXIS_DEFAULT_FILE = "params_six_axis_illustrative.json"


SOURCE_DIR = Path(fmu_src.__file__).resolve().parent
NOT_PACKED = ("fmi/native/", "fmi/model_description.py", "fmi/dependencies.py", "kernels/python_to_c.py")
"""What the pythonfmu FMU leaves out of fmu_src: what builds an FMU and never runs inside one (the
native FMU's generator, the C translator, the model description and its dependencies)."""
LIBRARY_MODULES = tuple(sorted(name for name in (path.relative_to(SOURCE_DIR).as_posix()
                                                 for path in SOURCE_DIR.rglob("*.py"))
                               if name not in ("__init__.py", SLAVE_MODULE) and not name.startswith(NOT_PACKED)))
"""What the pythonfmu FMU packs beside its slave module, as paths under fmu_src: every module of
it but the native FMU's generator (the models, the contract, the kernels' machinery, the FMI
layer, the parameter files; its __init__ is PACKED_LIBRARY_INIT), so a model module added to
fmu_src/models/ is packed too."""


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
    except parameter_specs.ParameterError as one_axis_error:
        try:
            read_six_axis(params_file)
        except parameter_specs.ParameterError:
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
                                      for axis, one in six_axes.axes.items()}, source, six_axes.coupling)
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
        Binaries to build, names of ``fmu_src/fmi/native/platforms.py`` (default: ``linux64``, and
        ``win64`` where mingw-w64 is installed; FMI 3: ``x86_64-linux``, ``x86_64-windows``); the
        C sources are always included.

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
    from fmu_src.fmi.native.build import build_native
    identifier, _, axes, document = fmu_axes(params_file, model)
    build = build_native(axes, identifier, out_dir, fmi_version, platforms, groups_of(document))
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
    from pythonfmu import builder
    from pythonfmu.builder import FmuBuilder
    pythonfmu_folder = Path(builder.__file__).parent
    binaries = pythonfmu_folder / "resources" / "binaries"
    if not any(binaries.rglob("*.so")) and not any(binaries.rglob("*.dll")):
        raise BuildError(f"pythonfmu here ({pythonfmu_folder}) has no FMU binaries: it is the copy a "
                         "pythonfmu FMU loaded into this process carries, not an installed one; build before "
                         "loading a pythonfmu FMU, or in another process")

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
            (library / name).parent.mkdir(parents=True, exist_ok=True)
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

    _write_model_description(fmu_path, identifier, axes, groups_of(defaults_json))
    from fmpy.validation import validate_fmu
    problems = validate_fmu(str(fmu_path))
    if problems:
        raise BuildError(f"{fmu_path} fails validation:\n  " + "\n  ".join(problems))
    return fmu_path


def groups_of(document: dict) -> tuple[tuple[int, ...], ...]:
    """The coupled groups of a defaults document (positions of the six axes; none for one axis)."""
    return tuple(tuple(SIX_AXIS_NAMES.index(name) for name in group)
                 for group in Coupling.of(document.get("coupling")).groups)


def _write_model_description(fmu_path: Path, identifier: str, axes: list, groups=()) -> None:
    """Replace pythonfmu's modelDescription.xml by the project's one writer's
    (``fmu_src.fmi.model_description``, as for the native FMU), keeping the guid pythonfmu gave it.
    ``axes``: [(axes.Axis, model on it, parameters)], what the packed library reads back from the
    defaults it is given (parameter_files.fmu_axes); ``groups``: its coupled groups."""
    from pythonfmu import __version__ as pythonfmu_version
    with zipfile.ZipFile(fmu_path) as archive:
        entries = {info.filename: archive.read(info.filename) for info in archive.infolist()}
    guid = ET.fromstring(entries["modelDescription.xml"]).get("guid")
    entries["modelDescription.xml"] = model_description.fmi2(axes, identifier, guid,
                                                             model_description.pythonfmu_face(pythonfmu_version),
                                                             groups=groups)
    with zipfile.ZipFile(fmu_path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in entries.items():
            archive.writestr(name, data)


# ---------------------------------------------------------------------------- the release bundle
RELEASE_FMI_VERSIONS = (2, 3)
RELEASE_DIR = Path("dist") / "release"
CHECKSUMS = "SHA256SUMS"
README = "README.txt"


def release_models() -> tuple[str, ...]:
    """What a release bundle carries: every one-axis model, then the six-axis FMU."""
    return (*MODEL_NAMES, SIX_AXIS)


def release_fmu_name(model: str, fmi_version: int) -> str:
    """``BoucWenBushing-fmi2.fmu``: the FMU's identifier and FMI version."""
    return f"{_identifier(model)}-fmi{fmi_version}.fmu"


def release_parameter_name(model: str) -> str:
    """``BoucWenBushing-default.ssv``: the default parameter set of ``model``'s FMUs."""
    return f"{_identifier(model)}-default.ssv"


def _identifier(model: str) -> str:
    return SIX_AXIS_IDENTIFIER if model in (SIX_AXIS, SIX_AXIS_IDENTIFIER) else get_model(model).identifier


@dataclass
class ReleaseBundle:
    """What :func:`build_release` wrote into ``folder``."""
    folder: Path
    fmus: dict[tuple[str, int], Path] = field(default_factory=dict)      # (model, FMI version) -> FMU
    parameter_files: dict[str, Path] = field(default_factory=dict)       # model -> its default set (.ssv)
    platforms: dict[int, list[str]] = field(default_factory=dict)        # FMI version -> binaries in every FMU
    missing: dict[int, dict[str, str]] = field(default_factory=dict)     # FMI version -> {platform: why}
    readme: Path | None = None
    checksums: Path | None = None
    seconds: float = 0.0

    @property
    def files(self) -> list[Path]:
        """Every file of the bundle, the checksum list last."""
        return [*self.fmus.values(), *self.parameter_files.values(), self.readme, self.checksums]


def _missing_text(missing: dict[int, dict[str, str]]) -> str:
    return "; ".join(f"{platform} (FMI {version}): {why}" for version, platforms in missing.items()
                     for platform, why in platforms.items())


def build_release(out_dir: str | Path = RELEASE_DIR, allow_missing_platforms: bool = False,
                  models: tuple[str, ...] | None = None,
                  fmi_versions: tuple[int, ...] = RELEASE_FMI_VERSIONS) -> ReleaseBundle:
    """Build the release bundle: the native FMU of every model (FMI 2 and 3, the binaries of every
    platform of ``fmu_src/fmi/native/platforms.py`` and the C sources in each, the model's default parameter set as start values), the
    default sets as SSP 1.0 ``.ssv``, ``README.txt`` and ``SHA256SUMS`` (``sha256sum -c``).

    The FMUs' parameters are start values, so one binary per model serves every parameter set:
    a user without a compiler applies a fitted set to the bundle's FMU (fmpy's
    ``simulate_fmu(start_values=...)``, or the host's SSP import of a ``.ssv``).

    Parameters
    ----------
    out_dir : str or Path
        Directory of the bundle (created if missing; the bundle's files in it are replaced, once
        every FMU is built).
    allow_missing_platforms : bool
        Build without a platform whose compiler is missing (the README and ``missing`` say which)
        instead of refusing.
    models : tuple of str, optional
        The models (default: :func:`release_models`, every one); fewer only for tests.
    fmi_versions : tuple of int
        Default 2 and 3.

    Returns
    -------
    ReleaseBundle

    Raises
    ------
    BuildError
        A platform's compiler is missing (and not ``allow_missing_platforms``), or no platform
        can be built at all; an FMU fails fmpy's validation.
    """
    from fmu_src.fmi.native.build import NO_COMPILER, missing_platforms, platform_names
    started = time.perf_counter()
    models = tuple(models or release_models())
    missing = {version: why for version in fmi_versions if (why := missing_platforms(version))}
    if any(len(why) == len(platform_names(version)) for version, why in missing.items()):
        raise BuildError(f"no platform could be built: {_missing_text(missing)}; {NO_COMPILER}")
    if missing and not allow_missing_platforms:
        raise BuildError(f"a release bundle carries every platform, and {_missing_text(missing)}; install the "
                         "compiler, or give --allow-missing-platforms to make a bundle without them")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    bundle = ReleaseBundle(out_dir, missing=missing)
    with tempfile.TemporaryDirectory(prefix="bushing_release_") as stage:
        stage = Path(stage)
        staged = {}

        for model in models:
            default = default_parameter_file(model)
            name = release_parameter_name(model)
            _write_default_ssv(default, model, stage / name)
            staged[name] = ("ssv", model, default)
            for version in fmi_versions:
                build = build_native_fmu(default, stage / f"fmi{version}", model, version,
                                         tuple(p for p in platform_names(version) if p not in missing.get(version, {})))
                fmu = release_fmu_name(model, version)
                build.path.rename(stage / fmu)
                staged[fmu] = ("fmu", model, version)
                bundle.platforms[version] = build.platforms
        (stage / README).write_text(_release_readme(staged, bundle), encoding="utf-8")
        names = sorted(staged, key=lambda n: (staged[n][0] != "fmu", n)) + [README]
        lines = [f"{hashlib.sha256((stage / name).read_bytes()).hexdigest()}  {name}\n" for name in names]
        (stage / CHECKSUMS).write_text("".join(lines), encoding="utf-8")
        for name in [*names, CHECKSUMS]:
            target = out_dir / name
            shutil.move(stage / name, target)
            kind, model, detail = staged.get(name, (None, None, None))
            if kind == "fmu":
                bundle.fmus[model, detail] = target
            elif kind == "ssv":
                bundle.parameter_files[model] = target
        bundle.readme, bundle.checksums = out_dir / README, out_dir / CHECKSUMS
    bundle.seconds = time.perf_counter() - started
    return bundle


def _write_default_ssv(default: Path, model: str, path: Path) -> None:
    """The release's start values of ``model``: every parameter its FMU has, the mounting's (0
    where the default set has none) included, so that the set applied to the FMU is all of it."""
    def complete(one):
        return {spec.name: one.parameters.get(spec.name, 0.0) for spec in one.model.fmu_specs}
    if model in (SIX_AXIS, SIX_AXIS_IDENTIFIER):
        six = read_six_axis(default)
        save_six_axis(path, {axis: (one.model.identifier, complete(one)) for axis, one in six.axes.items()})
    else:
        save_parameters(path, complete(read_parameter_set(default, model)), model)


def _release_readme(staged: dict, bundle: ReleaseBundle) -> str:
    fmus = [(name, model, version) for name, (kind, model, version) in staged.items() if kind == "fmu"]
    sets = [(name, model, default) for name, (kind, model, default) in staged.items() if kind == "ssv"]
    width = max(len(name) for name in staged) + 2

    def title(model: str) -> str:
        return "six uncoupled axes, each one of the models" if model == SIX_AXIS else get_model(model).title

    example_fmu = fmus[0][0]
    text = [
        f"boucwen-bushing {__version__}: native bushing FMUs",
        "=" * (len(__version__) + 37),
        "",
        "Compiled C FMUs of the rubber-bushing models, made by `python build_fmu.py --release`:",
        "co-simulation and model exchange in one FMU, needsExecutionTool=false (no Python in the host).",
        "Every FMU carries binaries for",
        *(f"    FMI {version}: {', '.join(names)}" for version, names in bundle.platforms.items()),
        "and its C sources (sources/), from which an FMI tool builds it for another platform.",
        "Inputs x [m] and v [m/s] (rotational axes: rad, rad/s), output F [N] (moments: N.m).",
        "",
        "linux64, x86_64-linux: Linux on x86_64; aarch64-linux: Linux on ARM 64 (both glibc);",
        "win64, x86_64-windows: 64-bit Windows; darwin64: one universal macOS library for Intel",
        "(macOS 10.15 or later) and Apple silicon (macOS 11 or later), as x86_64-darwin and",
        "aarch64-darwin are in FMI 3.",
        "",
        "FMI 2 on ARM Linux: FMI 2.0 named no ARM platform and importers differ in where they look.",
        "The bundle's FMI 2 FMUs carry binaries/aarch64-linux, FMI 2.0.4's name, but FMPy (0.3.32)",
        "reads binaries/linux64 on any Linux CPU (and darwin64 on any Mac, which the universal library",
        "serves). On ARM Linux, use the FMI 3 FMU (FMI 3 names aarch64-linux), or replace",
        "binaries/linux64/ by binaries/aarch64-linux/ in your copy of the FMI 2 FMU.",
        "",
    ]
    if bundle.missing:
        text += ["MISSING PLATFORMS: this bundle was made without",
                 *(f"    {platform} (FMI {version}): {why}" for version, platforms in bundle.missing.items()
                   for platform, why in platforms.items()),
                 "Rebuild it where that compiler is installed for a complete bundle.", ""]
    text += ["Files", "-----", ""]
    text += [f"{name:<{width}}{title(model)}; FMI {version}.0" for name, model, version in fmus]
    text += [f"{name:<{width}}default parameter set of its FMUs (SSP 1.0 ParameterValues; {default.name})"
             for name, model, default in sets]
    text += [f"{README:<{width}}this file",
             f"{CHECKSUMS:<{width}}SHA-256 of every file above: check with `sha256sum -c {CHECKSUMS}`",
             "",
             "Applying a parameter set (a fit, a set of your own)",
             "---------------------------------------------------",
             "",
             "The FMUs' parameters are start values: one binary per model serves every parameter set, and",
             "no compiler is needed. The values are in the project's units (N, mm, s; rotational axes of the",
             "six-axis FMU in N.mm, rad, s), named as in the .ssv files. Write a fitted set as .ssv with",
             "`bushing-identify fit ... --ssv fit.ssv` (six axes: `bushing-identify assemble --out six.ssv`),",
             "then:",
             "",
             "- fmpy:",
             "      from fmpy import simulate_fmu",
             "      from fmu_src.parameter_files import load_parameters",
             f"      result = simulate_fmu(\"{example_fmu}\", start_values=load_parameters(\"fit.ssv\"),",
             "                            input=signals, output=[\"F\"], step_size=1e-3, stop_time=1.0)",
             "  (for six axes: read_six_axis(\"fit.ssv\").flat()). Without the project installed, read the",
             "  .ssv's <ssv:Real value=...> of each <ssv:Parameter name=...> into the start_values dict.",
             "- A host that imports SSP parameter values: load the .ssv as the FMU instance's parameter",
             "  values.",
             "- Any other FMI host: set each parameter's start value (fmi2SetReal / fmi3SetFloat64 before",
             "  the exit of initialization mode).",
             "",
             "An invalid value is refused at the exit of initialization mode (fmi2Error / fmi3Error), the",
             "log naming the parameter, its value, unit and allowed range.",
             "Each *-default.ssv holds its FMUs' own start values: a template for a set of your own.",
             "",
             "With a C compiler, `python build_fmu.py --native --params fit.ssv` builds an FMU whose",
             "defaults are that set instead.",
             ""]
    return "\n".join(text)


def chosen_platforms(text: str | None, fmi_version: int) -> tuple[str, ...] | None:
    """The platforms ``--platforms`` names (``all``: every one; None: the default). A named platform
    whose compiler is missing is refused, naming the package that provides it."""
    from fmu_src.fmi.native.build import NativeBuildError, missing_platforms, platform_names
    if not text:
        return None
    names = platform_names(fmi_version) if text.strip() == "all" else tuple(
        name.strip() for name in text.split(",") if name.strip())
    if not names:
        raise NativeBuildError(f"--platforms {text!r} names no platform; give 'all' or some of "
                               f"{', '.join(platform_names(fmi_version))}")
    if text.strip() != "all" and (missing := missing_platforms(fmi_version, names)):
        raise NativeBuildError("cannot build " + "; ".join(f"{name}: {why}" for name, why in missing.items()))
    return names


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="bushing-build-fmu",
        description="Build a bushing FMU (pythonfmu, FMI 2.0 co-simulation; or --native: compiled C, FMI 2.0 "
                    "or 3.0, co-simulation and model exchange) with a parameter set as its start values; or "
                    "--release: the release bundle of native FMUs.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("--model", choices=(*MODEL_CHOICES, SIX_AXIS), metavar="MODEL",
                        help=f"{', '.join(MODEL_NAMES)} or {SIX_AXIS} (six uncoupled axes, each one of the models); "
                             "default: the model --params is for, else proposed (the paper's eqs. 1-5)")
    parser.add_argument("--params", help="parameter set of the model, project JSON or SSP 1.0 .ssv "
                                         "(paper N-mm-s units); default: the paper's Table 5 for the "
                                         "proposed model, data/params_<model>_fit_synthetic_table5.json for the "
                                         f"others, data/{SIX_AXIS_DEFAULT_FILE} for six_axis")
    parser.add_argument("--out", help="output directory (default: dist/ in the working directory; "
                                      f"with --release: {RELEASE_DIR}/)")
    parser.add_argument("--native", action="store_true",
                        help="build the native FMU: compiled C, co-simulation and model exchange, no Python in the "
                             "host (linux64 with the system's C compiler, win64 where mingw-w64 is installed; "
                             "more with --platforms)")
    parser.add_argument("--fmi-version", type=int, choices=(2, 3),
                        help="FMI version of the native FMU (default 2; the pythonfmu FMU is FMI 2 only)")
    parser.add_argument("--platforms", metavar="all|P,Q",
                        help="with --native: the binaries to build, 'all' or a comma list of FMI platform names "
                             "(FMI 2: linux64, win64, darwin64, aarch64-linux; FMI 3: x86_64-linux, "
                             "x86_64-windows, x86_64-darwin, aarch64-darwin, aarch64-linux); default linux64 "
                             "and win64 (FMI 3: x86_64-linux, x86_64-windows), each where its compiler is here")
    parser.add_argument("--release", action="store_true",
                        help="build the release bundle: the native FMU of every model, FMI 2 and 3, binaries for "
                             "Linux (x86_64, aarch64), Windows and macOS (x86_64, arm64) and sources in each, each with its default parameter set; the "
                             f"default sets as .ssv, {README} and {CHECKSUMS}. Its parameters are start values: "
                             "one binary per model serves every parameter set, no compiler needed to apply one")
    parser.add_argument("--allow-missing-platforms", action="store_true",
                        help="with --release: make the bundle without a platform whose compiler is missing "
                             "(the README names it) instead of refusing")
    args = parser.parse_args(argv)
    from fmu_src.fmi.native.build import NativeBuildError
    if args.release and (args.model or args.params or args.fmi_version or args.native):
        parser.error("--release builds every model, FMI 2 and 3, with its default parameter set: it takes "
                     "no --model, --params, --fmi-version or --native")
    if args.allow_missing_platforms and not args.release:
        parser.error("--allow-missing-platforms goes with --release")
    if args.platforms and not args.native:
        parser.error("--platforms goes with --native (--release builds every platform)")
    out = args.out or (RELEASE_DIR if args.release else "dist")
    try:
        if args.release:
            bundle = build_release(out, args.allow_missing_platforms)
            if bundle.missing:
                print(f"warning: the bundle has no {_missing_text(bundle.missing)}", file=sys.stderr)
            print(f"wrote {bundle.folder}: {len(bundle.fmus)} FMUs, {len(bundle.parameter_files)} parameter sets, "
                  f"{README}, {CHECKSUMS} ({bundle.seconds:.0f} s)")
            return 0
        if args.model is None:
            args.model = model_of_file(args.params) if args.params else "proposed"
        if args.native:
            version = args.fmi_version or 2
            build = build_native_fmu(args.params, out, args.model, version, chosen_platforms(args.platforms, version))
            path = build.path
            for platform, why in build.skipped.items():
                print(f"note: no {platform} binary: {why}", file=sys.stderr)
        elif args.fmi_version not in (None, 2):
            raise BuildError("--fmi-version 3 needs --native (pythonfmu builds FMI 2.0 FMUs only)")
        else:
            path = build_fmu(args.params, out, args.model)
    except (parameter_specs.ParameterError, BuildError, NativeBuildError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:   # an output directory that cannot be made or written
        print(f"error: --out {out}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    print(f"wrote {path}")
    return 0

if __name__ == "__main__":
    sys.exit(main())
