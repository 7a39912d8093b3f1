"""The binary platforms of a native FMU and the toolchain that compiles each one here.

Each platform is a directory under the FMU's ``binaries/`` (FMI 2: ``linux64``, ``win64``,
``darwin64`` and the FMI 2.0.4 tuple ``aarch64-linux``; FMI 3: ``<arch>-<os>`` tuples) holding one
shared library, compiled from the FMU's one translation unit for one target (CPU and operating
system), or for two: FMI 2's ``darwin64`` is a universal Mach-O of an x86_64 and an arm64 slice,
since FMI 2 names one macOS platform and both kinds of Mac read it.

The toolchains, each from a package registry:

- the system's C compiler (``$CC``, default ``cc``) for the machine it runs on;
- cross gcc for the other Linux CPU (Debian: ``gcc-aarch64-linux-gnu``, ``gcc-x86-64-linux-gnu``);
- mingw-w64 for Windows (Debian: ``gcc-mingw-w64-x86-64``);
- zig's clang for macOS (PyPI: ``ziglang``; its own macOS SDK stubs, Mach-O linker and ad-hoc
  signature): deployment targets 10.15 (x86_64) and 11.0 (arm64, the first macOS on Apple silicon).
"""
from __future__ import annotations

import importlib.util
import os
import platform as host_platform
import shutil
import sys
from dataclasses import dataclass


@dataclass(frozen=True)
class Toolchain:
    """A C compiler: ``command`` starts its command line; ``package`` says how to install it."""
    command: tuple[str, ...]
    package: str

    def missing(self) -> str | None:
        """Why this compiler cannot run here (naming what provides it), or None."""
        program = self.command[0]
        if program == sys.executable and self.command[1:3] == ("-m", "ziglang"):
            if importlib.util.find_spec("ziglang") is None:
                return f"zig is not installed ({self.package})"
            return None
        if shutil.which(program) is None:
            return f"{program} is not installed ({self.package})"
        return None


@dataclass(frozen=True)
class Target:
    """One CPU and operating system a library is compiled for: ``architecture`` (``x86_64``,
    ``aarch64``) and ``system`` (``linux``, ``windows``, ``darwin``), as in FMI 3's tuples."""
    architecture: str
    system: str

    @property
    def name(self) -> str:
        return f"{self.architecture}-{self.system}"


@dataclass(frozen=True)
class Platform:
    """A directory ``binaries/<name>/`` holding ``<identifier><suffix>`` compiled for ``targets``
    (two: a universal Mach-O of both)."""
    name: str
    suffix: str
    targets: tuple[Target, ...]


X86_64_LINUX, AARCH64_LINUX = Target("x86_64", "linux"), Target("aarch64", "linux")
X86_64_WINDOWS = Target("x86_64", "windows")
X86_64_DARWIN, AARCH64_DARWIN = Target("x86_64", "darwin"), Target("aarch64", "darwin")

PLATFORMS = {
    2: (Platform("linux64", ".so", (X86_64_LINUX,)), Platform("win64", ".dll", (X86_64_WINDOWS,)),
        Platform("darwin64", ".dylib", (X86_64_DARWIN, AARCH64_DARWIN)),
        Platform("aarch64-linux", ".so", (AARCH64_LINUX,))),
    3: (Platform("x86_64-linux", ".so", (X86_64_LINUX,)), Platform("x86_64-windows", ".dll", (X86_64_WINDOWS,)),
        Platform("x86_64-darwin", ".dylib", (X86_64_DARWIN,)), Platform("aarch64-darwin", ".dylib", (AARCH64_DARWIN,)),
        Platform("aarch64-linux", ".so", (AARCH64_LINUX,))),
}
"""Every platform of a native FMU of each FMI version: what a release bundle carries."""
QUICK_PLATFORMS = {2: ("linux64", "win64"), 3: ("x86_64-linux", "x86_64-windows")}
"""What ``build_fmu.py --native`` builds unless told otherwise (each where its compiler is here): the
x86_64 Linux and Windows libraries, two compilations rather than six."""

MINGW = "x86_64-w64-mingw32-gcc"
CROSS_GCC = {"x86_64": "x86_64-linux-gnu-gcc", "aarch64": "aarch64-linux-gnu-gcc"}
CROSS_PACKAGE = {"x86_64": "Debian: apt-get install gcc-x86-64-linux-gnu",
                 "aarch64": "Debian: apt-get install gcc-aarch64-linux-gnu"}
ZIG = (sys.executable, "-m", "ziglang", "cc")
DEPLOYMENT_TARGET = {"x86_64": "10.15", "aarch64": "11.0"}
"""The oldest macOS each slice loads on: 10.15 (Catalina, 2019) for Intel Macs, 11.0 (Big Sur, the
first macOS on Apple silicon) for arm64."""


def host_target() -> Target | None:
    """The target the system's C compiler builds for: this machine's (None where it is not one of
    the native FMU's)."""
    architecture = {"x86_64": "x86_64", "amd64": "x86_64", "aarch64": "aarch64", "arm64": "aarch64"}.get(
        host_platform.machine().lower())
    system = {"linux": "linux", "win32": "windows", "darwin": "darwin"}.get(sys.platform)
    return Target(architecture, system) if architecture and system else None


def toolchain(target: Target) -> Toolchain:
    """The compiler of ``target`` here: the system's (``$CC``) for this machine's Linux target,
    cross gcc for the other Linux CPU, mingw-w64 for Windows, zig for macOS."""
    if target.system == "darwin":
        return Toolchain(ZIG, "pip install ziglang")
    if target.system == "windows":
        return Toolchain((MINGW,), "Debian: apt-get install gcc-mingw-w64-x86-64")
    if target == host_target():
        return Toolchain((os.environ.get("CC", "cc"),), "Debian: apt-get install gcc")
    return Toolchain((CROSS_GCC[target.architecture],), CROSS_PACKAGE[target.architecture])


def target_flags(target: Target, identifier: str) -> tuple[str, ...]:
    """What ``target``'s compilation adds to the project's flags: mingw links libgcc statically (the
    DLL needs no mingw runtime); zig is told the macOS target and gives the library an ``@rpath``
    install name, as a host that loads it by path or bundles it expects, and links no compiler-rt
    of its own: macOS's libSystem carries those builtins, and zig would otherwise build its
    compiler-rt for each target on first use (3 s each, a tenth of a fresh release)."""
    if target.system == "windows":
        return ("-static-libgcc",)
    if target.system == "darwin":
        return ("-target", f"{target.architecture}-macos.{DEPLOYMENT_TARGET[target.architecture]}",
                f"-Wl,-install_name,@rpath/{identifier}.dylib", "-rtlib=none")
    return ()


def platforms_of(fmi_version: int) -> dict[str, Platform]:
    """{name: Platform} of every platform of an FMI ``fmi_version`` native FMU."""
    if fmi_version not in PLATFORMS:
        raise ValueError(f"FMI version {fmi_version}: give 2 or 3")
    return {platform.name: platform for platform in PLATFORMS[fmi_version]}


def missing(platform: Platform) -> str | None:
    """Why ``platform`` cannot be built here (each missing compiler and its package), or None."""
    reasons = dict.fromkeys(why for target in platform.targets if (why := toolchain(target).missing()))
    return "; ".join(reasons) or None
