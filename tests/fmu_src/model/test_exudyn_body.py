"""examples/cosim/exudyn_body.py: a 30 kg body on the native bushing FMU (Table 5) inside Exudyn's
implicit integrator (generalized-alpha at 0.2 ms, the FMU's state restored for every force
evaluation), against the same system stepped by fmpy alone at 2 us: within 0.1 % of the peak
force (0.065 % measured); the reference converged (4 us gives the same within 0.02 %)."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "examples" / "cosim"))
import exudyn_body  # noqa: E402


@pytest.fixture(scope="module")
def fmu(native_fmu_path):
    pytest.importorskip("exudyn", reason="Exudyn is not installed (pip install '.[cosim]')")
    return Path(native_fmu_path)


@pytest.fixture(scope="module")
def reference(fmu):
    return exudyn_body.run_reference(fmu)


def test_the_body_in_exudyn_is_the_body_stepped_by_fmpy_alone(fmu, reference):
    body = exudyn_body.run_exudyn(fmu, 2e-4)
    assert exudyn_body.compare(body, reference) < 1e-3
    assert abs(body.force_N[-1] + exudyn_body.MASS_KG * exudyn_body.GRAVITY_M_S2) < 1.0     # settled on its weight
    assert body.evaluations > 2 * body.time_s.size          # Newton's iterates each evaluated from the step's start


def test_the_reference_is_converged(fmu, reference):
    coarse = exudyn_body.run_reference(fmu, 4e-6)
    index = slice(None, None, 2)
    difference = abs(coarse.force_N[1:] - reference.force_N[index][1:coarse.force_N.size])
    assert difference.max() < 2e-4 * abs(reference.force_N).max()
