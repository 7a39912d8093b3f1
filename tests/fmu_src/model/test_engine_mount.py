"""The engine-mount example: three six-axis bushing FMUs and a rigid-body FMU in libcosim and fmpy.

Checks the frame work around the six-axis bushing (issue: six-axis FMU, section 4): the two
masters agree, the body's momentum and angular momentum change by the impulses the six-axis
convention assigns, and with Kelvin-Voigt axes the natural frequencies through the FMUs are
those of the linearised system written from the geometry alone.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(REPO / "examples" / "cosim"))

import engine_mount  # noqa: E402
import ssp_system  # noqa: E402

STEP = 1e-3
STOP = 0.12


def run_road(out: Path, native: bool = False, coupling: str = "none"):
    """The road case written as SSP in ``out`` and run in libcosim and fmpy: (body, libcosim, fmpy)."""
    out.mkdir(parents=True, exist_ok=True)
    bushing_set = engine_mount.coupled_set(out, coupling)
    bushing_fmu, body_fmu = engine_mount.build_fmus(out / "fmus", bushing_set, native=native)
    body = engine_mount.body_parameters()
    parts = engine_mount.write_system(out / "EngineMount", bushing_fmu, body_fmu, STOP, body, bushing_set)
    libcosim = ssp_system.run_libcosim(out / "EngineMount", parts, STEP, STOP)
    fmpy_run = ssp_system.run_fmpy(parts, engine_mount.connections(), STEP, STOP)
    return body, libcosim, fmpy_run


@pytest.fixture(scope="module")
def road_runs(tmp_path_factory):
    return run_road(tmp_path_factory.mktemp("engine"))


@pytest.mark.slow
def test_libcosim_and_fmpy_agree_on_the_engine(road_runs):
    _, libcosim, fmpy_run = road_runs
    differences = ssp_system.largest_difference(libcosim, fmpy_run)
    assert len(differences) == 3 * 12 + 17 + 3 * 6      # every output of the four components
    assert max(differences.values()) < 1e-9, max(differences.items(), key=lambda item: item[1])
    # the bushings are loaded in every direction: a real check, not zeros against zeros
    for mount in engine_mount.MOUNTS:
        for name in ("Fx", "Fy", "Fz", "Mx", "My", "Mz"):
            assert np.max(np.abs(libcosim[f"bushing_{mount}.{name}"])) > 1e-3


@pytest.mark.slow
def test_with_native_six_axis_fmus_libcosim_and_fmpy_agree_and_give_the_pythonfmu_systems_outputs(road_runs,
                                                                                                  tmp_path):
    _, libcosim_python, _ = road_runs
    _, libcosim, fmpy_run = run_road(tmp_path, native=True)
    assert max(ssp_system.largest_difference(libcosim, fmpy_run).values()) <= 1e-12
    assert max(ssp_system.largest_difference(libcosim, libcosim_python).values()) <= 1e-12


@pytest.mark.slow
@pytest.mark.parametrize("native", [False, True])
def test_with_radially_coupled_mounts_the_masters_agree_and_the_momentum_balances(road_runs, tmp_path, native):
    # x and y of every mount one coupled group: each axis's force now depends on the other's motion
    body, libcosim, fmpy_run = run_road(tmp_path, native=native, coupling="radial")
    assert max(ssp_system.largest_difference(libcosim, fmpy_run).values()) < 1e-9
    balance = engine_mount.momentum_balance(fmpy_run, STEP, body)
    assert balance["momentum"] < 1e-6 and balance["angular momentum"] < 1e-6
    _, uncoupled, _ = road_runs
    left = [np.hypot(run["bushing_left.Fx"], run["bushing_left.Fy"]) for run in (libcosim, uncoupled)]
    assert 0.0 < np.max(np.abs(left[0] - left[1])) < 0.1 * np.max(left[1])     # it changes the forces, a little


@pytest.mark.slow
def test_momentum_changes_by_the_bushing_impulses(road_runs):
    body, _, fmpy_run = road_runs
    balance = engine_mount.momentum_balance(fmpy_run, STEP, body)
    assert balance["momentum"] < 1e-6 and balance["angular momentum"] < 1e-6, balance


@pytest.mark.slow
def test_the_momentum_check_sees_a_lost_or_reversed_moment(road_runs):
    # The same run, with the bushings' moments dropped or reversed as a careless master would:
    # the balance must fail, so the check above can fail.
    body, _, fmpy_run = road_runs
    for factor in (0.0, -1.0):
        altered = dict(fmpy_run)
        for mount in engine_mount.MOUNTS:
            for name in ("Mx", "My", "Mz"):
                key = f"{engine_mount.BODY}.{mount}_{name}"
                altered[key] = factor * fmpy_run[key]
        assert engine_mount.momentum_balance(altered, STEP, body)["angular momentum"] > 1e-3


@pytest.mark.slow
def test_kelvin_voigt_natural_frequencies_match_the_linearised_system(tmp_path):
    step = 5e-4
    measured, linearised, run = engine_mount.free_decay(tmp_path, step, 2.0)
    # the six modes are distinct, and the spectrum finds each within 1 %
    assert np.all(np.diff(linearised) > 1.5)
    np.testing.assert_allclose(measured, linearised, rtol=0.01)
    # The twist the body sends is the rate of the pose it sends (base still): the body moves by
    # h*v_new each step, so the backward difference of d is v; the rotation vector's rate is
    # the relative angular velocity to small-angle order.
    for mount in engine_mount.MOUNTS:
        for pose, rate, tolerance in (("dx", "vx", 1e-3), ("dy", "vy", 1e-3), ("dz", "vz", 1e-3),
                                      ("rx", "wx", 5e-3), ("ry", "wy", 5e-3), ("rz", "wz", 5e-3)):
            d = run[f"{engine_mount.BODY}.{mount}_{pose}"]
            v = run[f"{engine_mount.BODY}.{mount}_{rate}"]
            assert np.max(np.abs(np.diff(d) / step - v[1:])) < tolerance * np.max(np.abs(v)), (mount, pose)
