"""Build a native bushing FMU: C generated from the model definitions, compiled for linux64 (the
system's C compiler) and win64 (mingw-w64, where it is installed), its sources inside so that
any tool can compile it for another platform (FMI 2 ``<SourceFiles>``, FMI 3
``buildDescription.xml``). No Python in the host: ``needsExecutionTool="false"``.

Layout of the FMU::

    modelDescription.xml
    binaries/linux64/<id>.so, binaries/win64/<id>.dll        (FMI 3: x86_64-linux, x86_64-windows)
    sources/<id>.c            the one translation unit: includes the files below
    sources/bushing_fmu.h, bushing_model.c (generated), bushing_instance.c, fmi2_functions.c
            (or fmi3_functions.c), and the FMI headers
    sources/buildDescription.xml                                (FMI 3)

The FMI 2 headers are fmpy's copy; the FMI 3 ones are the standard's 3.0.1 headers, kept in ``c/``
(fmpy's are 3.0's, whose two callbacks without prototypes clang refuses under -Werror).
"""
from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
import zipfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from .. import model_description
from .generate import model_source

C_LAYER = Path(__file__).resolve().parent / "c"
HAND_WRITTEN = ("bushing_fmu.h", "bushing_instance.c")
FMI_HEADERS = {2: ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
               3: ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
WARNINGS = ("-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror")
FLAGS = ("-O3", "-fPIC", "-ffp-contract=off", "-fvisibility=hidden")
"""-ffp-contract=off: no fused multiply-add, so the C gives the Python kernels' floats;
-fvisibility=hidden: only the FMI functions are exported."""
MINGW = "x86_64-w64-mingw32-gcc"
PLATFORMS = {2: {"linux64": ".so", "win64": ".dll"}, 3: {"x86_64-linux": ".so", "x86_64-windows": ".dll"}}


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
    functions = f"fmi{fmi_version}_functions.c"
    for name in (*HAND_WRITTEN, functions):
        shutil.copy2(C_LAYER / name, folder / name)
    headers = fmi_header_directory(fmi_version)
    for name in FMI_HEADERS[fmi_version]:
        shutil.copy2(headers / name, folder / name)
    (folder / f"{identifier}.c").write_text(
        f"/* The native FMU {identifier}: one translation unit (see bushing_fmu.h). */\n"
        '#include "bushing_fmu.h"\n#include "bushing_model.c"\n#include "bushing_instance.c"\n'
        f'#include "{functions}"\n')
    return generated


def compile_binary(sources: Path, identifier: str, target: Path, compiler: str, extra=()) -> None:
    """Compile the unit ``sources/<identifier>.c`` into the shared library ``target``."""
    target.parent.mkdir(parents=True, exist_ok=True)
    command = [compiler, *WARNINGS, *FLAGS, *extra, "-shared", "-I", str(sources), "-o", str(target),
               str(sources / f"{identifier}.c"), "-lm"]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise NativeBuildError(f"{compiler} failed on {identifier}.c:\n{result.stderr[-4000:]}")


def platform_compilers(fmi_version: int) -> dict[str, str]:
    """The compiler of each binary platform of an FMI ``fmi_version`` FMU: linux64 the system's
    ``cc`` (or ``$CC``), win64 mingw-w64 (FMI 3: x86_64-linux, x86_64-windows)."""
    if fmi_version not in (2, 3):
        raise NativeBuildError(f"FMI version {fmi_version}: give 2 or 3")
    native = os.environ.get("CC", "cc")
    return dict(zip(PLATFORMS[fmi_version], (native, MINGW)))


def missing_platforms(fmi_version: int, platforms: tuple[str, ...] | None = None) -> dict[str, str]:
    """{platform: why it cannot be built here} of ``platforms`` (default: every platform) of an FMI
    ``fmi_version`` FMU; empty when every compiler is installed."""
    compilers = platform_compilers(fmi_version)
    missing = {}
    for platform in platforms or compilers:
        if platform not in compilers:
            raise NativeBuildError(f"unknown platform {platform!r} for FMI {fmi_version}; "
                                   f"choose from {', '.join(compilers)}")
        compiler = compilers[platform]
        if shutil.which(compiler) is None:
            missing[platform] = (f"{compiler} is not installed" + (
                " (Debian: apt-get install gcc-mingw-w64-x86-64)" if compiler == MINGW else ""))
    return missing


def build_native(axis_models, identifier: str, out_dir: str | Path, fmi_version: int = 2,
                 platforms: tuple[str, ...] | None = None, groups=()) -> NativeBuild:
    """Write ``out_dir/<identifier>.fmu``, a native FMU (FMI ``fmi_version``, co-simulation and
    model exchange) of the axes ``axis_models`` [(axes.Axis, model on that axis, parameters)] with
    the coupled ``groups`` (tuples of positions among them).
    ``platforms``: default every platform whose compiler is here (linux64 with the system's
    ``cc``, win64 with mingw-w64); the result says which were skipped and why."""
    compilers = platform_compilers(fmi_version)
    wanted = list(platforms or compilers)
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

        def compile_platform(platform: str) -> None:
            compiler = compilers[platform]
            extra = ("-static-libgcc",) if compiler == MINGW else ()
            binary = stage / "binaries" / platform / f"{identifier}{PLATFORMS[fmi_version][platform]}"
            compile_binary(sources, identifier, binary, compiler, extra)

        # the platforms' compilers run side by side (each its own process)
        with ThreadPoolExecutor(max_workers=len(build.platforms)) as pool:
            for done in [pool.submit(compile_platform, platform) for platform in build.platforms]:
                done.result()
        with zipfile.ZipFile(build.path, "w", zipfile.ZIP_DEFLATED) as archive:
            for path in sorted(stage.rglob("*")):
                if path.is_file():
                    archive.write(path, path.relative_to(stage).as_posix())
    return build
