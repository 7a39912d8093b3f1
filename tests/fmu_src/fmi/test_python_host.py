"""Which step the pythonfmu FMU runs (compiled_kernels.compile_axes): the compiled (numba) step in a
host process that is a Python interpreter, the pure-Python step in a C/C++ host that embeds Python
(numba's kernels corrupted such a host's heap, tests/fmu_src/fmi/test_c_host.py), told by the operating
system's name for the process's executable on Linux, Windows and macOS. The platform is faked here
(sys.platform and the system call's library); the sentence the FMU logs says which step and why."""
import ntpath
import os
import sys

import pytest

from fmu_src.kernels import numba_binding as compiled_kernels
from fmu_src.model.registry import MODELS

MODEL = MODELS["kelvin_voigt"]
AXES = [("x", MODEL, {})]


@pytest.fixture
def compiling(monkeypatch):
    """compiled_model without numba: the model's own kernels, as if compiled in 0.25 s (what is
    tested here is the choice and its sentence, not numba)."""
    calls = []

    def compiled_model(model):
        calls.append(model.name)
        kernels = {name: getattr(model, name) for name in compiled_kernels.COMPILED_IN_FMU}
        kernels["step_axes"] = kernels["step_one"] = None
        return kernels, 0.25
    monkeypatch.setattr(compiled_kernels, "compiled_model", compiled_model)
    monkeypatch.delenv(compiled_kernels.STEP_ENVIRONMENT, raising=False)
    return calls


class Kernel32:
    """Windows' GetModuleFileNameW(NULL, buffer, size) for a process whose .exe is ``path``."""

    def __init__(self, path):
        self.path = path

    def GetModuleFileNameW(self, module, buffer, size):  # noqa: N802  Windows' name
        assert module is None and size == len(buffer)
        buffer.value = self.path
        return len(self.path)


class LibSystem:
    """macOS's _NSGetExecutablePath(buffer, &size): -1 and the size needed if the buffer is too small."""

    def __init__(self, path):
        self.path = path.encode()

    def _NSGetExecutablePath(self, buffer, size):  # noqa: N802  macOS's name
        if buffer is None or size.contents.value < len(self.path) + 1:
            size.contents.value = len(self.path) + 1
            return -1
        buffer.value = self.path
        return 0


def fake_linux(monkeypatch, path):
    monkeypatch.setattr(sys, "platform", "linux")
    real_readlink = os.readlink
    monkeypatch.setattr(os, "readlink", lambda link: path if link == "/proc/self/exe" else real_readlink(link))


def fake_windows(monkeypatch, path):
    monkeypatch.setattr(sys, "platform", "win32")
    monkeypatch.setattr(compiled_kernels, "_kernel32", lambda: Kernel32(path))


def fake_macos(monkeypatch, path):
    monkeypatch.setattr(sys, "platform", "darwin")
    monkeypatch.setattr(compiled_kernels, "_libc", lambda: LibSystem(path))


PYTHON_HOSTS = [
    (fake_linux, "/usr/bin/python3.12"),
    (fake_linux, "/opt/conda/bin/python3.11"),
    (fake_windows, r"C:\Program Files\Python312\python.exe"),
    (fake_windows, r"C:\Users\me\AppData\Local\Programs\Python\Python311\pythonw.exe"),
    (fake_macos, "/Library/Frameworks/Python.framework/Versions/3.12/Resources/Python.app/Contents/MacOS/Python"),
    (fake_macos, "/opt/homebrew/Cellar/python@3.12/3.12.4/bin/python3.12"),
]
C_HOSTS = [
    (fake_linux, "/opt/simulator/bin/cosim_master"),
    (fake_windows, r"C:\Program Files\Simulator\bin\cosim.exe"),
    (fake_macos, "/Applications/Simulator.app/Contents/MacOS/Simulator"),
]


def case_id(case):
    fake, path = case
    return f"{fake.__name__.removeprefix('fake_')}-{ntpath.basename(path)}"   # ntpath: / and \\ both


@pytest.mark.parametrize("fake, executable", PYTHON_HOSTS, ids=[case_id(c) for c in PYTHON_HOSTS])
def test_a_python_interpreter_host_runs_the_compiled_step_on_every_platform(monkeypatch, compiling, fake,
                                                                            executable):
    fake(monkeypatch, executable)
    axes, batched, said = compiled_kernels.compile_axes(AXES)
    assert compiling == ["kelvin_voigt"] and set(batched) == {"kelvin_voigt"}
    assert said.startswith(f"compiled step (numba): the host is {executable} (")
    assert "a Python interpreter" in said and "0.25 s" in said


@pytest.mark.parametrize("fake, executable", C_HOSTS, ids=[case_id(c) for c in C_HOSTS])
def test_a_c_host_embedding_python_runs_the_pure_python_step_and_says_why(monkeypatch, compiling, fake, executable):
    fake(monkeypatch, executable)
    axes, batched, said = compiled_kernels.compile_axes(AXES)
    assert compiling == [] and batched == {} and axes == AXES
    assert said.startswith(f"pure-Python step: the host is not a Python interpreter ({executable}, by ")
    assert "corrupted the heap" in said and "BUSHING_FMU_STEP=compiled forces them" in said


@pytest.mark.parametrize("fake, executable", C_HOSTS, ids=[case_id(c) for c in C_HOSTS])
def test_bushing_fmu_step_compiled_overrides_the_host_check(monkeypatch, compiling, fake, executable):
    fake(monkeypatch, executable)
    monkeypatch.setenv(compiled_kernels.STEP_ENVIRONMENT, "compiled")
    _, batched, said = compiled_kernels.compile_axes(AXES)
    assert set(batched) == {"kelvin_voigt"}
    assert said.startswith(f"compiled step (numba): the host is {executable} (") and "BUSHING_FMU_STEP=compiled" in said


def test_a_platform_that_cannot_name_the_executable_runs_the_pure_python_step(monkeypatch, compiling):
    monkeypatch.setattr(sys, "platform", "sunos5")

    def no_procfs(link):
        raise FileNotFoundError(link)
    monkeypatch.setattr(os, "readlink", no_procfs)
    _, batched, said = compiled_kernels.compile_axes(AXES)
    assert batched == {} and compiling == []
    assert said.startswith("pure-Python step: the host's executable is unknown (none of /proc/self/exe, "
                           "/proc/curproc/file exists on sunos5)")


def test_a_failing_system_call_runs_the_pure_python_step(monkeypatch, compiling):
    class Failing(Kernel32):
        def GetModuleFileNameW(self, module, buffer, size):  # noqa: N802
            return 0     # Windows' failure
    monkeypatch.setattr(sys, "platform", "win32")
    monkeypatch.setattr(compiled_kernels, "_kernel32", lambda: Failing(""))
    _, batched, said = compiled_kernels.compile_axes(AXES)
    assert batched == {}
    assert "the host's executable is unknown (asking win32 for it failed (OSError: GetModuleFileNameW returned 0))" \
        in said


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the unfaked check of a Linux process")
def test_this_python_process_is_a_python_host_by_the_real_system():
    executable, how = compiled_kernels.host_executable()
    assert how == "/proc/self/exe"
    assert os.path.samefile(executable, sys.executable)
    assert compiled_kernels._python_host(executable)

