"""Build a native bushing FMU: C generated from the model definitions, compiled for each platform
of ``platforms.py`` whose toolchain is here (Linux x86_64 and aarch64, Windows x86_64, macOS x86_64
and arm64), its sources inside so that any tool can compile it for another platform (FMI 2
``<SourceFiles>``, FMI 3 ``buildDescription.xml``). No Python in the host:
``needsExecutionTool="false"``.

Layout of the FMU::

    modelDescription.xml
    binaries/<platform>/<id>.so | .dll | .dylib     (platforms.PLATFORMS: linux64, win64, darwin64,
                                                     aarch64-linux; FMI 3: x86_64-linux, ...)
    sources/<id>.c            the one translation unit: includes the files below
    sources/bushing_fmu.h, bushing_model.c and bushing_messages.h (generated), bushing_instance.h
            and instance_*.c (the instance by concern), fmi2_functions.c (or fmi3_functions.c),
            and the FMI headers
    sources/buildDescription.xml                                (FMI 3)

The FMI 2 headers are fmpy's copy; the FMI 3 ones are the standard's 3.0.1 headers, kept in ``c/``
(fmpy's are 3.0's, whose two callbacks without prototypes clang refuses under -Werror).
"""
from __future__ import annotations

import shutil
import subprocess
import tempfile
import zipfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from ...model.registry import DEFAULT_MODEL
from .. import model_description
from ..fmu_inputs import check_valid, fmu_axes, groups_of
from . import macho, platforms as toolchains
from .generate import model_source
from .messages_header import c_header

C_LAYER = Path(__file__).resolve().parent / "c"
INSTANCE = ("log", "parameters", "life_cycle", "variables", "cosimulation", "model_exchange", "derivatives",
            "fmu_state")
"""The instance's parts (``c/instance_<part>.c``), by concern, in the order the translation unit includes them."""
HAND_WRITTEN = ("bushing_fmu.h", "bushing_instance.h", *(f"instance_{part}.c" for part in INSTANCE))
FMI_HEADERS = {2: ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
               3: ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
WARNINGS = ("-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror")
FLAGS = ("-O3", "-fPIC", "-ffp-contract=off", "-fvisibility=hidden")
"""-ffp-contract=off: no fused multiply-add, so the C gives the Python kernels' floats on every CPU
(gcc fuses by default on aarch64); -fvisibility=hidden: only the FMI functions are exported."""


NO_COMPILER = ("without a compiler, use a release bundle's FMU (python build_fmu.py --release on a machine with gcc "
               "and mingw-w64, or the project's release page) and apply your parameters as start values")
"""What the build's error says when no platform can be compiled here: one binary per model serves
every parameter set, since the parameters are start values."""


class NativeBuildError(RuntimeError):
    """The native FMU could not be built (the message says which step and why)."""


@dataclass
class NativeBuild:
    path: Path
    platforms: list[str] = field(default_factory=list)
    skipped: dict[str, str] = field(default_factory=dict)    # platform -> why it was not built


def fmi_header_directory(fmi_version: int = 2) -> Path:
    """Where the FMI ``fmi_version`` headers are: fmpy's copy for FMI 2, ``c/`` for FMI 3."""
    if fmi_version == 3:
        return C_LAYER
    import fmpy
    folder = Path(fmpy.__file__).resolve().parent / "c-code"
    if not (folder / "fmi2Functions.h").is_file():
        raise NativeBuildError(f"the FMI headers are not in {folder}: reinstall fmpy (>= 0.3.20)")
    return folder


def write_sources(folder: Path, axis_models, identifier: str, fmi_version: int, groups=()):
    """Write the FMU's sources/ into ``folder``; returns the generated model (``generate``)."""
    folder.mkdir(parents=True, exist_ok=True)
    generated = model_source(axis_models, identifier, groups)
    (folder / "bushing_model.c").write_text(generated.source)
    (folder / "bushing_messages.h").write_text(c_header())
    functions = f"fmi{fmi_version}_functions.c"
    for name in (*HAND_WRITTEN, functions):
        shutil.copy2(C_LAYER / name, folder / name)
    headers = fmi_header_directory(fmi_version)
    for name in FMI_HEADERS[fmi_version]:
        shutil.copy2(headers / name, folder / name)
    (folder / f"{identifier}.c").write_text(
        f"/* The native FMU {identifier}: one translation unit (see bushing_fmu.h). */\n"
        '#include "bushing_fmu.h"\n#include "bushing_model.c"\n#include "bushing_messages.h"\n'
        '#include "bushing_instance.h"\n' + "".join(f'#include "instance_{part}.c"\n' for part in INSTANCE)
        + f'#include "{functions}"\n')
    return generated


def compile_binary(sources: Path, identifier: str, target: Path, compiler: tuple[str, ...], extra=()) -> None:
    """Compile the unit ``sources/<identifier>.c`` into the shared library ``target``."""
    target.parent.mkdir(parents=True, exist_ok=True)
    command = [*compiler, *WARNINGS, *FLAGS, *extra, "-shared", "-I", str(sources), "-o", str(target),
               str(sources / f"{identifier}.c"), "-lm"]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise NativeBuildError(f"{' '.join(compiler)} failed on {identifier}.c:\n{result.stderr[-4000:]}")


def compile_platform(sources: Path, identifier: str, platform: toolchains.Platform, binaries: Path) -> Path:
    """Compile ``binaries/<platform>/<identifier><suffix>``: one library for each of the platform's
    targets, the universal Mach-O of them where there are two."""
    library = binaries / platform.name / f"{identifier}{platform.suffix}"
    if len(platform.targets) == 1:
        compile_targets = {platform.targets[0]: library}
    else:
        compile_targets = {target: binaries / f"{platform.name}.{target.name}" / library.name
                           for target in platform.targets}
    for target, path in compile_targets.items():
        compile_binary(sources, identifier, path, toolchains.toolchain(target).command,
                       toolchains.target_flags(target, identifier))
    if len(platform.targets) > 1:
        library.parent.mkdir(parents=True, exist_ok=True)
        library.write_bytes(macho.universal([path.read_bytes() for path in compile_targets.values()]))
        for path in compile_targets.values():
            shutil.rmtree(path.parent)
    return library


def platform_names(fmi_version: int) -> tuple[str, ...]:
    """Every binary platform of an FMI ``fmi_version`` native FMU (platforms.PLATFORMS)."""
    try:
        return tuple(toolchains.platforms_of(fmi_version))
    except ValueError as exc:
        raise NativeBuildError(str(exc)) from None


def missing_platforms(fmi_version: int, platforms: tuple[str, ...] | None = None) -> dict[str, str]:
    """{platform: why it cannot be built here} of ``platforms`` (default: every platform) of an FMI
    ``fmi_version`` FMU; empty when every compiler is installed."""
    known = platform_names(fmi_version)
    table = toolchains.platforms_of(fmi_version)
    missing = {}
    for name in platforms or known:
        if name not in known:
            raise NativeBuildError(f"unknown platform {name!r} for FMI {fmi_version}; choose from {', '.join(known)}")
        if why := toolchains.missing(table[name]):
            missing[name] = why
    return missing


def build_native(axis_models, identifier: str, out_dir: str | Path, fmi_version: int = 2,
                 platforms: tuple[str, ...] | None = None, groups=()) -> NativeBuild:
    """Write ``out_dir/<identifier>.fmu``, a native FMU (FMI ``fmi_version``, co-simulation and
    model exchange) of the axes ``axis_models`` [(axes.Axis, model on that axis, parameters)] with
    the coupled ``groups`` (tuples of positions among them).
    ``platforms``: names of platforms.PLATFORMS, default platforms.QUICK_PLATFORMS (x86_64 Linux
    and Windows), each where its compiler is here; the result says which were skipped and why."""
    platform_names(fmi_version)
    wanted = list(platforms or toolchains.QUICK_PLATFORMS[fmi_version])
    out_dir = Path(out_dir)
    build = NativeBuild(out_dir / f"{identifier}.fmu")
    build.skipped = missing_platforms(fmi_version, tuple(wanted))
    if len(build.skipped) == len(wanted):
        raise NativeBuildError("no platform could be built: " + "; ".join(
            f"{p}: {why}" for p, why in build.skipped.items()) + f"; {NO_COMPILER}")
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="bushing_native_") as stage:
        stage = Path(stage)
        sources = stage / "sources"
        generated = write_sources(sources, axis_models, identifier, fmi_version, groups)
        if fmi_version == 2:
            xml = model_description.fmi2(axis_models, identifier, generated.token,
                                         model_description.native_face(identifier),
                                         event_indicators=generated.event_indicators, groups=groups)
        else:
            xml = model_description.fmi3(axis_models, identifier, generated.token, groups)
            (sources / "buildDescription.xml").write_bytes(model_description.build_description(identifier))
        (stage / "modelDescription.xml").write_bytes(xml)
        build.platforms = [platform for platform in wanted if platform not in build.skipped]
        known = toolchains.platforms_of(fmi_version)
        # the platforms' compilers run side by side (each its own process)
        with ThreadPoolExecutor(max_workers=len(build.platforms)) as pool:
            for done in [pool.submit(compile_platform, sources, identifier, known[name], stage / "binaries")
                         for name in build.platforms]:
                done.result()
        with zipfile.ZipFile(build.path, "w", zipfile.ZIP_DEFLATED) as archive:
            for path in sorted(stage.rglob("*")):
                if path.is_file():
                    archive.write(path, path.relative_to(stage).as_posix())
    return build


def build_native_fmu(params_file: str | Path | None = None, out_dir: str | Path = "dist", model: str = DEFAULT_MODEL,
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
        A model of ``fmu_src/model/registry.py`` or ``six_axis`` (default: the paper's, ``proposed``).
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
    identifier, _, axes, document = fmu_axes(params_file, model)
    build = build_native(axes, identifier, out_dir, fmi_version, platforms, groups_of(document))
    check_valid(build.path)
    return build


def chosen_platforms(text: str | None, fmi_version: int) -> tuple[str, ...] | None:
    """The platforms ``--platforms`` names (``all``: every one; None: the default). A named platform
    whose compiler is missing is refused, naming the package that provides it."""
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
