"""Training tests from the command line and from a tests.json manifest."""
import json
import re
import time

import pytest

from conftest import DATA
from fmu_src.parameter_files import load_parameters
from identification.cli.arguments import main
from identification.measured.measurements import MeasurementError
from identification.measured.rig_tests import ManifestError, load_manifest, training_tests

SINE = DATA / "synthetic_table5_sine_2mm_10Hz.csv"
STEP = DATA / "synthetic_table5_step_2mm_rise0.4s.csv"
RANDOM = DATA / "synthetic_table5_random_2mm.csv"


def test_steps_pair_with_their_rise_times_in_order():
    tests = training_tests([SINE], [STEP, STEP], [0.4, 0.2], [RANDOM])
    assert [(t.kind, t.rise_time_s) for t in tests] == [("sine", None), ("step", 0.4), ("step", 0.2),
                                                        ("random", None)]


@pytest.mark.parametrize("steps, rises, fragment", [
    ([STEP], [], "1 step test(s) but 0 rise time(s)"),
    ([STEP], [12.0], "rise time 12 s must be > 0 s and shorter than the test (10 s)"),
    ([STEP], [0.0], "rise time 0 s must be > 0 s"),
    ([], [], "no training tests"),
])
def test_bad_step_tests_are_refused(steps, rises, fragment):
    with pytest.raises(ManifestError, match=re.escape(fragment)):
        training_tests([], steps, rises)


def test_a_manifest_names_files_relative_to_itself(tmp_path):
    manifest = tmp_path / "tests.json"
    manifest.write_text(json.dumps({"sine": [str(SINE)], "step": [{"file": str(STEP), "rise_time_s": 0.4}],
                                    "random": [str(RANDOM)], "model": "spencer"}))
    loaded = load_manifest(manifest)
    assert [t.kind for t in loaded.tests] == ["sine", "step", "random"] and loaded.model == "spencer"
    (tmp_path / "local.csv").write_text(SINE.read_text())
    manifest.write_text(json.dumps({"sine": ["local.csv"]}))
    assert load_manifest(manifest).tests[0].measurement.source == str(tmp_path / "local.csv")


@pytest.mark.parametrize("document, fragment", [
    ('{"sine": ["a.csv"]', "not valid JSON"),
    ('{"sines": ["a.csv"]}', "unknown keys ['sines']"),
    ('{"step": ["b.csv"]}', 'each step must be {"file": ..., "rise_time_s": ...}'),
    ('{"sine": "a.csv"}', "'sine' must be a list"),
    ('{"sine": ["missing.csv"]}', "missing.csv does not exist"),
    ('{"step": [{"file": "%s", "rise_time_s": "fast"}]}' % STEP, "rise time 'fast' must be a number"),
])
def test_bad_manifests_name_the_problem(tmp_path, document, fragment):
    manifest = tmp_path / "tests.json"
    manifest.write_text(document)
    with pytest.raises(MeasurementError, match=re.escape(fragment)):
        load_manifest(manifest)


@pytest.mark.parametrize("arguments, fragment", [
    (["--sine", str(SINE), "--tests", "x.json"], "either in --tests MANIFEST or as --sine"),
    (["--sine", str(SINE), "--out", "/nonexistent/dir/p.json"], "--out /nonexistent/dir/p.json: the directory"),
    (["--sine", str(SINE), "--ensemble", "{tmp}/folder.json"], "is a directory, expected a file"),
    (["--sine", str(SINE), "--ensemble", "{tmp}/e.ssv"], "--ensemble {tmp}/e.ssv: give a file name ending in .json"),
    (["--sine", str(SINE), "--out", "{tmp}/p.ssv"], "ending in .json"),
])
def test_cli_refuses_bad_options_before_any_work(tmp_path, capsys, arguments, fragment):
    (tmp_path / "folder.json").mkdir()
    arguments = [a.replace("{tmp}", str(tmp_path)) for a in arguments]
    fragment = fragment.replace("{tmp}", str(tmp_path))
    arguments = arguments if "--out" in arguments else arguments + ["--out", str(tmp_path / "p.json")]
    assert main(["fit", *arguments]) == 2
    assert fragment in capsys.readouterr().err


@pytest.mark.parametrize("option, value", [("--starts", "0"), ("--screening", "-5"), ("--rise-time", "-0.4"),
                                           ("--workers", "0")])
def test_numeric_options_out_of_range_are_refused(tmp_path, capsys, option, value):
    with pytest.raises(SystemExit) as exit_info:
        main(["fit", "--sine", str(SINE), option, value, "--out", str(tmp_path / "p.json")])
    assert exit_info.value.code == 2
    assert f"argument {option}" in capsys.readouterr().err


@pytest.mark.parametrize("command, fragment", [
    (["sensitivity", "--params", str(DATA / "params_table5_combined.json"), "--csv", "/nonexistent/dir/s.csv"],
     "--csv /nonexistent/dir/s.csv: the directory"),
    (["report", "--params", str(DATA / "params_table5_combined.json"), "--data", str(SINE),
      "--plots", "/nonexistent/dir/plots"], "--plots /nonexistent/dir/plots: the directory"),
    (["predict", "--params", str(DATA / "params_table5_combined.json"), "--data", str(SINE),
      "--out", "/nonexistent/dir/p.csv"], "--out /nonexistent/dir/p.csv: the directory"),
    (["compare", "--sine", str(SINE), "--out", "/nonexistent/dir/cmp"], "--out /nonexistent/dir/cmp: the directory"),
    (["fit-many", str(DATA), "--out", "/nonexistent/dir/fleet"], "--out /nonexistent/dir/fleet: the directory"),
])
def test_every_command_checks_its_outputs_before_any_work(capsys, command, fragment):
    started = time.monotonic()
    assert main(command) == 2
    assert fragment in capsys.readouterr().err
    assert time.monotonic() - started < 5      # refused at once, not after the work


def test_sensitivity_delta_must_be_a_fraction(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["sensitivity", "--params", str(DATA / "params_table5_combined.json"), "--delta", "0"])
    assert exit_info.value.code == 2 and "argument --delta" in capsys.readouterr().err


def test_a_fit_whose_files_cannot_be_written_after_all_is_rescued_into_the_working_directory(
        tmp_path, monkeypatch, capsys):
    # The check before the work passes; then the folder disappears during the fit.
    import shutil
    import fmu_src.parameter_files as parameter_files
    out_dir = tmp_path / "results"
    out_dir.mkdir()
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    real_save = parameter_files.save_parameters

    def vanishing_folder(path, *args, **kwargs):
        shutil.rmtree(out_dir, ignore_errors=True)
        return real_save(path, *args, **kwargs)
    monkeypatch.setattr("identification.fitting.result.save_parameters", vanishing_folder)
    assert main(["fit", "--model", "kelvin_voigt", "--sine", str(SINE), "--out", str(out_dir / "p.json"),
                 "--quiet"]) == 0
    rescued, = work.glob("rescued_fit_*.json")
    err = capsys.readouterr().err
    assert "could not write the fit's files" in err and str(rescued) in err
    assert load_parameters(rescued, model="kelvin_voigt")["k"] > 0
