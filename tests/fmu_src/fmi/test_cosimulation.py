"""Real co-simulation: the shaker-rig example in libcosim (from its SSP file) and in fmpy."""
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(REPO / "examples" / "cosim"))

import shaker_rig  # noqa: E402
from fmu_src.parameter_files import load_parameters  # noqa: E402
from identification.forward.population import simulate_population_held  # noqa: E402

STEP = 1e-3
STOP = 0.15


def run_rig(out: Path, native: bool = False):
    """The rig written as SSP in ``out`` and run in libcosim and fmpy: (system_dir, libcosim, fmpy)."""
    bushing_fmu, body_fmu = shaker_rig.build_fmus(out / "fmus", native)
    system_dir = out / "ShakerRig"
    shaker_rig.write_ssp(system_dir, bushing_fmu, body_fmu, STOP)
    libcosim = shaker_rig.run_libcosim(system_dir, STEP, STOP)
    fmpy_run = shaker_rig.run_fmpy(bushing_fmu, body_fmu, system_dir, STEP, STOP)
    return system_dir, libcosim, fmpy_run


@pytest.fixture(scope="module")
def rig_runs(tmp_path_factory):
    return run_rig(tmp_path_factory.mktemp("rig"))


def test_libcosim_and_fmpy_agree_on_the_same_system(rig_runs):
    _, libcosim, fmpy_run = rig_runs
    differences = shaker_rig.largest_difference(libcosim, fmpy_run)
    assert max(differences.values()) < 0.01, differences   # the bound
    assert max(differences.values()) < 1e-9, differences   # same scheme: equal in practice


@pytest.mark.parametrize("component", list(shaker_rig.BUSHINGS))
def test_libcosim_applies_each_components_parameter_set(rig_runs, component):
    # Every bushing's force in libcosim is the model with *its* .ssv parameters driven by the
    # displacement the body sent it: the SSP parameter binding was applied, to the right one.
    system_dir, libcosim, _ = rig_runs
    x_sent = np.concatenate([[0.0], libcosim[f"{shaker_rig.BODY}.x_rel"][:-1]]) * 1e3   # mm
    v_sent = np.concatenate([[0.0], libcosim[f"{shaker_rig.BODY}.v_rel"][:-1]]) * 1e3   # mm/s
    t = STEP * np.arange(x_sent.size + 1)
    params = load_parameters(system_dir / "resources" / f"{component}.ssv")
    expected = simulate_population_held([params], t, np.append(x_sent, 0.0), np.append(v_sent, 0.0))[0, 1:]
    force = libcosim[f"{component}.F"]
    np.testing.assert_allclose(force, expected, rtol=1e-9, atol=1e-9 * np.max(np.abs(expected)))
    default = load_parameters(REPO / "data" / "params_table5_combined.json")
    if params != default:
        wrong = simulate_population_held([default], t, np.append(x_sent, 0.0), np.append(v_sent, 0.0))[0, 1:]
        assert np.max(np.abs(force - wrong)) > 0.01 * np.max(np.abs(force))


def test_an_invalid_parameter_fails_libcosims_run_and_reaches_its_log(rig_runs, tmp_path):
    import re
    import shutil
    import subprocess

    system_dir, _, _ = rig_runs
    broken = tmp_path / "BrokenRig"
    shutil.copytree(system_dir, broken)
    ssv = broken / "resources" / "bushing_front_left.ssv"
    # An invalid value written past our own checked writer, as a hand-edited file would be.
    ssv.write_text(re.sub(r'(<ssv:Parameter name="c1">\s*<ssv:Real value=")[^"]*', r"\g<1>0.0", ssv.read_text()))
    # libcosim logs from its own threads to the process's console: run it in a child to read that.
    script = ("from libcosimpy.CosimExecution import CosimExecution\n"
              "from libcosimpy.CosimLogging import CosimLogLevel, log_output_level\n"
              "log_output_level(CosimLogLevel.WARNING)\n"
              f"execution = CosimExecution.from_ssp_file({str(broken)!r}, step_size={int(STEP * 1e9)})\n"
              "print('step', execution.step())\n")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert "step False" in result.stdout, result.stdout + result.stderr[-2000:]
    log = result.stdout + result.stderr  # libcosim's console sink writes to stdout
    assert "category=logStatusError" in log and "c1 = 0.0 [N.s/mm] must be > 0" in log
    assert result.returncode == 0    # a failed step, not an aborted process


def test_with_native_bushing_fmus_libcosim_and_fmpy_agree_and_give_the_pythonfmu_systems_outputs(rig_runs,
                                                                                              tmp_path):
    # The same rig with the compiled bushing FMU (the body stays a pythonfmu FMU)
    _, libcosim_python, _ = rig_runs
    _, libcosim, fmpy_run = run_rig(tmp_path, native=True)
    assert max(shaker_rig.largest_difference(libcosim, fmpy_run).values()) <= 1e-12
    assert max(shaker_rig.largest_difference(libcosim, libcosim_python).values()) <= 1e-12


def test_an_invalid_start_value_stops_libcosim_with_the_native_fmus_reason(tmp_path):
    # The native FMU answers an invalid start value with fmi2Error at fmi2ExitInitializationMode;
    # libcosim (libcosimpy 0.0.6) ends its process on that (terminate after a cosim::error),
    # after its log has the reason.
    import re
    import subprocess
    bushing_fmu, body_fmu = shaker_rig.build_fmus(tmp_path / "fmus", native=True)
    system_dir = tmp_path / "ShakerRig"
    shaker_rig.write_ssp(system_dir, bushing_fmu, body_fmu, STOP)
    ssv = system_dir / "resources" / "bushing_front_left.ssv"
    ssv.write_text(re.sub(r'(<ssv:Parameter name="c1">\s*<ssv:Real value=")[^"]*', r"\g<1>0.0", ssv.read_text()))
    script = ("from libcosimpy.CosimExecution import CosimExecution\n"
              "from libcosimpy.CosimLogging import CosimLogLevel, log_output_level\n"
              "log_output_level(CosimLogLevel.WARNING)\n"
              f"execution = CosimExecution.from_ssp_file({str(system_dir)!r}, step_size={int(STEP * 1e9)})\n"
              "print('step', execution.step(), flush=True)\n")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    log = result.stdout + result.stderr
    assert result.returncode != 0 and "step True" not in log
    assert "c1 = 0.0 [N.s/mm] must be > 0 (it divides eq. 3)" in log and "the simulation cannot start" in log
