"""compare's race (identification.analysis.race): the rule that stops a model after its screening,
on hand-made fits; one compiled module asked for by two threads at once; and compare through the
command line with a race that stops a model (slow)."""
import csv
import json
import math
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from fmu_src.model.registry import MODELS
from identification.__main__ import main
from identification.analysis import race
from identification.analysis.race import out_of_race
from identification.forward import parameter_jacobian

DATA = Path(__file__).resolve().parents[3] / "data"


@dataclass
class Finished:
    """What the rule reads of a finished fit."""
    model: str
    misfit: float
    at_floor: bool
    free_parameters: int = 14
    residuals: int = 1000
    floor_misfit: float = 1.0

    @property
    def information_criterion(self) -> float:
        return self.residuals * self.misfit + self.free_parameters * math.log(self.residuals)


def test_no_model_is_stopped_before_one_has_finished():
    assert out_of_race(1e9, 6, 1000, [], closing=10.0) is None


def test_a_model_that_could_still_reach_the_floor_runs_on():
    # 15.6 / 10 = 1.56 <= 1.25^2 = 1.5625: its later stages might still reach the floor
    assert out_of_race(15.6, 6, 1000, [Finished("leader", 1.0, True)], closing=10.0) is None


def test_a_model_that_cannot_reach_the_floor_a_finished_model_reached_is_stopped_and_told_why():
    reason = out_of_race(15.7, 6, 1000, [Finished("leader", 1.0, True)], closing=10.0)
    assert reason is not None and "leader" in reason and "15.7" in reason and "10x" in reason


def test_where_the_device_repeats_less_than_its_noise_the_floor_is_its_repeatability():
    # a sine whose cycles differ by 10x its noise level: a fit at that floor has chi^2/n up to 100
    # (in noise units), so a model whose later stages could reach 150 may still reach it, one at 160 not
    leader = Finished("leader", 90.0, True, floor_misfit=100.0)
    assert out_of_race(1500.0, 6, 1000, [leader], closing=10.0) is None
    reason = out_of_race(1600.0, 6, 1000, [leader], closing=10.0)
    assert reason is not None and "156" in reason and "leader" in reason


def test_without_a_model_at_the_floor_the_bic_decides():
    # the leader misses the floor (chi^2/n 40); a 6-parameter model whose later stages could reach
    # 30 (first stage 300, closing 10) might still have the lower BIC: 1000*30 + 6 ln 1000 < 1000*40 + ...
    leader = Finished("leader", 40.0, False)
    assert out_of_race(300.0, 6, 1000, [leader], closing=10.0) is None
    # at best 41 > 40: its BIC stays above the leader's, whatever its parameters
    reason = out_of_race(410.0, 2, 1000, [leader], closing=10.0)
    assert reason is not None and "BIC" in reason and "leader" in reason
    # near the tie the parameter count decides: 1000*40.001 + 2 ln 1000 < 1000*40 + 14 ln 1000
    assert out_of_race(400.01, 2, 1000, [leader], closing=10.0) is None


def test_the_default_closing_is_the_measured_constant(monkeypatch):
    monkeypatch.setattr(race, "RACE_CLOSING", 10.0)
    assert out_of_race(15.7, 6, 1000, [Finished("leader", 1.0, True)]) is not None
    monkeypatch.setattr(race, "RACE_CLOSING", 11.0)
    assert out_of_race(15.7, 6, 1000, [Finished("leader", 1.0, True)]) is None


def test_before_its_last_stage_a_model_is_weighed_with_the_last_stages_factor():
    leader = Finished("leader", 1.0, True)
    # 8 / 2 = 4 > 1.25^2: the last stage cannot bring it to the floor the leader reached
    reason = out_of_race(8.0, 6, 1000, [leader], closing=2.0, reached=race.BEFORE_LAST_STAGE)
    assert reason is not None and "before its last stage" in reason and "2x" in reason
    assert out_of_race(3.0, 6, 1000, [leader], closing=2.0, reached=race.BEFORE_LAST_STAGE) is None


class StandInSearch:
    """What race_models asks of a search, with the misfits each step reaches given."""
    jacobian_kind = "none"      # nothing for the module pipeline to compile
    problem = None
    d, n = 6, 1000

    def __init__(self, name, screened, first, before_last, final):
        self.request = type("Request", (), {"model": type("Model", (), {"title": name, "name": name})()})()
        self.name, self.misfits, self.seconds, self.steps = name, (screened, first, before_last, final), 0.0, []

    def prepare(self):
        pass

    def screen(self, compile_beside=True, since=None):
        self.steps.append("screen")
        return self.misfits[0]

    @property
    def screened_misfit(self):
        return self.misfits[0]

    def first_stage(self):
        self.steps.append("first stage")
        return self.misfits[1]

    @property
    def first_stage_misfit(self):
        return self.misfits[1]

    def early_stages(self):
        self.steps.append("early stages")
        return self.misfits[2]

    def finish(self, ensemble=None):
        self.steps.append("last stage")
        result = Finished(self.name, self.misfits[3], self.misfits[3] <= 1.25 ** 2)
        result.converged, result.seconds = True, 0.0
        return result


@pytest.mark.parametrize("race_on", [True, False])
def test_a_model_far_from_the_leader_after_its_middle_stage_skips_its_last(monkeypatch, race_on):
    # the leader reaches the floor; the other's first stage (9) could still come down to it
    # (9 / 10 < 1.5625), its middle stage (8) cannot with the last stage's factor (8 / 2 > 1.5625)
    searches = {"leader": StandInSearch("leader", 2.0, 1.2, 1.1, 1.0),
                "other": StandInSearch("other", 12.0, 9.0, 8.0, 7.5)}
    monkeypatch.setattr(race, "begin", lambda request, *rest: searches[request.model.name])
    monkeypatch.setattr(race, "RACE_CLOSING", 10.0)
    monkeypatch.setattr(race, "RACE_CLOSING_LAST", 2.0)
    requests = [type("Request", (), {"model": type("Model", (), {"name": name, "linear": None})()})()
                for name in ("other", "leader")]
    settled = []
    results, stopped, _ = race.race_models(requests, engine=None, race=race_on, progress=False,
                                           on_settled=lambda r, s: settled.append((sorted(r), len(s))))
    # without the race the stages run through (finish runs the early ones itself)
    assert searches["leader"].steps == (["screen", "first stage", "early stages", "last stage"] if race_on
                                        else ["screen", "first stage", "last stage"])
    if race_on:
        assert sorted(results) == ["leader"] and [s.model for s in stopped] == ["other"]
        assert searches["other"].steps == ["screen", "first stage", "early stages"]
        assert stopped[0].when == "before its last stage" and stopped[0].before_last_misfit == 8.0
        assert settled == [(["leader"], 0), (["leader"], 1)]
    else:
        assert sorted(results) == ["leader", "other"] and not stopped
        assert searches["other"].steps[-1] == "last stage"


def test_two_threads_asking_for_one_sensitivity_module_compile_it_once(monkeypatch):
    made = []

    class Module:
        __name__ = "bushing_jacobian_stand_in"      # its compile lock's name

        @staticmethod
        def _simulate_sensitivities(*arguments):
            time.sleep(0.3)         # a compile that takes a while: the second thread arrives during it

    def generated(bushing, lanes):
        made.append((bushing.name, lanes))
        return Module()

    monkeypatch.setattr(parameter_jacobian, "_compiled", {})
    monkeypatch.setattr(parameter_jacobian, "_generated_module", generated)
    got = []
    threads = [threading.Thread(target=lambda: got.append(parameter_jacobian.sensitivity_module(MODELS["proposed"], 14)))
               for _ in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert made == [("proposed", 14)] and len(got) == 2 and got[0] is got[1]


@pytest.mark.slow
def test_compare_stops_a_model_that_cannot_win_and_samples_the_recommended_models_ensemble_only(tmp_path, capsys,
                                                                                                 monkeypatch):
    # a closing factor of 2 (the measured one is larger): single Bouc-Wen, whose best fit of the
    # Table 5 data misses them by 9x their noise (chi^2/n about 48), cannot reach the floor the
    # proposed model reaches; Kelvin-Voigt is linear and always finished
    monkeypatch.setattr(race, "RACE_CLOSING", 2.0)
    out = tmp_path / "cmp"
    code = main(["compare", "--models", "proposed,single_bouc_wen,kelvin_voigt", "--sine",
                 str(DATA / "synthetic_table5_sine_2mm_10Hz.csv"), "--step",
                 str(DATA / "synthetic_table5_step_2mm_rise0.4s.csv"), "--rise-time", "0.4", "--screening", "512",
                 "--starts", "16", "--quiet", "--out", str(out)])
    assert code == 0
    printed = capsys.readouterr().out
    assert printed.strip().splitlines()[-1] == "recommended: proposed"
    assert "single_bouc_wen" in printed and "stopped after its screening" in printed
    with open(out / "comparison.csv") as handle:
        rows = {row["model"]: row for row in csv.DictReader(handle)}
    assert rows["single_bouc_wen"]["stopped_after_screening"].startswith("chi^2/n")
    assert float(rows["single_bouc_wen"]["first_stage_misfit_chi2_per_residual"]) > 2 * 1.25 ** 2
    assert rows["proposed"]["stopped_after_screening"] == "" and rows["proposed"]["recommended"] == "True"
    # the misfits on the way: the screening's best, after the first stage, at the end (read when
    # each step ended, not from the records the later stages went on with)
    misfits = [float(rows["proposed"][f"{column}_chi2_per_residual"]) for column in ("screened_misfit",
                                                                                     "first_stage_misfit", "misfit")]
    assert misfits[0] > misfits[1] > misfits[2]
    assert not (out / "params_single_bouc_wen.json").exists()
    assert np.isfinite(float(rows["kelvin_voigt"]["misfit_chi2_per_residual"]))
    fit = {model: json.loads((out / f"params_{model}.json").read_text())["fit"]
           for model in ("proposed", "kelvin_voigt")}
    assert fit["proposed"]["ensemble_sampled"] is True and fit["proposed"]["ensemble_members"] > 1


def test_a_compile_notice_shows_after_its_delay_unless_the_command_stops_first(capsys):
    # the notice of a long compile (search.JacobianCompile) must not print after the one line of
    # a command stopped by a signal, while the interpreter shuts down
    from identification.fitting.progress import close_open_bars, notice_later
    shown = notice_later(0.05, lambda: "compiling, about 30 s")
    stopped = notice_later(0.3, lambda: "too late")
    shown.start()
    stopped.start()
    time.sleep(0.15)
    close_open_bars()
    time.sleep(0.3)
    assert capsys.readouterr().err == "compiling, about 30 s\n"
