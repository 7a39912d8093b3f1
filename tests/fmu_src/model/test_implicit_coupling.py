"""examples/cosim/implicit_coupling.py: a light body on the native bushing FMU (Table 5) released
from 1 mm. At a 1 ms communication step explicit coupling diverges at 0.3 kg and 1 kg (the FMU
refuses a step), and the linearly implicit coupling with the FMU's dF/dx, dF/dv stays within 0.2
of the initial displacement of the 0.01 ms reference over 0.3 s; the reference is converged
(0.02 ms gives the same to 1 % of x0)."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "examples" / "cosim"))
import implicit_coupling as coupling  # noqa: E402


@pytest.fixture(scope="module")
def fmu(native_fmu_path):
    return str(native_fmu_path)


@pytest.mark.parametrize("mass_kg", [0.3, 1.0])
def test_linearly_implicit_coupling_stays_bounded_where_explicit_coupling_diverges(fmu, mass_kg):
    reference = coupling.couple(fmu, mass_kg, 1e-5, "explicit")
    assert reference.refused_at is None
    explicit = coupling.couple(fmu, mass_kg, 1e-3, "explicit")
    assert explicit.refused_at is not None and explicit.refused_at < 0.05
    implicit = coupling.couple(fmu, mass_kg, 1e-3, "implicit")
    assert implicit.refused_at is None
    assert coupling.deviation(implicit, reference) <= 0.2


def test_the_reference_is_converged(fmu):
    fine = coupling.couple(fmu, 1.0, 1e-5, "explicit")
    coarse = coupling.couple(fmu, 1.0, 2e-5, "explicit")
    assert coupling.deviation(coarse, fine) <= 0.01


def test_bad_arguments_are_refused(fmu):
    with pytest.raises(ValueError, match="mass -1.0 kg"):
        coupling.couple(fmu, -1.0, 1e-3, "implicit")
