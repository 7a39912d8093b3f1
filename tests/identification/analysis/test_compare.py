"""Choosing the model (identification.analysis.compare): the recommendation rule on hand-made assessments,
and `compare` through the command line on the synthetic filled-rubber bushing."""
import csv
import math
from pathlib import Path

import numpy as np
import pytest

from identification.__main__ import main
from identification.analysis.compare import Assessment, recommend
from identification.fitting.result import TableFit

DATA = Path(__file__).resolve().parents[3] / "data"
FILLED = DATA / "synthetic_filled_rubber"


def assessment(model, parameters, ratio, held_out=None, table=None, misfit=1.0, residuals=1000):
    a = Assessment(model, parameters, residuals, misfit, ratio, ratio <= 1.25, ratio <= 1.25, 1.0)
    if held_out is not None:
        a.validation = {"held_out.csv": (held_out, 0.0)}
    if table is not None:    # a table error of `table` uncertainties: |K*| off by table %
        a.table = TableFit("table.csv", np.array([table * 0.01]), np.array([0.0]), np.array([1.0]), 0.0)
    return a


def test_the_simplest_model_at_the_floor_that_predicts_within_ten_percent_of_the_best_is_recommended():
    choice = recommend([assessment("many", 14, 1.0, held_out=0.0100), assessment("few", 6, 1.1, held_out=0.0108),
                        assessment("linear", 2, 40.0, held_out=0.2)])
    assert choice.model == "few"
    assert "2 of 3 at the floor" in choice.reason and "fewest free parameters" in choice.reason


def test_a_simpler_model_that_predicts_worse_by_more_than_ten_percent_is_not_recommended():
    choice = recommend([assessment("many", 14, 1.0, held_out=0.0100), assessment("few", 6, 1.1, held_out=0.0120)])
    assert choice.model == "many"


def test_every_kind_of_held_out_data_must_be_predicted_well():
    choice = recommend([assessment("a", 6, 1.0, held_out=0.010, table=5.0),
                        assessment("b", 8, 1.0, held_out=0.0105, table=0.5)])
    assert choice.model == "b"


def test_without_a_model_at_the_floor_the_best_predictor_is_recommended_and_the_reason_says_so():
    choice = recommend([assessment("a", 6, 3.0, held_out=0.05), assessment("b", 14, 2.0, held_out=0.03),
                        assessment("c", 2, 50.0, held_out=0.30)])
    assert choice.model == "b" and choice.reason.startswith("no model reaches the floor")


def test_without_a_model_at_the_floor_or_held_out_data_the_lowest_bic_is_recommended_not_the_fewest_parameters():
    # the friction-damper sine: every model misses (70, 74 and 142 times the noise), and the
    # linear bushing, the simplest, misses most; chi^2 = n*misfit decides, the parameters' ln(n) hardly
    n = 5000
    proposed = assessment("proposed", 14, 70.0, misfit=70.0 ** 2, residuals=n)
    bouc_wen = assessment("single_bouc_wen", 6, 74.0, misfit=74.0 ** 2, residuals=n)
    linear = assessment("kelvin_voigt", 2, 142.0, misfit=142.0 ** 2, residuals=n)
    choice = recommend([linear, bouc_wen, proposed])
    assert choice.model == "proposed"
    assert choice.reason.startswith("no model reaches the floor") and "lowest BIC" in choice.reason
    assert "no model describes these data to their floor" in choice.caveat
    assert "proposed" in choice.caveat and "70x the noise" in choice.caveat


def test_without_a_model_at_the_floor_a_close_predictor_with_the_lower_bic_is_recommended():
    # within 10 % of the best held-out error, the information criterion decides, not the parameters
    choice = recommend([assessment("few", 2, 40.0, held_out=0.100, misfit=1600.0),
                        assessment("many", 14, 20.0, held_out=0.105, misfit=400.0),
                        assessment("off", 8, 10.0, held_out=0.300, misfit=100.0)])
    assert choice.model == "many" and "2 predict the held-out files within 10% of the best" in choice.reason
    assert choice.caveat


def test_models_at_the_floor_carry_no_caveat():
    choice = recommend([assessment("a", 6, 1.0), assessment("b", 2, 30.0, misfit=900.0)])
    assert choice.model == "a" and choice.caveat == ""


def test_without_held_out_data_equal_counts_are_decided_by_the_information_criterion():
    # BIC = n*misfit + d*ln(n): the same d, the lower chi^2 wins
    a, b = assessment("a", 8, 1.1, misfit=1.02), assessment("b", 8, 1.0, misfit=1.01)
    assert b.information_criterion < a.information_criterion
    assert recommend([a, b]).model == "b"
    assert recommend([a, b, assessment("c", 6, 1.2, misfit=1.1)]).model == "c"
    assert b.information_criterion == pytest.approx(1000 * 1.01 + 8 * math.log(1000))


@pytest.mark.slow
def test_compare_on_the_filled_rubber_bushing_writes_its_files_and_recommends_a_filled_rubber_model(tmp_path, capsys):
    out = tmp_path / "cmp"
    code = main(["compare", "--models", "berg,kelvin_voigt", "--sine", f"{FILLED}_sine_2mm_10Hz.csv",
                 "--sine", f"{FILLED}_sine_0.5mm_3Hz.csv", "--validate", f"{FILLED}_random_2mm.csv",
                 "--validate-kdyn", str(DATA / "kdyn_synthetic_filled_rubber.csv"), "--screening", "256",
                 "--starts", "8", "--no-ensemble", "--quiet", "--out", str(out)])
    printed = capsys.readouterr().out
    assert code == 0
    assert printed.strip().splitlines()[-1] == "recommended: berg"     # Kelvin-Voigt misses by 20x the noise
    for name in ("comparison.csv", "validation.csv", "kdyn_errors.csv", "params_berg.json", "params_kelvin_voigt.json",
                 "compare_synthetic_filled_rubber_random_2mm.png", "compare_kdyn_synthetic_filled_rubber.csv.png"):
        assert (out / name).is_file(), name
    with open(out / "comparison.csv") as handle:
        rows = {row["model"]: row for row in csv.DictReader(handle)}
    assert rows["berg"]["recommended"] == "True" and rows["kelvin_voigt"]["recommended"] == "False"
    assert int(rows["berg"]["free_parameters"]) == 8 and int(rows["kelvin_voigt"]["free_parameters"]) == 2
    with open(out / "kdyn_errors.csv") as handle:
        assert sum(1 for _ in csv.DictReader(handle)) == 2 * 25      # every row of the table, per model


@pytest.mark.slow
def test_compare_on_a_hydromount_data_sheet_recommends_the_hydraulic_model(tmp_path, capsys):
    # compare --kdyn (issue 43): the synthetic mount's training sheet (0.1, 0.5, 2 mm x 1-50 Hz) and
    # its 1 mm / 8 Hz sine, data/generate_hydraulic.py; only the hydraulic models have a fluid column
    # to give a 60-70 deg loss-angle peak, so only they reach the floor, and of the two the membrane
    # model, with fewer parameters, is recommended (issue 49: the free plate does not displace it)
    out = tmp_path / "cmp"
    code = main(["compare", "--models", "hydraulic,hydraulic_free_decoupler,berg,kelvin_voigt", "--kdyn",
                 str(DATA / "kdyn_synthetic_hydraulic_train.csv"), "--sine",
                 str(DATA / "synthetic_hydraulic_sine_1mm_8Hz.csv"), "--no-ensemble", "--quiet", "--out", str(out)])
    printed = capsys.readouterr().out
    assert code == 0
    assert printed.strip().splitlines()[-1] == "recommended: hydraulic"
    with open(out / "comparison.csv") as handle:
        floor = {row["model"]: row["at_floor"] for row in csv.DictReader(handle)}
    assert floor == {"hydraulic": "True", "hydraulic_free_decoupler": "True", "berg": "False", "kelvin_voigt": "False"}


@pytest.mark.slow
def test_compare_on_a_free_play_mount_recommends_the_free_plate(tmp_path, capsys):
    # issue 49: data/generate_hydraulic_free_decoupler.py's mount (a hard-caged plate free within
    # +-0.12 mm and progressive rubber, solved by scipy, not by a model of the project), trained on
    # its sheet and its 1 mm / 8 Hz sine: the membrane's fluid path never lets go, so only the free
    # plate reaches the floor; it predicts the unseen 0.3 and 1 mm sheet within 3 % and 2 deg
    import json
    from identification.forward.dynamic_stiffness import characterise
    from identification.measured.kdyn_table import load_kdyn_table
    out = tmp_path / "cmp"
    code = main(["compare", "--models", "hydraulic,hydraulic_free_decoupler", "--kdyn",
                 str(DATA / "kdyn_synthetic_free_decoupler_train.csv"), "--sine",
                 str(DATA / "synthetic_free_decoupler_sine_1mm_8Hz.csv"), "--no-ensemble", "--quiet", "--out", str(out)])
    printed = capsys.readouterr().out
    assert code == 0
    assert printed.strip().splitlines()[-1] == "recommended: hydraulic_free_decoupler"
    with open(out / "comparison.csv") as handle:
        floor = {row["model"]: row["at_floor"] for row in csv.DictReader(handle)}
    assert floor == {"hydraulic": "False", "hydraulic_free_decoupler": "True"}
    unseen = load_kdyn_table(DATA / "kdyn_synthetic_free_decoupler_unseen.csv")
    fitted = json.loads((out / "params_hydraulic_free_decoupler.json").read_text())["parameters"]
    sheet = characterise(fitted, amplitudes_mm=(0.3, 1.0), frequencies_hz=np.unique(unseen.frequency_hz),
                         model="hydraulic_free_decoupler")
    mine, truth = np.lexsort((sheet.frequency_hz, sheet.amplitude_mm)), np.lexsort((unseen.frequency_hz,
                                                                                    unseen.amplitude_mm))
    assert np.max(np.abs(sheet.kdyn_N_per_mm[mine] / unseen.kdyn_N_per_mm[truth] - 1.0)) <= 0.03   # measured 0.70 %
    assert np.max(np.abs(sheet.loss_angle_deg[mine] - unseen.loss_angle_deg[truth])) <= 2.0       # measured 0.22 deg


@pytest.mark.slow
def test_compare_on_filled_rubber_does_not_recommend_the_hydraulic_model(tmp_path, capsys):
    # the hydraulic model has no rate-independent friction: on the filled rubber (its stiffness
    # falling with amplitude, a loss angle flat over frequency) Berg's model stays the choice
    out = tmp_path / "cmp"
    code = main(["compare", "--models", "berg,hydraulic", "--sine", f"{FILLED}_sine_2mm_10Hz.csv",
                 "--sine", f"{FILLED}_sine_0.5mm_3Hz.csv", "--validate", f"{FILLED}_random_2mm.csv",
                 "--screening", "256", "--starts", "8", "--no-ensemble", "--quiet", "--out", str(out)])
    assert code == 0
    assert capsys.readouterr().out.strip().splitlines()[-1] == "recommended: berg"


def test_a_model_whose_fitted_set_fails_on_a_whole_record_is_not_recommended():
    # its misfit on the fit's strided samples was the lowest; on every sample its simulation fails
    failed = assessment("stiff", 4, math.inf, misfit=1.0)
    choice = recommend([failed, assessment("other", 8, 3.0, misfit=9.0)])
    assert choice.model == "other"
