"""Installable like the tools users know: console scripts, package data, one version."""
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description

from conftest import REPO
from fmu_src import __version__

BIN = Path(sys.executable).parent


@pytest.fixture(scope="module")
def installed_wheel(tmp_path_factory) -> Path:
    """The project's wheel, unpacked into a folder of its own (a pure-Python wheel unpacked is
    installed): what `pip install` puts on a user's machine, with no checkout behind it."""
    folder = tmp_path_factory.mktemp("wheel")
    # Built from a copy: setuptools leaves build/ behind, whose stale files a later build would pack.
    source = folder / "source"
    shutil.copytree(REPO, source, ignore=shutil.ignore_patterns(".git", ".venv", "build", "dist", "out", "*.egg-info",
                                                                 "__pycache__", ".pytest_cache"))
    result = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", str(source), "-w", str(folder)],
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    wheel, = folder.glob("*.whl")
    site = folder / "site"
    with zipfile.ZipFile(wheel) as archive:
        archive.extractall(site)
    return site


def run_outside_the_checkout(site: Path, cwd: Path, code: str) -> subprocess.CompletedProcess:
    # PYTHONPATH comes before the editable install's finder, so the unpacked wheel is what runs.
    environment = dict(os.environ, PYTHONPATH=str(site))
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, env=environment, capture_output=True, text=True,
                          timeout=300)


@pytest.mark.slow
def test_the_wheel_declares_both_console_scripts(installed_wheel):
    entry_points, = installed_wheel.glob("*.dist-info/entry_points.txt")
    text = entry_points.read_text()
    assert "bushing-identify = identification.cli:main" in text
    assert "bushing-build-fmu = build_fmu:main" in text


@pytest.mark.slow
def test_the_installed_build_finds_its_default_parameters_outside_the_checkout(installed_wheel, tmp_path):
    code = ("import sys, build_fmu\n"
            "print(build_fmu.__file__)\n"
            "sys.exit(build_fmu.main(['--model', 'kelvin_voigt']))\n")
    result = run_outside_the_checkout(installed_wheel, tmp_path, code)
    assert result.returncode == 0, result.stderr[-3000:]
    assert str(installed_wheel) in result.stdout          # the wheel's copy ran, not the checkout's
    fmu = tmp_path / "dist" / "KelvinVoigtBushing.fmu"    # in the working directory, not site-packages
    assert fmu.is_file()
    assert read_model_description(str(fmu)).version == __version__


@pytest.mark.slow
def test_the_installed_build_makes_a_native_fmu_outside_the_checkout(installed_wheel, tmp_path):
    # the C layer ships with the package (package data), the generated C is written at build time
    result = run_outside_the_checkout(installed_wheel, tmp_path,
                                      "import sys, build_fmu\nsys.exit(build_fmu.main(['--native']))\n")
    assert result.returncode == 0, result.stderr[-3000:]
    fmu = tmp_path / "dist" / "BoucWenBushing.fmu"
    with zipfile.ZipFile(fmu) as archive:
        assert {"sources/instance_cosimulation.c", "sources/bushing_messages.h", "sources/fmi2_functions.c", "binaries/linux64/BoucWenBushing.so"} \
            <= set(archive.namelist())


@pytest.mark.parametrize("script", ["bushing-identify", "bushing-build-fmu"])
def test_console_scripts_print_the_projects_version_from_any_directory(script, tmp_path):
    path = BIN / script
    if not path.exists():
        pytest.skip(f"{script} is not installed in this environment (pip install -e . makes it)")
    result = subprocess.run([str(path), "--version"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0
    assert result.stdout.strip() == f"{script} {__version__}"


def test_version_lives_in_one_place():
    pyproject = (REPO / "pyproject.toml").read_text()
    assert 'dynamic = ["version"]' in pyproject and 'version = { attr = "fmu_src.__version__" }' in pyproject
    from importlib.metadata import PackageNotFoundError, version
    try:
        assert version("boucwen-bushing") == __version__
    except PackageNotFoundError:
        pytest.skip("the project is not installed")
    assert f"## {__version__}" in (REPO / "CHANGELOG.md").read_text()


def test_fmu_carries_the_version_and_the_generation_tool(fmu_path):
    description = read_model_description(str(fmu_path))
    assert description.version == __version__
    assert description.generationTool.startswith(f"boucwen-bushing {__version__} (build_fmu.py) with PythonFMU")


def test_license_is_the_one_the_package_and_the_fmu_declare(fmu_path):
    assert (REPO / "LICENSE").read_text().startswith("MIT License")
    assert 'license = { text = "MIT" }' in (REPO / "pyproject.toml").read_text()
    assert read_model_description(str(fmu_path)).license == "MIT"


@pytest.mark.slow
def test_the_base_install_builds_runs_and_simulates_and_names_the_extra_it_lacks(tmp_path):
    # `pip install .` alone, in a fresh environment: numpy, scipy, pythonfmu, fmpy and nothing
    # of the extras. It builds the FMU and runs it through fmpy, simulates with the kernels as
    # plain Python, and a fit says which extra to install (one line, exit 2).
    import venv
    environment = tmp_path / "venv"
    venv.EnvBuilder(with_pip=True).create(environment)
    python = environment / "bin" / "python"
    source = tmp_path / "source"
    shutil.copytree(REPO, source, ignore=shutil.ignore_patterns(".git", ".venv", "build", "dist", "out", "*.egg-info",
                                                                 "__pycache__", ".pytest_cache", "site"))
    installed = subprocess.run([str(python), "-m", "pip", "install", "-q", str(source)], capture_output=True,
                               text=True, timeout=900)
    assert installed.returncode == 0, installed.stderr[-3000:]
    work = tmp_path / "work"
    work.mkdir()
    script = ("import importlib.util, sys\n"
              "import numpy as np\n"
              "for extra in ('numba', 'matplotlib', 'pymoo', 'emcee', 'distributed', 'libcosimpy'):\n"
              "    assert importlib.util.find_spec(extra) is None, extra + ' is installed'\n"
              "import build_fmu\n"
              "from fmpy import simulate_fmu\n"
              "from identification import simulate\n"
              "from fmu_src.fmi.fmu_inputs import default_parameter_file\n"
              "path = build_fmu.build_fmu(out_dir='dist')\n"
              "t = np.arange(0, 0.201, 1e-3)\n"
              "table = np.array(list(zip(t, 2e-3*np.sin(20*np.pi*t), 2e-3*20*np.pi*np.cos(20*np.pi*t))),\n"
              "                 dtype=[('time', float), ('x', float), ('v', float)])\n"
              "fmu = simulate_fmu(str(path), stop_time=0.2, step_size=1e-3, input=table, output=['F'])\n"
              "force = simulate(default_parameter_file(), t, 2*np.sin(20*np.pi*t))\n"
              "print(np.max(np.abs(fmu['F'])), np.max(np.abs(force)))\n")
    run = subprocess.run([str(python), "-c", script], capture_output=True, text=True, timeout=600, cwd=work)
    assert run.returncode == 0, run.stderr[-3000:]
    fmu_peak, simulated_peak = map(float, run.stdout.split()[-2:])
    assert 4000.0 < fmu_peak < 5000.0 and 4000.0 < simulated_peak < 5000.0   # Table 5 on 2 mm / 10 Hz
    fit = subprocess.run([str(environment / "bin" / "bushing-identify"), "fit", "--sine",
                          str(REPO / "data" / "synthetic_table5_sine_2mm_10Hz.csv"), "--out", "p.json"],
                         capture_output=True, text=True, timeout=120, cwd=work)
    assert fit.returncode == 2 and fit.stderr.count("\n") == 1 and "Traceback" not in fit.stderr
    assert "needs the 'fit' extra" in fit.stderr and "pip install 'boucwen-bushing[fit]'" in fit.stderr
