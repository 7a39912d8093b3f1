"""The native FMU on every platform of the release: the aarch64 Linux library run under qemu-user
against the x86_64 one (FMI 2 and 3, the same inputs' bits, a C master compiled for each CPU), the
macOS libraries checked as Mach-O files (CPU, deployment target, install name, signature, exports,
linked libraries: built here, not run), and the generated C under clang's strict warnings.

The quick tests take the proposed model; the slow ones every one-axis model, a derived one, the
six-axis FMU and a coupled one. A toolchain that is missing skips its tests, naming its package."""
import importlib.util
import re
import shutil
import struct
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

import build_fmu
from fmu_src.fmi import fmu_inputs
from conftest import REPO
from fmu_src.fmi.axes import ONE_AXIS, SIX_AXES
from fmu_src.fmi.native import build as native_build, macho, platforms
from fmu_src.model.registry import MODELS
from test_six_axis_fmu import axis_signals

HOST_SOURCE = REPO / "tests" / "c_host" / "fmi_host.c"
CROSS_GCC = platforms.CROSS_GCC["aarch64"]
QEMU = shutil.which("qemu-aarch64") or shutil.which("qemu-aarch64-static")
SYSROOT = Path("/usr/aarch64-linux-gnu")
HAS_QEMU = (shutil.which(CROSS_GCC) is not None and QEMU is not None and (SYSROOT / "lib").is_dir()
            and shutil.which("cc") is not None)
needs_qemu = pytest.mark.skipif(not HAS_QEMU, reason=(
    "needs cc, the aarch64 cross gcc and qemu-user (Debian: apt-get install gcc gcc-aarch64-linux-gnu "
    "libc6-dev-arm64-cross qemu-user)"))
HAS_ZIG = importlib.util.find_spec("ziglang") is not None
needs_zig = pytest.mark.skipif(not HAS_ZIG, reason="needs zig (pip install ziglang, in the test extra)")
needs_macholib = pytest.mark.skipif(importlib.util.find_spec("macholib") is None,
                                    reason="needs macholib (pip install macholib, in the test extra)")
LINUX = {2: "linux64", 3: "x86_64-linux"}
DARWIN = {2: ("darwin64",), 3: ("x86_64-darwin", "aarch64-darwin")}
STEP_S, STEPS = 1e-3, 600


def build(tmp_path, model, version, names, params=None):
    """The native FMU of ``model`` with the binaries of the platforms ``names``."""
    return build_fmu.build_native_fmu(params, tmp_path / f"{model}-{version}", model, version, names).path


# --------------------------------------------------------------------------- aarch64 under qemu
@pytest.fixture(scope="module")
def hosts(tmp_path_factory):
    """tests/c_host/fmi_host.c compiled for this machine and for aarch64 (run under qemu)."""
    if not HAS_QEMU:
        pytest.skip("no aarch64 toolchain")
    folder = tmp_path_factory.mktemp("hosts")
    compiled = {}
    for architecture, compiler in (("x86_64", "cc"), ("aarch64", CROSS_GCC)):
        compiled[architecture] = folder / f"fmi_host_{architecture}"
        subprocess.run([compiler, "-std=c99", "-O1", "-ffp-contract=off", "-o", str(compiled[architecture]),
                        str(HOST_SOURCE), "-ldl"], check=True)
    return compiled


def port_signals(description) -> dict[str, np.ndarray]:
    """{input port: values at the end of each step} in SI: two tones on one axis, a different sine
    on each of six."""
    t = np.arange(1, STEPS + 1) * STEP_S
    if any(v.name == SIX_AXES[0].displacement for v in description.modelVariables):
        return axis_signals(t)
    w1, w2 = 2 * np.pi * 7.0, 2 * np.pi * 31.0
    return {ONE_AXIS.displacement: 2e-3 * np.sin(w1 * t) + 5e-4 * np.sin(w2 * t),
            ONE_AXIS.velocity: 2e-3 * w1 * np.cos(w1 * t) + 5e-4 * w2 * np.cos(w2 * t)}


def run_host(host, library: Path, fmu_folder: Path, description, version: int, under_qemu: bool) -> np.ndarray:
    """The outputs [steps x outputs] of the library driven by the C master, one step per input row."""
    refs = {v.name: v.valueReference for v in description.modelVariables}
    outputs = [v.name for v in description.modelVariables if v.causality == "output"]
    signals = port_signals(description)
    rows = "".join(" ".join(repr(float(value)) for value in row) + "\n" for row in zip(*signals.values()))
    token = description.guid if version == 2 else description.instantiationToken
    resources = (fmu_folder / "resources").as_uri() if version == 2 else str(fmu_folder / "resources") + "/"
    command = [str(host), str(version), str(library), token, resources, ",".join(str(refs[n]) for n in signals),
               ",".join(str(refs[n]) for n in outputs), repr(STEP_S)]
    if under_qemu:
        command = [QEMU, "-L", str(SYSROOT), *command]
    run = subprocess.run(command, input=rows, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    values = np.array([[float.fromhex(field) for field in line.split()] for line in run.stdout.splitlines()])
    assert values.shape == (STEPS, len(outputs))
    return values


def aarch64_against_x86_64(fmu: Path, version: int, hosts, tmp_path) -> tuple[float, int]:
    """(largest difference / peak output, samples not equal bit for bit) of the FMU's aarch64
    library under qemu against its x86_64 one."""
    folder = tmp_path / fmu.stem
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(folder)
    description = read_model_description(str(fmu))
    identifier = description.coSimulation.modelIdentifier
    x86 = run_host(hosts["x86_64"], folder / "binaries" / LINUX[version] / f"{identifier}.so", folder,
                   description, version, under_qemu=False)
    arm = run_host(hosts["aarch64"], folder / "binaries" / "aarch64-linux" / f"{identifier}.so", folder,
                   description, version, under_qemu=True)
    peak = np.max(np.abs(x86), axis=0)
    assert np.all(np.isfinite(arm)) and np.all(peak > 0)
    return float(np.max(np.abs(arm - x86) / peak)), int(np.sum(arm != x86))


@needs_qemu
@pytest.mark.parametrize("version", (2, 3))
def test_the_aarch64_library_under_qemu_gives_the_x86_64_forces(hosts, tmp_path, version):
    fmu = build(tmp_path, "proposed", version, (LINUX[version], "aarch64-linux"))
    assert validate_fmu(str(fmu)) == []
    relative, unequal = aarch64_against_x86_64(fmu, version, hosts, tmp_path)
    assert relative <= 1e-12, (relative, unequal)        # measured: bit for bit


@pytest.mark.slow
@needs_qemu
@pytest.mark.parametrize("version", (2, 3))
def test_every_model_under_qemu_gives_the_x86_64_forces(hosts, tmp_path, version):
    from example_parameter_files import derived_parameter_file, six_axis_file
    cases = {model: (model, None) for model in (*MODELS, "six_axis")}
    cases["derived"] = ("single_bouc_wen+backbone4+limits+maxwell", derived_parameter_file(tmp_path))
    cases["coupled six axis"] = ("six_axis", six_axis_file(tmp_path, {"translation": "spherical",
                                                                      "rotation": "conical"}))
    results = {}
    for name, (model, params) in cases.items():
        fmu = build(tmp_path / name.replace(" ", "_"), model, version, (LINUX[version], "aarch64-linux"), params)
        results[name] = aarch64_against_x86_64(fmu, version, hosts, tmp_path)
    print(f"\nFMI {version}, aarch64 under qemu against x86_64 (largest difference / peak, samples not equal):",
          results)
    assert all(relative <= 1e-12 for relative, _ in results.values()), results


# --------------------------------------------------------------------------- macOS, built and checked
def exported_functions_of_the_linux_library(fmu: Path, version: int, tmp_path) -> set[str]:
    """The dynamic symbols the FMU's x86_64 Linux library defines (``nm -D --defined-only``)."""
    identifier = read_model_description(str(fmu)).coSimulation.modelIdentifier
    with zipfile.ZipFile(fmu) as archive:
        so = archive.extract(f"binaries/{LINUX[version]}/{identifier}.so", tmp_path)
    listing = subprocess.run(["nm", "-D", "--defined-only", so], capture_output=True, text=True, check=True).stdout
    return {line.split()[-1] for line in listing.splitlines() if line.strip()}


def mach_o_slices(path: Path):
    """[(header, symbol table)] of every slice of a thin or universal Mach-O file (macholib)."""
    from macholib.MachO import MachO
    from macholib.SymbolTable import SymbolTable
    library = MachO(str(path))
    return [(header, SymbolTable(library, header)) for header in library.headers]


def check_mach_o_slice(header, symbols, identifier: str, exports: set[str]) -> str:
    """Assert what every macOS library of the FMU must be; returns its CPU (x86_64 or arm64)."""
    from macholib import mach_o
    cpu = {macho.CPU_TYPE_X86_64: "x86_64", macho.CPU_TYPE_ARM64: "arm64"}[header.header.cputype]
    assert header.filetype == "dylib" and header.header.magic in (mach_o.MH_MAGIC_64, mach_o.MH_CIGAM_64)
    commands = {}
    for load_command, command, data in header.commands:
        commands.setdefault(load_command.cmd, []).append((command, data))
    (identity, name), = commands[mach_o.LC_ID_DYLIB]
    assert name.rstrip(b"\0").decode() == f"@rpath/{identifier}.dylib"
    assert [data.rstrip(b"\0").decode() for _, data in commands[mach_o.LC_LOAD_DYLIB]] == ["/usr/lib/libSystem.B.dylib"]
    (build, _), = commands[mach_o.LC_BUILD_VERSION]
    assert build.platform == 1                                    # PLATFORM_MACOS
    assert (build.minos >> 16, (build.minos >> 8) & 0xFF) == {"x86_64": (10, 15), "arm64": (11, 0)}[cpu]
    if cpu == "arm64":                                            # Apple silicon loads signed code only
        assert mach_o.LC_CODE_SIGNATURE in commands
    # exports: the Linux library's FMI functions, and only the linker's own Mach-O header symbols
    defined = {name.decode().removeprefix("_") for entry, name in symbols.extdefsyms
               if not entry.n_type & mach_o.N_PEXT}
    assert defined - {"_mh_dylib_header", "__dso_handle"} == exports
    # imports: only what macOS's libSystem exports (its symbol list as zig ships it: the C library,
    # libm and the compiler-rt builtins, so no compiler-rt of zig's own is linked in)
    imported = {name.decode() for _, name in symbols.undefsyms}
    assert imported and imported <= libsystem_exports(), imported - libsystem_exports()
    return cpu


def libsystem_exports() -> set[str]:
    """Every name in zig's text stub of /usr/lib/libSystem.B.dylib (a superset of its exports)."""
    import ziglang
    stub = Path(ziglang.__file__).parent / "lib" / "libc" / "darwin" / "libSystem.tbd"
    return set(re.findall(r"[\w$.]+", stub.read_text()))


@needs_zig
@needs_macholib
@pytest.mark.parametrize("version", (2, 3))
def test_the_macos_libraries_are_mach_o_of_their_cpus_exporting_what_linux_exports(tmp_path, version):
    fmu = build(tmp_path, "proposed", version, (LINUX[version], *DARWIN[version]))
    assert validate_fmu(str(fmu)) == []
    check_macos_libraries(fmu, version, tmp_path)


def functions_of_the_fmi_header(version: int) -> set[str]:
    """Every function the FMI ``version`` header declares (``FMI2_Export fmi2DoStepTYPE fmi2DoStep;``)."""
    header = (native_build.fmi_header_directory(version) / f"fmi{version}Functions.h").read_text()
    return set(re.findall(rf"^\s*FMI{version}_Export\s+fmi{version}\w+TYPE\s+(fmi{version}\w+);", header, re.M))


def check_macos_libraries(fmu: Path, version: int, tmp_path):
    identifier = read_model_description(str(fmu)).coSimulation.modelIdentifier
    exports = exported_functions_of_the_linux_library(fmu, version, tmp_path)
    assert exports == functions_of_the_fmi_header(version) and len(exports) == {2: 44, 3: 75}[version]
    with zipfile.ZipFile(fmu) as archive:
        for platform in DARWIN[version]:
            path = Path(archive.extract(f"binaries/{platform}/{identifier}.dylib", tmp_path))
            cpus = [check_mach_o_slice(header, symbols, identifier, exports)
                    for header, symbols in mach_o_slices(path)]
            wanted = {"darwin64": ["x86_64", "arm64"], "x86_64-darwin": ["x86_64"], "aarch64-darwin": ["arm64"]}
            assert cpus == wanted[platform]
            if platform == "darwin64":                       # one universal file (FAT_MAGIC), as lipo writes it
                assert path.read_bytes()[:4] == b"\xca\xfe\xba\xbe"


@pytest.mark.slow
@needs_zig
@needs_macholib
@pytest.mark.parametrize("version", (2, 3))
def test_every_models_macos_libraries_pass_the_mach_o_checks(tmp_path, version):
    for model in (*MODELS, "six_axis"):
        fmu = build(tmp_path / model, model, version, (LINUX[version], *DARWIN[version]))
        check_macos_libraries(fmu, version, tmp_path / model)


def test_a_universal_file_holds_its_slices_unchanged_at_aligned_offsets():
    # two made-up thin headers: what lipo's fat_arch entries say, read back with the struct layout of <mach-o/fat.h>
    x86 = struct.pack("<IiI", macho.MH_MAGIC_64, macho.CPU_TYPE_X86_64, 3) + b"x" * 5000
    arm = struct.pack("<IiI", macho.MH_MAGIC_64, macho.CPU_TYPE_ARM64, 0x80000000) + b"a" * 300
    fat = macho.universal([x86, arm])
    magic, count = struct.unpack_from(">II", fat)
    assert (magic, count) == (0xCAFEBABE, 2)
    entries = [struct.unpack_from(">iIIII", fat, 8 + 20 * i) for i in range(2)]
    assert [(e[0], e[1], e[4]) for e in entries] == [(0x01000007, 3, 12), (0x0100000C, 0, 14)]
    for (_, _, offset, size, align), thin in zip(entries, (x86, arm)):
        assert offset % 2 ** align == 0 and fat[offset:offset + size] == thin
    with pytest.raises(ValueError, match="one slice per CPU"):
        macho.universal([x86, x86])
    with pytest.raises(ValueError, match="not a thin 64-bit"):
        macho.universal([b"\xca\xfe\xba\xbe" + bytes(20)])


# --------------------------------------------------------------------------- the generated C under clang
@needs_zig
@pytest.mark.parametrize("version", (2, 3))
def test_clang_takes_the_generated_c_with_the_projects_strict_flags(tmp_path, version):
    # zig's clang, for x86_64 Linux: -std=c99 -pedantic -Wall -Wextra -Werror, as gcc and mingw do in every build
    check_clang(tmp_path, ("proposed", "six_axis"), version)


def check_clang(tmp_path, models, version):
    for model in models:
        identifier, _, axes, document = fmu_inputs.fmu_axes(model=model)
        sources = tmp_path / f"{model}-{version}"
        native_build.write_sources(sources, axes, identifier, version, fmu_inputs.groups_of(document))
        run = subprocess.run([*platforms.ZIG, "-target", "x86_64-linux-gnu", *native_build.WARNINGS,
                              "-Wstrict-prototypes", "-c", "-o", str(sources / "check.o"), "-I", str(sources),
                              str(sources / f"{identifier}.c")],
                             capture_output=True, text=True)
        assert run.returncode == 0, run.stderr[-3000:]


@pytest.mark.slow
@needs_zig
@pytest.mark.parametrize("version", (2, 3))
def test_clang_takes_every_models_generated_c(tmp_path, version):
    check_clang(tmp_path, MODELS, version)


# --------------------------------------------------------------------------- asking for a platform
def test_a_platform_whose_compiler_is_missing_is_refused_naming_its_package(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(platforms.CROSS_GCC, "aarch64", "aarch64-linux-gnu-gcc-not-here")
    assert build_fmu.main(["--native", "--platforms", "linux64,aarch64-linux", "--out", str(tmp_path)]) == 2
    error = capsys.readouterr().err
    assert error.startswith("error: cannot build aarch64-linux: aarch64-linux-gnu-gcc-not-here is not installed "
                            "(Debian: apt-get install gcc-aarch64-linux-gnu)")
    monkeypatch.setattr(platforms, "ZIG", ("python-without-zig", "-m", "ziglang", "cc"))
    assert build_fmu.main(["--native", "--fmi-version", "3", "--platforms", "aarch64-darwin",
                           "--out", str(tmp_path)]) == 2
    assert "aarch64-darwin: python-without-zig is not installed (pip install ziglang)" in capsys.readouterr().err
    assert build_fmu.main(["--native", "--platforms", "darwin", "--out", str(tmp_path)]) == 2
    assert ("unknown platform 'darwin' for FMI 2; choose from linux64, win64, darwin64, aarch64-linux"
            in capsys.readouterr().err)
    assert not list(tmp_path.iterdir())
