"""The fit says how sure it is: convergence evidence, the never-silent warning, the ensemble's
band, the design of the next test, the same bits on every engine, the fleet."""
import json

import numpy as np
import pytest

from conftest import DATA, paper_parameters, paper_test_force
from identification import FitNotConvergedWarning, fit, load_measurement, predict, simulate
from identification.cli.arguments import main
from identification.measured.measurements import Measurement, write_measurement
from identification.measured.signals import Sine, Step, sample_times
from identification.measured.rig_tests import RigTest

SMALL = ["--screening", "64", "--starts", "2", "--quiet"]


def short_tests(params, noise=0.01, seed=0, sine_s=0.3, step_s=1.0):
    """A short sine 2 mm/10 Hz and step 2 mm/0.1 s of the proposed model with ``params``, with
    white force noise; the forces from the paper's equations (conftest.paper_test_force, scipy's
    Radau), not from the model the fit runs."""
    rng = np.random.default_rng(seed)
    tests = []
    for kind, protocol, duration, rise in (("sine", Sine(2.0, 10.0), sine_s, None),
                                          ("step", Step(2.0, 0.1, step_s), step_s, 0.1)):
        t = sample_times(duration, 1000.0)
        x, v = protocol.signals(t)
        force = paper_test_force(params, kind, duration, rise_time_s=0.1)
        assert force.size == t.size
        force = force + rng.normal(0.0, noise * np.sqrt(np.mean(force ** 2)), t.size)
        tests.append(RigTest(Measurement(t, x, force, np.gradient(x, t), True, f"{kind}.csv"), kind, rise))
    return tests


def write_tests(folder, tests):
    """CSV files and a tests.json manifest for ``tests`` in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    manifest = {"sine": [], "step": [], "random": []}
    for test in tests:
        m = test.measurement
        write_measurement(folder / test.name, m.time_s, m.displacement_mm, m.force_N, ["SYNTHETIC (test)"])
        entry = {"file": test.name, "rise_time_s": test.rise_time_s} if test.kind == "step" else test.name
        manifest[test.kind].append(entry)
    (folder / "tests.json").write_text(json.dumps(manifest))
    return folder / "tests.json"


@pytest.mark.slow      # 45 s, a third of the README's command on two cores: run in CI's slow phase
@pytest.mark.optimizer
def test_a_starved_budget_prints_the_warning_and_stores_converged_false(tmp_path, capsys):
    # one start from 8 screened points: one final start cannot agree with another, on any path
    manifest = write_tests(tmp_path / "bushing", short_tests(paper_parameters("table2")))
    out = tmp_path / "starved.json"
    assert main(["fit", "--tests", str(manifest), "--screening", "8", "--starts", "1", "--workers", "1",
                 "--quiet", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    warning = [line for line in err.splitlines() if line.startswith("WARNING: not converged")]
    assert len(warning) == 1 and "1 of 1 final starts" in warning[0]
    provenance = json.loads(out.read_text())["fit"]
    assert provenance["converged"] is False and provenance["starts_agreeing"] == 1
    assert all(0.008 < t["noise_fraction"] < 0.012 for t in provenance["tests"])   # 1 % noise, estimated


@pytest.mark.slow
@pytest.mark.optimizer
def test_a_model_that_cannot_describe_the_data_stays_above_the_floor_and_says_so():
    # The single Bouc-Wen element cannot show the proposed model's relaxation: on every path
    # its fit ends far above the noise floor (measured: NRMSE 6-7x the noise), and the warning
    # leads with the training NRMSE. Its hint follows the starts: where they agree (they did on
    # every path tried), the model is blamed; where not, more starts are asked for.
    with pytest.warns(FitNotConvergedWarning) as record:
        result = fit(short_tests(paper_parameters("table2")), model="single_bouc_wen", seed=0, workers=1,
                     progress=False, screening=256, starts=8)
    assert not result.at_floor and not result.converged
    assert max(t.ratio for t in result.tests) > 3.0
    message = str(record[0].message)
    assert message.startswith("not converged: training NRMSE")
    if result.agreeing >= 2:
        assert "the starts agree" in message and "more starts" not in message
    else:
        assert "more starts" in message and "the starts agree" not in message


def test_agreeing_starts_above_the_floor_blame_the_model_not_the_search():
    # The hint's logic on records made by hand: two of three final starts within the threshold
    # of the best, every test far above its noise level, the best fit inside the box.
    from fmu_src.model.registry import get_model
    from fmu_src.parameter_files import ParameterSet
    from identification.fitting.result import FitResult, RigTestFit
    from identification.fitting.multistart import StartRecord
    from identification.measured.noise import estimate_noise
    from identification.fitting.search_space import SearchSpace
    tests = short_tests(paper_parameters("table5"))
    space = SearchSpace.from_measurements([t.measurement for t in tests], steps=[t.kind == "step" for t in tests])
    best = paper_parameters("table5")
    theta = space.to_coordinates(best)
    records = [StartRecord(0, theta, 20.0, 2, 100), StartRecord(1, theta, 20.005, 2, 100),
               StartRecord(2, theta, 25.0, 2, 100)]
    fits = [RigTestFit(t.name, t.kind, estimate_noise(t.measurement.force_N), 0.05) for t in tests]
    result = FitResult(ParameterSet(get_model("proposed"), best), 20.0, fits, records, 0.01, [best], None,
                       "default", 0, 1, 1.0, space=space, final_starts=3)
    assert result.agreeing == 2 and not result.at_floor and not result.converged and result.at_box_edge() == []
    assert "training NRMSE 5.00%" in result.warning and "the starts agree" in result.warning
    result.records[1].misfit = 20.02        # beyond the threshold: now the search is to blame
    assert result.agreeing == 1 and "more starts" in result.warning and "the starts agree" not in result.warning


@pytest.mark.slow
@pytest.mark.optimizer
@pytest.mark.parametrize("refined", [False, True], ids=["signal_steps", "refined_steps"])
def test_the_same_seed_gives_the_same_file_on_one_worker_two_workers_and_a_dask_cluster(tmp_path, monkeypatch,
                                                                                         refined):
    from dask.distributed import LocalCluster
    import identification.fitting.refinement as refinement
    if refined:
        # no error budget: every check doubles the steps (up to 2), so the last stage runs with
        # an objective other than the screening's (the refinement runs in this process; the
        # refined objective travels to the workers)
        monkeypatch.setattr(refinement, "ERROR_BUDGET", 0.0)
        monkeypatch.setattr(refinement, "MAX_REFINED_STEPS", 2)
    else:
        # the signal's steps on every path: whether the fitted set would ask for finer ones
        # depends on where the search ends
        monkeypatch.setattr(refinement, "MAX_REFINED_STEPS", 1)
    manifest = write_tests(tmp_path / "bushing", short_tests(paper_parameters("table5"), seed=4))
    files = []
    # 16 first-stage starts: more than the 8 chunks of 2 workers, so chunks hold several starts
    budget = ["--screening", "2048", "--starts", "16", "--quiet"]
    def fit_with(engine):
        out = tmp_path / f"fit_{len(files)}.json"
        assert main(["fit", "--tests", str(manifest), "--seed", "7", *budget, *engine, "--out", str(out)]) == 0
        files.append(out.read_bytes())

    fit_with(["--workers", "1"])
    fit_with(["--workers", "2"])
    if not refined:   # the refined objective reaches Dask workers as it reaches local ones: pickled
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
            fit_with(["--scheduler", cluster.scheduler_address])
    assert all(f == files[0] for f in files[1:])
    assert json.loads(files[0])["fit"]["steps_per_sample"][0] == (2 if refined else 1)


@pytest.mark.slow   # in CI's slow phase: it keeps the README's test command near 5 minutes
def test_an_unreachable_scheduler_is_a_clear_error_not_a_hang(tmp_path, capsys):
    import time
    manifest = write_tests(tmp_path / "bushing", short_tests(paper_parameters("table5")))
    started = time.monotonic()
    code = main(["fit", "--tests", str(manifest), *SMALL, "--scheduler", "tcp://127.0.0.1:9",
                 "--out", str(tmp_path / "never.json")])
    assert code == 2 and time.monotonic() - started < 30
    assert "cannot reach the Dask scheduler at 'tcp://127.0.0.1:9'" in capsys.readouterr().err
    assert not (tmp_path / "never.json").exists()


@pytest.fixture(scope="module")
def table2_ensemble(tmp_path_factory):
    """An ensemble file made by hand (Table 2 and two sets beside it) and Table 2's short tests:
    what ``predict`` and ``report`` read (their claims are the files and the printout, no fit's)."""
    from fmu_src.parameter_files import save_ensemble
    folder = tmp_path_factory.mktemp("table2")
    base = paper_parameters("table2")
    members = [base, dict(base, A2=base["A2"] * 1.2), dict(base, k1=base["k1"] * 0.95)]
    save_ensemble(folder / "ensemble.json", members, provenance={"tests": [{"noise_N": 10.0}]})
    return folder, short_tests(base, seed=5, sine_s=0.5, step_s=2.0)


@pytest.mark.slow
@pytest.mark.optimizer
def test_the_ensemble_band_holds_the_truth_where_the_best_fit_misses():
    # Inputs the fit never saw, beyond the training amplitude: the best fit misses the
    # noise-free truth by more than 1 % NRMSE there, so the best alone (the band of one set)
    # leaves the truth outside; the ensemble's band widened by the noise level holds it.
    # The default budget, as the reliability benchmark measures the band: with 512 screened
    # points and 16 starts, 2 of 6 seeds agreed on a basin at chi^2/n 1.43 (the truth scores
    # 1.18), said converged, and the band held the truth on only 36-56 % of the samples.
    # Measured at the default budget, seeds 1-4: NRMSE 1.5-2.3 %, alone 27-59 %, inside 100 %.
    from identification.fitting.objectives import nrmse
    tests = short_tests(paper_parameters("table2"), seed=5, sine_s=0.5, step_s=2.0)
    result = fit(tests, seed=1, progress=False, workers=2)
    assert result.converged and len(result.ensemble) > 10
    sigma = max(t.noise.sigma_N for t in result.tests)
    for protocol in (Sine(3.0, 10.0, 0.5), Sine(3.0, 20.0, 0.5)):
        t = sample_times(0.5, 1000.0)
        x, v = protocol.signals(t)
        prediction = predict(result, t, x, v)
        truth = simulate(paper_parameters("table2"), t, x, v)
        assert nrmse(prediction.force_N, truth) > 0.01, protocol
        alone = np.abs(truth - prediction.force_N) <= sigma
        inside = (truth >= prediction.lower_N - sigma) & (truth <= prediction.upper_N + sigma)
        assert np.mean(alone) < 0.9 and np.mean(inside) >= 0.95, (protocol, np.mean(alone), np.mean(inside))


def test_predict_writes_the_force_and_the_band(table2_ensemble, tmp_path, capsys):
    folder, _ = table2_ensemble
    t = sample_times(0.3, 1000.0)
    x, _ = Sine(1.0, 20.0).signals(t)
    data = tmp_path / "input.csv"
    data.write_text("time_s,displacement_mm\n" + "".join(f"{a:.6f},{b:.6f}\n" for a, b in zip(t, x)))
    out = tmp_path / "pred.csv"
    assert main(["predict", "--params", str(folder / "ensemble.json"), "--data", str(data), "--out", str(out),
                 "--plot", str(tmp_path / "pred.png")]) == 0
    table = np.genfromtxt(out, delimiter=",", names=True, skip_header=1)   # after the "# predicted by" line
    assert table.dtype.names == ("time_s", "displacement_mm", "force_N", "force_min_N", "force_max_N")
    assert np.all(table["force_min_N"] <= table["force_N"]) and np.any(table["force_max_N"] > table["force_min_N"])
    assert (tmp_path / "pred.png").stat().st_size > 10_000
    assert "band width" in capsys.readouterr().out


def test_report_prints_the_band_width_per_case(table2_ensemble, capsys):
    folder, tests = table2_ensemble
    data = folder / "sine.csv"
    m = tests[0].measurement
    write_measurement(data, m.time_s, m.displacement_mm, m.force_N)
    assert main(["report", "--params", str(folder / "ensemble.json"), "--data", str(data)]) == 0
    out = capsys.readouterr().out
    assert "band mean" in out and "sine.csv" in out


def test_design_ranks_an_informative_test_above_an_uninformative_one(capsys, tmp_path):
    from fmu_src.parameter_files import save_ensemble
    from identification.analysis.design import Candidate, design
    # Two sets that differ only in the gain of the right block: a large, fast sine sees it,
    # a small slow one hardly.
    base = paper_parameters("table5")
    members = [base, dict(base, A2=base["A2"] * 1.5)]
    small, large = Candidate("sine", 0.5, frequency_hz=1.0), Candidate("sine", 3.0, frequency_hz=30.0)
    result = design(members, noise_N=10.0, candidates=[small, large])
    assert [r.candidate for r in result.ranked] == [large, small]
    assert result.ranked[0].spread_N > 10 * result.ranked[1].spread_N
    path = save_ensemble(tmp_path / "two.json", members, provenance={"tests": [{"noise_N": 10.0}]})
    assert main(["design", "--ensemble", str(path), "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    best = answer["recommended"][0]
    assert best["kind"] in ("sine", "step") and best["spread"] == answer["largest_spread_N"] > 10.0
    assert set(best) >= {"kind", "amplitude_mm", "spread"}


def test_design_of_a_file_takes_the_noise_its_fit_recorded(tmp_path):
    """design accepts what predict does, a file's path too; from a path it reads the file once and
    takes the noise level its provenance records (it refused before, finding no record)."""
    from fmu_src.parameter_files import save_ensemble
    from identification.analysis.design import Candidate, design
    base = paper_parameters("table5")
    members = [base, dict(base, A2=base["A2"] * 1.5)]
    path = save_ensemble(tmp_path / "two.json", members, provenance={"tests": [{"noise_N": 7.5}, {"noise_N": 12.5}]})
    result = design(path, candidates=[Candidate("sine", 3.0, frequency_hz=30.0)])
    assert result.noise_N == 12.5 and result.members == 2


def test_design_says_no_further_test_is_needed_when_the_members_agree(tmp_path, capsys):
    from fmu_src.parameter_files import save_ensemble
    base = paper_parameters("table5")
    members = [base, dict(base, k2=base["k2"] * (1 + 1e-6))]
    path = save_ensemble(tmp_path / "agree.json", members, provenance={"tests": [{"noise_N": 10.0}]})
    assert main(["design", "--ensemble", str(path), "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert answer["recommended"] == [] and 0 < answer["largest_spread_N"] < 10.0


@pytest.mark.slow
def test_fit_many_fits_each_bushing_and_reports_a_broken_one(tmp_path, capsys):
    import csv
    fleet = tmp_path / "fleet"
    write_tests(fleet / "front_left", short_tests(paper_parameters("table5"), seed=1))
    write_tests(fleet / "rear_right", short_tests(paper_parameters("table2"), seed=2))
    broken = fleet / "broken"
    broken.mkdir()
    (broken / "tests.json").write_text('{"sine": ["missing.csv"]}')
    # the single fit first: it compiles the model here, and the fleet's two workers load it from
    # the disk cache instead of compiling it twice at once (with an empty cache)
    single = tmp_path / "single.json"
    assert main(["fit", "--tests", str(fleet / "front_left" / "tests.json"), *SMALL, "--workers", "1",
                 "--no-ensemble", "--out", str(single)]) == 0
    out = tmp_path / "out"
    assert main(["fit-many", str(fleet), "--out", str(out), "--workers", "2", "--no-ensemble", *SMALL]) == 0
    rows = {row["name"]: row for row in csv.DictReader(open(out / "summary.csv"))}
    assert set(rows) == {"broken", "front_left", "rear_right"}
    assert "missing.csv" in rows["broken"]["error"] and rows["front_left"]["error"] == ""
    assert float(rows["front_left"]["misfit"]) > 0 and "nrmse_sine.csv" in rows["front_left"]
    assert sorted(p.name for p in out.glob("*.json")) == ["front_left.json", "rear_right.json"]
    # the fleet's file for a bushing is the file a single fit with the same seed writes
    assert json.loads((out / "front_left.json").read_text()) == json.loads(single.read_text())


def test_the_front_door_simulates_every_model(tmp_path):
    from fmu_src.model.registry import MODELS
    from fmu_src.parameter_files import read_parameter_set
    t = sample_times(0.2, 1000.0)
    x, v = Sine(1.0, 10.0).signals(t)
    for name, model in MODELS.items():
        forces = simulate(read_parameter_set(DATA / model.default_file), t, x, v)
        assert forces.shape == t.shape and np.all(np.isfinite(forces)), name
    assert load_measurement(DATA / "synthetic_table5_sine_2mm_10Hz.csv").time_s.size == 1001


def test_a_fit_stuck_on_the_box_says_where():
    # A truth outside the box (block 2's shape coordinates beyond their bounds, as for a
    # bushing with n2 = 1.14): the best fit that the box allows sits on its bound, and the
    # warning names the coordinate instead of blaming the model.
    from fmu_src.model.registry import get_model
    from fmu_src.models.proposed_model import PARAMETER_NAMES
    from fmu_src.parameter_files import ParameterSet
    from identification.fitting.result import FitResult, RigTestFit
    from identification.measured.noise import estimate_noise
    from identification.fitting.search_space import SearchSpace
    tests = short_tests(paper_parameters("table5"))
    space = SearchSpace.from_measurements([t.measurement for t in tests], steps=[t.kind == "step" for t in tests])
    theta = space.to_coordinates(paper_parameters("table5"))
    names = [c.parameter for c in space.coordinates]
    theta[names.index("gamma2")] = space.bounds()[names.index("gamma2"), 1]      # on the upper bound
    params = dict(zip(PARAMETER_NAMES, map(float, space.to_parameters(theta)[0])))
    fits = [RigTestFit(t.name, t.kind, estimate_noise(t.measurement.force_N), 0.05) for t in tests]
    result = FitResult(ParameterSet(get_model("proposed"), params), 20.0, fits, [], 0.01, [params], None,
                       "default", 0, 1, 1.0, space=space, final_starts=6)
    assert result.at_box_edge() == ["gamma2"]
    assert "lies on the search box's bound in gamma2" in result.warning
