"""The rig's offsets as nuisance parameters (fmu_src.model.derived's ``rig`` option, the fit's
result): a test made of a known model read through a known displacement zero and load-cell zero;
the fit recovers both, reports them with their uncertainty, and keeps them out of the parameter
file unless asked. The truth is Berg's filled rubber, whose progressive spring k0*x + k3*x^3 tells
a displacement zero from a load-cell zero (for a linear spring the two are one constant force)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import DATA
from fmu_src.parameter_files import read_parameter_set
from identification.measured.measurements import Measurement
from identification.measured.rig_tests import RigTest
from identification.measured.signals import Sine, sample_times
from python_core import simulate_python_core

ZERO_MM, LOAD_CELL_N = 0.25, 35.0


@pytest.fixture(scope="module")
def fitted(request):
    """The fit (under the optimizer tests' rounding variant: a module's fixture applies it itself)."""
    from identification.fitting.fit import fit
    from suite_options import rounding_variant
    import warnings
    from identification.errors import FitNotConvergedWarning
    truth = read_parameter_set(DATA / "params_berg_filled_rubber.json").parameters
    with warnings.catch_warnings(), rounding_variant(request.config):
        warnings.simplefilter("ignore", FitNotConvergedWarning)     # 1.5x its noise: the budget is small
        tests = []
        for amplitude, frequency, seed in ((2.0, 10.0, 1), (1.0, 3.0, 2)):
            t = sample_times(0.6, 1000.0)
            x, v = Sine(amplitude, frequency).signals(t)
            # the bushing sits at its own zero where the rig reads 0.25 mm; the load cell reads 35 N at no force
            force = simulate_python_core(truth, t, x - ZERO_MM, v, model="berg") + LOAD_CELL_N
            force = force + np.random.default_rng(seed).normal(0.0, 3.0, t.size)
            tests.append(RigTest(Measurement(t, x, force, v, source=f"sine_{amplitude}mm.csv"), kind="sine"))
        return fit(tests, model="berg+rig", screening=1024, starts=32, workers=1, progress=False), truth


@pytest.mark.slow
@pytest.mark.optimizer
def test_the_fit_recovers_the_rigs_offsets_within_their_uncertainty(fitted):
    result, _ = fitted
    offsets = result.rig_offsets
    zero, spread_zero, unit_zero = offsets["rig_displacement_zero"]
    force, spread_force, unit_force = offsets["rig_force_zero"]
    assert (unit_zero, unit_force) == ("mm", "N")
    assert abs(zero - ZERO_MM) <= max(3 * spread_zero, 0.01), (zero, spread_zero)
    assert abs(force - LOAD_CELL_N) <= max(3 * spread_force, 1.0), (force, spread_force)
    assert 0.0 < spread_zero < 0.05 and 0.0 < spread_force < 15.0        # measured 0.013 mm and 7.0 N
    assert "rig offsets" in result.summary() and "force zero" in result.summary()


@pytest.mark.slow
def test_the_parameter_file_keeps_the_offsets_out_of_the_model_unless_asked(fitted, tmp_path):
    result, truth = fitted
    result.save(tmp_path / "p.json", ensemble=tmp_path / "e.json")
    saved = read_parameter_set(tmp_path / "p.json")
    assert saved.model.name == "berg" and not any(name.startswith("rig_") for name in saved.parameters)
    document = json.loads((tmp_path / "p.json").read_text())
    record = document["fit"]["rig_offsets"]
    assert set(record) == {"rig_displacement_zero", "rig_force_zero"}
    assert record["rig_force_zero"]["unit"] == "N" and document["fit"]["rig_offsets_in_fmu"] is False
    ensemble = json.loads((tmp_path / "e.json").read_text())
    assert all(not any(name.startswith("rig_") for name in member) for member in ensemble["ensemble"])
    # asked: the FMU's mounting takes them, the same force at any displacement
    result.save(tmp_path / "in.json", rig_into_fmu=True)
    mounted = read_parameter_set(tmp_path / "in.json")
    assert mounted.parameters["offset"] == pytest.approx(result.rig_offsets["rig_displacement_zero"][0])
    assert mounted.parameters["preload"] == pytest.approx(result.rig_offsets["rig_force_zero"][0])
