"""A search that starts from a nested model's fit (``loop_start.FitStart``: ``compare`` weighing the
recommended model's variants): one screened start is that fit itself, the added element at its
neutral values, so the variant ends no worse than the fit it nests, whatever its budget; a fit
that sets every coordinate is one start, not copies of it."""
from dataclasses import replace
from pathlib import Path

import pytest

from fmu_src.model.registry import get_model
from identification.fitting.engine import SerialEngine
from identification.fitting.fit import training_request
from identification.fitting.loop_start import FitStart
from identification.fitting.presets import SearchSettings
from identification.fitting.search import run
from identification.measured.rig_tests import training_tests

DATA = Path(__file__).resolve().parents[3] / "data"
TINY = SearchSettings(screening=4, stages=((1, 3),))
"""Four Sobol points and one start of three evaluations: alone, far from any fit."""


@pytest.fixture(scope="module")
def tests_and_fit():
    tests = training_tests(sine=[DATA / "synthetic_table5_sine_2mm_10Hz.csv"],
                           step=[DATA / "synthetic_table5_step_2mm_rise0.4s.csv"], rise_times_s=[0.4])
    base = run(training_request(tests, "single_bouc_wen", screening=256, starts=8, ensemble=False),
               SerialEngine(), False, 0.0)
    return tests, base


@pytest.mark.parametrize("settings", [TINY, SearchSettings(screening=64, stages=((1, 3),), prefix_fraction=0.1,
                                                           prefix_kept=1 / 64)])
def test_a_variant_with_an_element_added_starts_at_the_fit_it_nests(tests_and_fit, settings):
    # with a prefix screening too, which keeps 5 of the 320 points and must keep the fit's own
    tests, base = tests_and_fit
    variant = get_model("single_bouc_wen+maxwell")
    start = FitStart(dict(base.parameters.parameters), "single_bouc_wen", dict(variant.options.neutral))
    assert start.neutral == {"maxwell_k": 0.0, "maxwell_c": 1.0}
    request = replace(training_request(tests, variant, ensemble=False), settings=settings, start=start)
    result = run(request, SerialEngine(), False, 0.0)
    # the Maxwell element's stiffness at the box's lowest, its time constant screened: the fit's force
    # within a fraction of a per cent; least squares from there only descends
    assert result.misfit <= base.misfit * 1.001
    assert any("screened starts take the parameters of the single_bouc_wen fit" in note for note in result.notes)


def test_a_fit_that_sets_every_coordinate_is_one_start(tests_and_fit):
    tests, base = tests_and_fit
    # the element left out: every coordinate of the plain model is the nested fit's (here, its own)
    start = FitStart(dict(base.parameters.parameters), "single_bouc_wen")
    request = replace(training_request(tests, "single_bouc_wen", ensemble=False), settings=TINY, start=start)
    result = run(request, SerialEngine(), False, 0.0)
    assert any(note.startswith("note: 1 of the screened starts take") for note in result.notes)
    assert result.misfit <= base.misfit * (1 + 1e-9)


def test_a_search_from_a_fit_screens_an_eighth_and_runs_a_quarter_of_the_starts_never_more():
    from identification.fitting.presets import PRESETS, from_a_fit
    settings = from_a_fit(PRESETS["default"])      # 8192 points, (128, 10), (24, 30), (6, 300)
    assert settings.screening == 1024 and settings.stages == ((32, 10), (6, 30), (3, 300))
    small = SearchSettings(screening=64, stages=((2, 10), (2, 30), (2, 300)))
    assert from_a_fit(small) == replace(small, screening=8)       # at most the starts it was given
    assert from_a_fit(PRESETS["paper"]) == PRESETS["paper"]       # the GA's population as it is


def test_the_parameter_file_says_the_search_as_it_ran(tests_and_fit):
    tests, base = tests_and_fit
    assert base.provenance()["method"].startswith("256 scrambled Sobol points")      # screening=256 given
    start = FitStart(dict(base.parameters.parameters), "single_bouc_wen")
    request = replace(training_request(tests, "single_bouc_wen", ensemble=False), settings=TINY, start=start)
    method = run(request, SerialEngine(), False, 0.0).provenance()["method"]
    assert method.startswith("4 scrambled Sobol points") and "(starts x evaluations: 1 x 3)" in method
    assert method.endswith("; started from the single_bouc_wen fit")


def test_compare_searches_each_variant_from_the_recommended_fit(tmp_path):
    import json
    from identification.__main__ import main
    out = tmp_path / "compare"
    assert main(["compare", "--sine", str(DATA / "synthetic_table5_sine_2mm_10Hz.csv"), "--step",
                 str(DATA / "synthetic_table5_step_2mm_rise0.4s.csv"), "--rise-time", "0.4", "--models",
                 "single_bouc_wen", "--try-options", "maxwell", "--screening", "32", "--starts", "1",
                 "--no-ensemble", "--quiet", "--workers", "1", "--out", str(out)]) == 0
    method = lambda name: json.loads((out / f"params_{name}.json").read_text())["fit"]["method"]
    assert method("single_bouc_wen").startswith("32 scrambled Sobol points") and "started from" not in method(
        "single_bouc_wen")
    variant = method("single_bouc_wen+maxwell")       # an eighth of the 32 points, from the fit
    assert variant.startswith("4 scrambled Sobol points") and variant.endswith("; started from the single_bouc_wen fit")
