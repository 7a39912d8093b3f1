"""A start whose residuals or Jacobian are not finite is a failed start: skipped, counted, never
raised (multistart, ensemble, fitting), and a starved fit still ends with its parameter file.

The stand-in problems are one or two coordinates with residuals written here, so where they stop
being finite is known in advance; the command-line tests run the real fit on the shipped synthetic
files with a starved budget (``--screening 8 --starts 1``)."""
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from identification.__main__ import main
from identification.fitting.engine import SerialEngine
from identification.fitting.ensemble import ProfileProblem, _profile_task, identifiability
from identification.fitting.multistart import (EXACT_JACOBIAN_LIMIT, StartRecord, _least_squares_task, exact_usable,
                                               failed_starts, jacobian, run_stages)

DATA = Path(__file__).resolve().parents[3] / "data"
TABLE2 = DATA / "synthetic_table2_noise1pct"


@dataclass(frozen=True)
class _Box:
    low: float = -2.0
    high: float = 2.0

    def bounds(self):
        return np.array([[self.low, self.high]])


@dataclass(frozen=True)
class Cliff:
    """Residuals (theta - 1, 0.1): misfit (theta - 1)^2 + 0.01, finite for theta >= ``edge`` and
    infinite below it (a model that blows up in part of its box)."""
    edge: float = -1.0
    space: _Box = _Box()
    jacobian: str = "difference"

    def residuals(self, theta):
        theta = np.atleast_2d(theta)[:, 0]
        out = np.column_stack([theta - 1.0, np.full_like(theta, 0.1)])
        out[theta < self.edge] = np.inf
        return out

    def misfit(self, theta):
        with np.errstate(over="ignore", invalid="ignore"):
            return np.sum(self.residuals(theta) ** 2, axis=1)


def test_a_start_whose_residuals_are_not_finite_fails_without_raising():
    theta, misfit, used, message, failed = _least_squares_task(Cliff(), (np.array([-1.5]), 20))
    assert failed and message.startswith("failed:") and not np.isfinite(misfit) and theta[0] == -1.5


def test_a_start_from_a_finite_point_is_not_failed_by_infinite_trial_points():
    # scipy shrinks its trust region where a trial point's residuals are not finite
    theta, misfit, _, _, failed = _least_squares_task(Cliff(edge=-0.5), (np.array([-0.4]), 50))
    assert not failed and theta[0] == pytest.approx(1.0, abs=1e-6) and misfit == pytest.approx(0.01)


def test_failed_starts_are_counted_kept_at_their_last_finite_point_and_skipped_in_later_stages():
    records = [StartRecord(0, np.array([-1.5]), 5.0, -1, 1), StartRecord(1, np.array([0.0]), 1.01, -1, 1),
               StartRecord(2, np.array([0.5]), 0.26, -1, 1)]
    out = run_stages(Cliff(), SerialEngine(), records, [(3, 10), (3, 30)])
    assert failed_starts(out) == 1
    bad = next(r for r in out if r.start == 0)
    assert bad.failed and bad.stage == -1 and bad.misfit == 5.0 and bad.theta[0] == -1.5   # as it was, not inf
    assert out[-1] is bad                                                       # failed starts sort last
    assert all(r.stage == 1 and not r.failed and r.theta[0] == pytest.approx(1.0, abs=1e-6) for r in out[:2])


class Exact(Cliff):
    """Exact Jacobian of the cliff's residuals, but with an entry of ``blow`` (a diverging
    sensitivity) at theta > 0.5."""
    def __init__(self, blow):
        object.__setattr__(self, "blow", blow)

    jacobian = "exact"

    def residuals_and_jacobian(self, theta):
        derivative = np.array([[1.0], [0.0]])
        if theta[0] > 0.5:
            derivative[1, 0] = self.blow
        return self.residuals(theta[None, :])[0], derivative


@pytest.mark.parametrize("blow", [2e303, np.inf, np.nan])
def test_an_exact_jacobian_that_diverges_is_taken_by_differences_there(blow):
    problem = Exact(blow)
    assert exact_usable(np.array([[1.0], [EXACT_JACOBIAN_LIMIT]])) and not exact_usable(np.array([[blow]]))
    derivative, _ = jacobian(problem, np.array([0.75]))
    np.testing.assert_allclose(derivative, [[1.0], [0.0]], atol=1e-6)             # the secant, not `blow`
    theta, misfit, _, _, failed = _least_squares_task(problem, (np.array([0.6]), 30))
    assert not failed and theta[0] == pytest.approx(1.0, abs=1e-6)


class _Probe:
    """A stand-in probe whose measure is not finite."""
    def __init__(self, *args):
        pass

    def values(self, thetas):
        return np.full(len(np.atleast_2d(thetas)), np.nan)

    def gradient(self, theta):
        return np.nan, np.full(len(theta), np.nan)


@pytest.mark.parametrize("kind", ["difference", "exact"])
def test_a_profile_whose_probe_is_not_finite_fails_without_raising(monkeypatch, kind):
    import identification.fitting.ensemble as ensemble
    monkeypatch.setattr(ensemble, "ProbeMeasure", _Probe)

    class Objective:
        size = 2

    class Problem(Cliff):
        objective = Objective()
    problem = Problem(jacobian=kind)
    ident = identifiability(np.array([[1.0], [0.0]]), ["theta"], 3.84)
    shared = ProfileProblem(problem, np.array([1.0]), 0.01, 2.0, ident)
    kept, failed = _profile_task(shared, (("sine", 4.0, 40.0, 0.25, "rms"), 1.0))
    assert failed and kept is None


def fit_command(tmp_path, *options, seed=8):
    out = tmp_path / "p.json"
    code = main(["fit", "--sine", f"{TABLE2}_sine_2mm_10Hz.csv", "--step", f"{TABLE2}_step_2mm_rise0.4s.csv",
                 "--rise-time", "0.4", "--seed", str(seed), "--screening", "8", "--starts", "1", "--workers", "1",
                 "--quiet", "--out", str(out), *options])
    return code, out


@pytest.mark.slow   # in CI's slow phase: it keeps the README's test command near 5 minutes
def test_the_starved_fit_of_the_issue_ends_with_its_file_and_a_warning(tmp_path, capsys):
    # seed 8 ended in a traceback from the ensemble's profiles (2026-11-26, this machine): its only
    # start died on a sensitivity of 2e303; on any processor, a file and a warning or convergence
    code, out = fit_command(tmp_path)
    err = capsys.readouterr().err
    assert code == 0 and "Traceback" not in err
    provenance = json.loads(out.read_text())["fit"]
    assert provenance["converged"] is False and "WARNING: not converged" in err
    assert isinstance(provenance["failed_starts"], int) and provenance["failed_starts"] >= 0


FUZZ_FILES = {"berg": "synthetic_filled_rubber", "fractional": "synthetic_filled_rubber"}
"""The shipped synthetic tests each model is fuzzed on (the paper's Table 2 tests, 1 % noise, for the others)."""


@pytest.mark.slow
@pytest.mark.parametrize("ensemble", [True, False], ids=["ensemble", "no-ensemble"])
@pytest.mark.parametrize("model", ["proposed", "spencer", "single_bouc_wen", "berg", "fractional", "kelvin_voigt"])
def test_a_starved_fit_of_every_model_and_seed_ends_with_its_file(tmp_path, capsys, model, ensemble):
    # the issue's fuzz matrix: as a user would starve the search; measured 2026-11-26: 0 tracebacks
    # in 120 runs, 11 of them with failed starts (the fits of 20-25 min of one core)
    files = DATA / FUZZ_FILES.get(model, "synthetic_table2_noise1pct")
    for seed in range(10):
        out = tmp_path / f"{model}_{seed}.json"
        code = main(["fit", "--model", model, "--sine", f"{files}_sine_2mm_10Hz.csv", "--step",
                     f"{files}_step_2mm_rise0.4s.csv", "--rise-time", "0.4", "--seed", str(seed), "--screening", "8",
                     "--starts", "1", "--workers", "1", "--quiet", "--out", str(out)]
                    + ([] if ensemble else ["--no-ensemble"]))
        err = capsys.readouterr().err
        assert code == 0 and "Traceback" not in err, (seed, err[-2000:])
        provenance = json.loads(out.read_text())["fit"]
        assert provenance["converged"] or "WARNING: not converged" in err, seed
        assert provenance["converged"] == ("WARNING: not converged" not in err), seed
