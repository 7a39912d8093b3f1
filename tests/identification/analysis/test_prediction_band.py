"""Where a measurement likely falls (identification.analysis.predict): the members' envelope
widened by 1.96 times the fit's rms misfit on its own training tests, which a fit records per test
(``misfit_N``, ``samples``) and ``predict`` reads from a FitResult or a parameter file."""
import math

import numpy as np
import pytest

from conftest import DATA
from fmu_src.model.registry import get_model
from fmu_src.parameter_files import ParameterEnsemble, read_ensemble
from identification import fit, predict, simulate
from identification.errors import FitNotConvergedWarning
from identification.analysis.predict import MISFIT_WIDENING, training_misfit_N
from identification.measured.measurements import load_measurement

SINE = DATA / "synthetic_table5_sine_2mm_10Hz.csv"


def test_the_training_misfit_pools_the_tests_by_their_samples():
    record = {"tests": [{"kind": "sine", "misfit_N": 3.0, "samples": 100},
                        {"kind": "step", "misfit_N": 4.0, "samples": 300},
                        {"kind": "kdyn"}]}          # a data sheet has no time-series residual
    ensemble = ParameterEnsemble(get_model("kelvin_voigt"), [{"k": 100.0, "c": 1.0, "preload": 0.0}], record)
    assert training_misfit_N(ensemble) == pytest.approx(math.sqrt((100 * 9.0 + 300 * 16.0) / 400))
    assert math.isnan(training_misfit_N({"k": 100.0, "c": 1.0, "preload": 0.0}))   # typed by hand
    assert math.isnan(training_misfit_N(ParameterEnsemble(ensemble.model, ensemble.members, {})))


def test_a_fits_misfit_is_its_residual_and_widens_the_prediction(tmp_path):
    # Kelvin-Voigt on the proposed model's sine: the linear model misses the loop by far more than
    # the noise; its misfit is the rms of what simulate gives against the record
    with pytest.warns(FitNotConvergedWarning):       # the loop is beyond a linear model: it says so
        result = fit([SINE], model="kelvin_voigt", ensemble=False, progress=False, workers=1)
    m = load_measurement(SINE)
    residual = simulate(result, m.time_s, m.displacement_mm) - m.force_N
    misfit = float(np.sqrt(np.mean(residual ** 2)))
    assert result.tests[0].misfit_N == pytest.approx(misfit, rel=1e-6) and misfit > 10 * result.tests[0].noise.sigma_N
    band = predict(result, m.time_s, m.displacement_mm)
    assert band.misfit_N == pytest.approx(misfit, rel=1e-6)
    assert np.allclose(band.likely_upper_N - band.upper_N, MISFIT_WIDENING * band.misfit_N, rtol=1e-12, atol=0)
    assert np.allclose(band.lower_N - band.likely_lower_N, MISFIT_WIDENING * band.misfit_N, rtol=1e-12, atol=0)
    inside = (m.force_N >= band.likely_lower_N) & (m.force_N <= band.likely_upper_N)
    assert np.mean(inside) > 0.9       # the record it was fitted to lies within what it says it misses
    # the parameter file keeps it, and predict reads it from there
    path = result.save(tmp_path / "params.json")[0]
    assert training_misfit_N(read_ensemble(path)) == pytest.approx(misfit, rel=1e-6)
    written = predict(path, m.time_s, m.displacement_mm).write_csv(tmp_path / "prediction.csv")
    header = [line for line in written.read_text().splitlines() if not line.startswith("#")][0]
    assert header == "time_s,displacement_mm,force_N,likely_min_N,likely_max_N"
