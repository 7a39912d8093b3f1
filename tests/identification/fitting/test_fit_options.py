"""A fit's settings as one value (``FitOptions``): the front doors take keywords as before, refuse
an unknown one by name, and pass one value on."""
from pathlib import Path

import pytest

from identification import FitOptions, fit
from identification.analysis.compare import CompareOptions, compare_models
from identification.fitting.fit import training_request
from identification.fitting.fleet import fit_many
from identification.measured.rig_tests import training_tests

DATA = Path(__file__).resolve().parents[3] / "data"


def test_options_take_keywords_over_a_value_and_refuse_an_unknown_one_by_name():
    base = FitOptions(seed=3, starts=8)
    assert FitOptions.of(base, screening=64) == FitOptions(seed=3, starts=8, screening=64)
    assert FitOptions.of() == FitOptions()
    assert FitOptions.of(base) is not None and base.starts == 8      # frozen: the value is not changed
    with pytest.raises(TypeError, match="unknown keyword sed; the fit takes preset, seed"):
        FitOptions.of(sed=1)


@pytest.mark.parametrize("call", [
    lambda: fit([], sed=1),
    lambda: training_request([], "proposed", sed=1),
    lambda: fit_many("no-such-folder", "out", sed=1),
])
def test_a_front_door_refuses_an_unknown_keyword_before_any_work(call):
    with pytest.raises(TypeError, match="sed"):
        call()


def test_compare_refuses_an_unknown_keyword(tmp_path):
    with pytest.raises(TypeError, match="sed"):
        compare_models(["kelvin_voigt"], [], [], tmp_path, sed=1)


def test_a_value_and_the_same_keywords_make_the_same_request():
    tests = training_tests(sine=[DATA / "synthetic_table5_sine_2mm_10Hz.csv"])
    by_value = training_request(tests, "single_bouc_wen", FitOptions(seed=2, screening=128, starts=4, preset="paper"))
    by_keywords = training_request(tests, "single_bouc_wen", seed=2, screening=128, starts=4, preset="paper")
    assert (by_value.seed, by_value.preset, by_value.settings) == (2, "paper", by_keywords.settings)
    assert by_keywords.settings.screening == 128 and by_keywords.settings.stages[0][0] == 4


def test_compares_fits_run_without_their_ensemble_and_with_its_data_sheet():
    training = CompareOptions(seed=5, ensemble=True, training_table="sheet", race=False).training()
    assert training == FitOptions(seed=5, ensemble=False, kdyn="sheet")
