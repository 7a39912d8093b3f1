"""Fit a model's parameters to training tests, and say how sure the fit is.

``fit(tests, model="proposed", preset="default", seed=0, workers=None, scheduler=None)``:

1. the noise level of every test from its own data (``identification.noise``);
2. the search (``identification.multistart``): screened Sobol starts, then successive
   halving of bounded trust-region least squares on the misfit (``identification.objectives``),
   every start a task of the engine (``identification.engine``: this process, local worker
   processes, or a Dask cluster; the same seed gives the same bits on each);
3. the evidence (pyPESTO's multi-start practice): how many of the last stage's starts reach
   the best misfit within the ensemble threshold, and whether every training test is at its
   noise floor (NRMSE <= FLOOR_FACTOR x its noise level). A fit that is not both is
   ``converged = False`` and says why (``FitResult.warning``);
4. how sure (``identification.ensemble``): the singular values of the residual Jacobian and
   the ensemble: distinct start end points and posterior draws (emcee) pushed to the edge of
   the 95 % confidence region.

The ``paper`` preset replaces the Sobol screening by the paper's genetic algorithm (pymoo:
population 300, 200 generations, uniform crossover 0.8, mutation probability 0.05 per
coordinate) and keeps the rest. Kelvin-Voigt is fitted by linear least squares (the
optimum is exact, so only the floor is checked).
"""
from __future__ import annotations

import sys
import time
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Sequence

import numpy as np

from fmu_src.bushing_models import get_model
from fmu_src.parameter_files import ParameterSet, save_ensemble, save_parameters
from identification.compiled_core import parameter_matrix
from identification.engine import make_engine
from identification.errors import IdentificationError
from identification.ensemble import (PROBES, PROFILE_EVALUATIONS, PROFILE_ROUNDS, PUSH, STEPS, WALKERS,
                                     Identifiability, SamplerReport, identifiability, misfit_threshold,
                                     posterior_samples, profile_extremes, push_to_boundary, select_members,
                                     threshold_scale)
from identification.kdyn_table import FIT_CYCLES, KDYN_UNCERTAINTY, LOSS_ANGLE_UNCERTAINTY_DEG, KdynTable, load_kdyn_table
from identification.measurements import Measurement
from identification.multistart import (Problem, SearchSettings, StartRecord, first_records, jacobian, run_stages,
                                       screen)
from identification.noise import NoiseEstimate, estimate_noise
from identification.objectives import MIN_NOISE_FRACTION, Objective, nrmse
from identification.refinement import refine_steps
from identification.rig_tests import Manifest, RigTest
from identification.search_space import KelvinVoigtFit, SearchSpace
from identification.simulate import simulate

PRESETS = {
    "default": SearchSettings(screening=8192, stages=((128, 10), (24, 30), (6, 300))),
    # the paper's GA as the global stage (its final population ranks the starts)
    "paper": SearchSettings(screening=300, stages=((128, 10), (24, 30), (6, 300))),
}
PAPER_GA = {"population": 300, "generations": 200, "crossover_probability": 0.8, "mutation_probability": 0.05}
FLOOR_FACTOR = 1.25
"""A test is at its noise floor when the fit's NRMSE on it is at most this times its noise level."""
MIN_AGREEING = 2
MIN_FINAL_STARTS = 3
"""A reduced budget (``starts``) keeps at least this many starts to the end: with two, one
stray start already makes the agreement fail."""


class FitNotConvergedWarning(UserWarning):
    """A fit that ended above the noise floor or whose starts do not agree."""


@dataclass
class TestFit:
    """One training test at the fitted parameters."""
    name: str
    kind: str
    noise: NoiseEstimate
    nrmse: float

    @property
    def noise_fraction(self) -> float:
        """The noise level the fit works with: the estimate, at least MIN_NOISE_FRACTION of
        the rms force (what the objective divides by)."""
        return max(self.noise.relative, MIN_NOISE_FRACTION)

    @property
    def ratio(self) -> float:
        return self.nrmse / self.noise_fraction

    @property
    def at_floor(self) -> bool:
        return bool(self.ratio <= FLOOR_FACTOR)

    def as_dict(self) -> dict:
        return {"file": self.name, "kind": self.kind, "noise_N": _round(self.noise_fraction * self.noise.rms_force_N),
                "noise_fraction": _round(self.noise_fraction), "nrmse": _round(self.nrmse),
                "nrmse_over_noise": _round(self.ratio), "at_floor": self.at_floor}


@dataclass
class TableFit:
    """A dynamic-stiffness table at the fitted parameters: the converged characterisation
    (``dynamic_stiffness.characterise``) against the table's rows of weight > 0."""
    name: str
    kdyn_errors: np.ndarray          # relative |K*| error per row
    angle_errors_deg: np.ndarray     # loss-angle error per row [deg]
    weight: np.ndarray
    cycles_error: float              # largest |K*| difference of the fit's fixed-cycle loop from its steady state

    @property
    def ratio(self) -> float:
        """The rms of the weighted errors in uncertainty units (KDYN_UNCERTAINTY,
        LOSS_ANGLE_UNCERTAINTY_DEG): 1 where the fit matches the table to its uncertainty."""
        scaled = np.concatenate([self.kdyn_errors / KDYN_UNCERTAINTY, self.angle_errors_deg / LOSS_ANGLE_UNCERTAINTY_DEG])
        return float(np.sqrt(np.mean((np.tile(self.weight, 2) * scaled) ** 2)))

    @property
    def at_floor(self) -> bool:
        return bool(self.ratio <= FLOOR_FACTOR)

    def as_dict(self) -> dict:
        return {"file": self.name, "kind": "kdyn", "rows": int(self.weight.size),
                "rms_kdyn_error": _round(float(np.sqrt(np.mean(self.kdyn_errors ** 2)))),
                "largest_kdyn_error": _round(float(np.max(np.abs(self.kdyn_errors)))),
                "rms_loss_angle_error_deg": _round(float(np.sqrt(np.mean(self.angle_errors_deg ** 2)))),
                "largest_loss_angle_error_deg": _round(float(np.max(np.abs(self.angle_errors_deg)))),
                "uncertainty": {"kdyn": KDYN_UNCERTAINTY, "loss_angle_deg": LOSS_ANGLE_UNCERTAINTY_DEG},
                "fit_loop_kdyn_difference": _round(self.cycles_error),
                "error_over_uncertainty": _round(self.ratio), "at_floor": self.at_floor}

    def format(self) -> str:
        d = self.as_dict()
        return (f"{self.name:44s} {'kdyn':7s} |K*| rms {d['rms_kdyn_error']:.2%} (largest {d['largest_kdyn_error']:.2%}), "
                f"loss angle rms {d['rms_loss_angle_error_deg']:.2f} deg (largest {d['largest_loss_angle_error_deg']:.2f}); "
                f"{self.ratio:.2f}x the uncertainty ({KDYN_UNCERTAINTY:.0%}, {LOSS_ANGLE_UNCERTAINTY_DEG:g} deg)  "
                f"{'yes' if self.at_floor else 'NO'}")


@dataclass
class FitResult:
    parameters: ParameterSet               # the best fit, with its provenance
    misfit: float                          # chi^2/n, 1 at the noise floor
    tests: list[TestFit]
    records: list[StartRecord]             # every start, the last stage's first, by misfit
    threshold: float                       # misfit increase within the 95 % confidence region
    ensemble: list[dict[str, float]]       # the best first
    identifiability: Identifiability | None
    preset: str
    seed: int
    evaluations: int
    seconds: float
    engine: str = "1 process"
    space: SearchSpace | None = None
    final_starts: int = 1
    sampler: SamplerReport | None = None
    notes: list[str] = field(default_factory=list)
    steps_per_sample: list[int] = field(default_factory=list)   # the forward model's, per test
    table: TableFit | None = None          # the dynamic-stiffness table, if one was fitted
    added_starts: int = 0                  # starts that ran the last stage because one alone reached the best
    agreed_before_added: int | None = None  # the agreement count when the last stage ended, before any added start
    ensemble_sampled: bool = True          # False: fit(ensemble=False), the ensemble is the best fit alone

    @property
    def model(self) -> str:
        return self.parameters.model.name

    @property
    def agreeing(self) -> int:
        """Starts of the last stage whose misfit is within the threshold of the best."""
        return _agreeing(self.records, self.records[0].stage, self.misfit, self.threshold) if self.records else 1

    @property
    def at_floor(self) -> bool:
        return all(t.at_floor for t in self.tests) and (self.table is None or self.table.at_floor)

    @property
    def converged(self) -> bool:
        enough = self.agreeing >= MIN_AGREEING or self.space is None   # Kelvin-Voigt: exact optimum
        return self.at_floor and enough

    @property
    def warning(self) -> str | None:
        """The ``not converged`` message with its figures, or None."""
        if self.converged:
            return None
        reasons = []
        worst = max(self.tests, key=lambda t: t.ratio) if self.tests else None
        if worst is not None and not worst.at_floor:
            reasons.append(f"training NRMSE {worst.nrmse:.2%} on {worst.name} is {worst.ratio:.2f}x "
                           f"its noise level {worst.noise_fraction:.2%} (the floor is {FLOOR_FACTOR}x)")
        if self.table is not None and not self.table.at_floor:
            reasons.append(f"the table {self.table.name} is matched to {self.table.ratio:.2f}x its uncertainty "
                           f"({KDYN_UNCERTAINTY:.0%} on |K*|, {LOSS_ANGLE_UNCERTAINTY_DEG:g} deg; the floor is "
                           f"{FLOOR_FACTOR}x)")
        if self.space is not None and self.agreeing < MIN_AGREEING:
            reasons.append(f"only {self.agreeing} of {self.final_starts} final starts reach the best misfit")
        edges = self.at_box_edge()
        if edges:
            hint = (f"the best fit lies on the search box's bound in {', '.join(edges)}: the parameters that "
                    "describe these data may lie outside the box (see identification/search_space.py)")
        elif self.space is not None and self.agreeing < MIN_AGREEING:
            hint = "more starts (--starts, --screening) may find a better optimum"
        else:
            hint = ("the starts agree, so the model may not describe these data to their noise level "
                    "(or the noise estimate is low: correlated noise reads low)")
        return f"not converged: {'; '.join(reasons)}; {hint}"

    def at_box_edge(self, tolerance: float = 1e-3) -> list[str]:
        """The searched coordinates of the best fit within ``tolerance`` of the box's size from
        an upper bound, or from a lower bound that is a limit of the search (the time constants'
        floor, n >= 0.1). Other lower bounds stand for a physical limit a fit may rightly sit on:
        no spring or dashpot (1e-3 k_ref, 1e-4 c_ref), A >= 1, beta >= 0 and the shape sums >= 0."""
        if self.space is None:
            return []
        theta = self.space.to_coordinates(self.parameters.parameters)
        edges = []
        for c, value, (low, high) in zip(self.space.coordinates, theta, self.space.bounds()):
            margin = tolerance * (high - low)
            if value >= high - margin or (value <= low + margin and c.kind in ("time_constant", "exponent")):
                edges.append(c.parameter)
        return edges

    def provenance(self) -> dict:
        """What the parameter file records of the fit: everything but timings and engine, so
        that the same seed gives the same file on any engine."""
        out = {"method": self._method(), "preset": self.preset, "seed": self.seed,
               "converged": self.converged, "misfit_chi2_per_residual": _round(self.misfit),
               "tests": [t.as_dict() for t in self.tests] + ([self.table.as_dict()] if self.table else [])}
        if self.space is not None:
            out.update({"starts_agreeing": self.agreeing, "final_starts": self.final_starts,
                        "starts_added_for_agreement": self.added_starts,
                        "starts_agreeing_before_added": self.agreed_before_added,
                        "agreement_threshold_misfit": _round(self.threshold),
                        "ensemble_members": len(self.ensemble), "ensemble_sampled": self.ensemble_sampled,
                        "steps_per_sample": list(self.steps_per_sample),
                        "search_space": {"k_ref_N_per_mm": _round(self.space.k_ref),
                                         "c_ref_Ns_per_mm": _round(self.space.c_ref),
                                         "F_ref_N": _round(self.space.F_ref),
                                         "shortest_time_constant_s": _round(self.space.shortest_time_constant_s)},
                        "note": "alpha = 1 in every Bouc-Wen block: the (alpha, A, beta, gamma) redundancy "
                                "(search_space.rescale_hysteresis gives the equivalent sets)"})
        if self.sampler is not None:
            out["posterior_sampling"] = {"acceptance": _round(self.sampler.acceptance),
                                         "autocorrelation_steps": _round(self.sampler.autocorrelation_steps),
                                         "kept_steps": self.sampler.kept_steps}
        if self.identifiability is not None:
            out["weak_directions"] = [{k: (_round(v) if not isinstance(v, dict) else {n: _round(x) for n, x in v.items()})
                                       for k, v in entry.items()} for entry in self.identifiability.weakest()]
        return out

    def _method(self) -> str:
        if self.space is None:
            return "linear least squares F = k*x + c*v on the tests other than steps"
        stages = ", ".join(f"{s} x {e}" for s, e in PRESETS[self.preset].stages)
        first = ("the paper's GA (pymoo, population 300, 200 generations)" if self.preset == "paper"
                 else f"{PRESETS[self.preset].screening} scrambled Sobol points")
        return (f"{first}, then successive halving of bounded trust-region least squares "
                f"(starts x evaluations: {stages}) on chi^2/n over every sample")

    def summary(self) -> str:
        """A report like lmfit's fit_report: figures first, then the warnings."""
        fitted = f"{len(self.tests)} test(s)" + (f" and the table {self.table.name}" if self.table else "")
        lines = [f"{self.parameters.model.title} fitted to {fitted}, preset {self.preset!r}, "
                 f"seed {self.seed}, {self.evaluations} simulations in {self.seconds:.1f} s on {self.engine}",
                 f"misfit chi^2/n = {self.misfit:.4f} (1 = the noise floor)"]
        lines.append(f"{'test':44s} {'kind':7s} {'noise':>8s} {'NRMSE':>8s} {'ratio':>6s}  floor")
        for t in self.tests:
            lines.append(f"{t.name:44s} {t.kind:7s} {t.noise_fraction:8.2%} {t.nrmse:8.2%} "
                         f"{t.ratio:6.2f}  {'yes' if t.at_floor else 'NO'}")
        if self.table is not None:
            lines.append(self.table.format())
            if self.table.cycles_error > 0.1 * KDYN_UNCERTAINTY:
                lines.append(f"note: the fit's {FIT_CYCLES}-cycle loop differs from the steady state by up to "
                             f"{self.table.cycles_error:.2%} in |K*| at the fitted set (a slow transient); more than "
                             "a tenth of the table's uncertainty")
        if self.space is not None:
            lines.append(f"starts: {self.agreeing} of {self.final_starts} final starts agree (misfit within "
                         f"{self.threshold:.2e} of the best: delta chi^2 at 95 % for {len(self.space.names)} parameters); "
                         + (f"ensemble: {len(self.ensemble)} parameter sets" if self.ensemble_sampled
                            else "ensemble: not sampled (ensemble=False), the best fit alone"))
        if self.steps_per_sample:
            lines.append("forward model: " + ", ".join(f"{m} step{'s' if m > 1 else ''} per sample on {t.name}"
                                                       for m, t in zip(self.steps_per_sample, self.tests)))
        if self.identifiability is not None:
            lines.append(self.identifiability.format())
        if self.sampler is not None:
            lines.append(self.sampler.format())
        lines += self.notes
        lines.append("converged: yes" if self.converged else f"converged: no ({self.warning})")
        return "\n".join(lines)

    def save(self, path: str | Path, ssv: str | Path | None = None, ensemble: str | Path | None = None,
             data: Sequence[str] = ()) -> list[Path]:
        """Write the parameter file (JSON with provenance), optionally an .ssv and the ensemble."""
        provenance = dict(self.provenance(), data=[str(d) for d in data])
        written = [save_parameters(path, self.parameters.parameters, self.model, provenance)]
        if ssv is not None:
            written.append(save_parameters(ssv, self.parameters.parameters, self.model))
        if ensemble is not None:
            if not self.ensemble_sampled:
                raise IdentificationError(f"no ensemble to write to {ensemble}: this fit ran with ensemble=False "
                                          "(--no-ensemble); fit again without it for the ensemble")
            written.append(save_ensemble(ensemble, self.ensemble, self.model, provenance))
        return written


def as_tests(measurements) -> list[RigTest]:
    """RigTests from a Manifest, RigTests, Measurements (kind ``random``) or file paths."""
    from identification.measurements import load_measurement
    if isinstance(measurements, Manifest):
        return list(measurements.tests)
    if isinstance(measurements, (RigTest, Measurement, str, Path)):
        measurements = [measurements]
    tests = []
    for item in measurements:
        if isinstance(item, RigTest):
            tests.append(item)
        elif isinstance(item, Measurement):
            tests.append(RigTest(item))
        else:
            tests.append(RigTest(load_measurement(item)))
    if not tests:
        raise IdentificationError("no training tests given")
    return tests


def fit(measurements, model: str = "proposed", preset: str = "default", seed: int = 0, workers: int | None = None,
        scheduler=None, engine=None, progress: bool = True, screening: int | None = None,
        starts: int | None = None, kdyn=None, ensemble: bool = True) -> FitResult:
    """Identify ``model``'s parameters from training tests (see the module docstring).

    ``measurements``: a ``rig_tests.Manifest``, ``RigTest``s, ``Measurement``s or CSV paths.
    ``workers``/``scheduler``: where the starts run (default: every local core); ``engine``: an
    engine to reuse (not closed). ``screening``, ``starts``: override the preset's number of
    Sobol points and of first-stage starts (later stages shrink in proportion, at least
    MIN_FINAL_STARTS remain). ``kdyn``: a dynamic-stiffness table (a CSV path or a
    ``kdyn_table.KdynTable``) fitted with the tests, or alone (``measurements`` empty).
    ``ensemble=False`` skips the prediction profiles and the posterior sampling (a third to
    half of a fit's time): the result's ensemble is then the best fit alone, so ``predict``
    gives no band and ``save(ensemble=...)`` refuses.
    Emits a ``FitNotConvergedWarning`` when the fit is not converged.
    """
    from threadpoolctl import threadpool_limits
    started = time.perf_counter()
    table = kdyn if kdyn is None or isinstance(kdyn, KdynTable) else load_kdyn_table(kdyn)
    empty = measurements is None or (isinstance(measurements, (list, tuple)) and not measurements)
    tests = [] if (empty and table is not None) else as_tests(measurements)
    bushing = get_model(model)
    if seed < 0:
        raise IdentificationError(f"seed = {seed}: give an integer >= 0")
    noise = [_noise_of(t) for t in tests]
    # One BLAS thread here as in every task: a multi-threaded BLAS may sum in another order,
    # and the scales and the Jacobian's SVD computed here must not depend on the engine.
    with threadpool_limits(limits=1):
        if bushing.name == "kelvin_voigt":
            result = _fit_kelvin_voigt(tests, noise, started, table)
        else:
            if preset not in PRESETS:
                raise IdentificationError(f"unknown preset {preset!r}; choose one of {', '.join(PRESETS)}")
            settings = _settings(PRESETS[preset], screening, starts)
            owned = engine is None
            engine = engine or make_engine(workers, scheduler)
            try:
                result = _search(tests, noise, bushing.name, preset, settings, seed, engine, progress, started, table,
                                 ensemble)
            finally:
                if owned:
                    engine.close()
    if not result.converged:
        warnings.warn(result.warning, FitNotConvergedWarning, stacklevel=2)
    return result


def _noise_of(test: RigTest) -> NoiseEstimate:
    try:
        return estimate_noise(test.measurement.force_N)
    except ValueError as exc:
        raise IdentificationError(f"{test.measurement.source}: {exc}") from None


def _settings(base: SearchSettings, screening: int | None, starts: int | None) -> SearchSettings:
    if starts is not None:
        if starts < 1:
            raise IdentificationError(f"starts = {starts}: give 1 or more")
        first = base.stages[0][0]
        stages = tuple((max(min(MIN_FINAL_STARTS, starts), round(count * starts / first)) if i else starts, evaluations)
                       for i, (count, evaluations) in enumerate(base.stages))
        base = replace(base, stages=stages)
    if screening is not None:
        base = replace(base, screening=screening)
    return SearchSettings(base.screening, base.stages)   # validates


def _search(tests, noise, model, preset, settings, seed, engine, progress, started, table=None,
            sample_ensemble=True) -> FitResult:
    measurements = [t.measurement for t in tests]
    space = SearchSpace.from_measurements(measurements, model, steps=[t.kind == "step" for t in tests], table=table)
    # with a table, the screening and the early stages run its coarser loop (kdyn_table)
    problem = Problem(Objective(tests, noise, model=space.model, table=table, search=table is not None), space)
    ga_evaluations = PAPER_GA["population"] * PAPER_GA["generations"]
    bars = _Progress(progress, settings, ga_evaluations if preset == "paper" else settings.screening)
    if preset == "paper":
        from identification.multistart import genetic_algorithm
        theta, misfits = genetic_algorithm(problem, engine, seed, bars.screening, **PAPER_GA)
    else:
        theta, misfits = screen(problem, engine, settings.screening, seed, bars.screening)
    evaluations = ga_evaluations if preset == "paper" else len(misfits)
    n, d = problem.objective.size, len(space.names)
    *early, last = settings.stages
    records = run_stages(problem, engine, first_records(theta, misfits, settings.stages[0][0]), early, bars.stage)
    # The forward model's steps per sample, checked where the result is decided: at the best
    # start before the last stage, and at the best fit; if that changes them, the last stage
    # runs once more, and a third check only reports (identification.refinement). A lone best
    # start gets company before the check at the best fit (_extend_if_alone).
    notes = []
    refinement = _check_steps(problem, tests, records, n, d)
    problem = Problem(refinement.objective.with_fit_loop(tests), space)
    records = run_stages(problem, engine, records, [last], bars.stage, first_stage=len(early))
    records, added, agreeing = _extend_if_alone(problem, engine, records, last, len(early), n, d, bars)
    final_count = last[0] + added
    if added:
        notes.append(f"note: only {agreeing} of the {last[0]} final starts reached the best misfit, so {added} more "
                     f"start{'s' if added > 1 else ''} of the earlier stages also ran the last stage")
    refinement_at_best = _check_steps(problem, tests, records, n, d)
    evaluations += refinement.evaluations + refinement_at_best.evaluations
    if refinement_at_best.changed:
        problem = Problem(refinement_at_best.objective, space)
        records = run_stages(problem, engine, records, [(final_count, last[1])],
                             lambda s, k: bars.stage(s, k, again=True, total=final_count), first_stage=len(early))
        final_check = _check_steps(problem, tests, records, n, d)
        evaluations += final_check.evaluations
        if final_check.changed:
            notes.append(f"note: at the best fit the forward model would need "
                         f"{'/'.join(map(str, final_check.objective.steps_per_sample))} steps per sample (it ran "
                         f"{'/'.join(map(str, problem.objective.steps_per_sample))}); its own error may take more "
                         "than a tenth of the confidence region")
    bars.close()
    evaluations += sum(r.evaluations - 1 for r in records)

    final = [r for r in records if r.stage == len(early)]     # scored by the objective used from here on
    best = min(final, key=lambda r: (r.misfit, r.start))
    threshold = misfit_threshold(best.misfit, n, d)
    scaled_jacobian, _ = jacobian(problem, best.theta)
    ident = identifiability(scaled_jacobian * np.sqrt(n), space.names, threshold * n)
    evaluations += d + 1
    limit = best.misfit + threshold
    sampler = None
    members = [best.theta]
    if sample_ensemble:
        extremes, extreme_misfits = profile_extremes(problem, best.theta, best.misfit, ident, limit, engine)
        # here, not on a worker: the compiled kernel runs the walkers on every core of this process
        draws, _, sampler = posterior_samples(problem, best.theta, seed, threshold_scale(best.misfit, n, d))
        pushed, pushed_misfits = push_to_boundary(problem, best.theta, draws, limit)
        evaluations += WALKERS * STEPS + len(draws) * len(PUSH) \
            + len(PROBES) * 2 * (d + 1) * (1 + PROFILE_ROUNDS * PROFILE_EVALUATIONS)
        members = select_members(best.theta, [(r.theta, r.misfit) for r in final],
                                 np.vstack([extremes, pushed]), np.concatenate([extreme_misfits, pushed_misfits]),
                                 limit, space.bounds())
    rows = space.to_model_parameters(np.array(members))
    names = space.bushing.parameter_names
    ensemble = [dict(zip(names, map(float, row))) for row in rows]
    parameters = ParameterSet(space.bushing, ensemble[0])
    steps = problem.objective.steps_per_sample
    result = FitResult(parameters, float(best.misfit), _test_fits(tests, noise, parameters, steps), records, threshold,
                       ensemble, ident, preset, seed, evaluations, time.perf_counter() - started, engine.description,
                       space, final_starts=len(final), sampler=sampler, notes=notes, steps_per_sample=steps,
                       table=_table_fit(table, parameters), added_starts=added, agreed_before_added=agreeing,
                       ensemble_sampled=sample_ensemble)
    result.parameters.provenance = result.provenance()
    return result


def _fit_kelvin_voigt(tests, noise, started, table=None) -> FitResult:
    """F = k*x + c*v by linear least squares with k, c >= 0 on the tests other than steps (a
    linear spring cannot show the step's relaxation; all tests if there are only steps). With
    a dynamic-stiffness table: scipy's bounded least squares on the whole objective (tests and
    table), from that solution or, with a table alone, from the table's median K' and K''/omega."""
    from scipy.optimize import least_squares
    bushing = get_model("kelvin_voigt")
    if tests:
        linear = KelvinVoigtFit.fit([t.measurement for t in tests if t.kind != "step"]
                                    or [t.measurement for t in tests], nonnegative=True)
        values = {"k": linear.k, "c": linear.c, "preload": 0.0}
    else:
        scales = SearchSpace.from_table(table)
        values = {"k": scales.k_ref, "c": scales.c_ref, "preload": 0.0}
    objective = Objective(tests, noise, model=bushing.name, table=table)
    if table is not None:
        def residuals(kc):
            return objective.residual_matrix(parameter_matrix([{"k": kc[0], "c": kc[1], "preload": 0.0}],
                                                              bushing.name))[0]
        solution = least_squares(residuals, [values["k"], values["c"]], bounds=([0.0, 0.0], [np.inf, np.inf]),
                                 x_scale="jac")
        values = {"k": float(solution.x[0]), "c": float(solution.x[1]), "preload": 0.0}
    parameters = ParameterSet(bushing, values)
    misfit = float(objective(parameter_matrix([values], bushing.name))[0])
    result = FitResult(parameters, misfit, _test_fits(tests, noise, parameters), [], 0.0, [values], None,
                       "linear", 0, 1, time.perf_counter() - started, table=_table_fit(table, parameters))
    result.parameters.provenance = result.provenance()
    return result


def _extend_if_alone(problem: Problem, engine, records: list[StartRecord], last: tuple[int, int], stage: int,
                     n: int, d: int, bars) -> tuple[list[StartRecord], int, int]:
    """If fewer than MIN_AGREEING of the last stage's starts reach the best misfit within the
    ensemble threshold, up to ``last[0]`` more starts run the last stage too (once): those that
    stopped in the latest earlier stage first, each group by misfit. A lone best start thus
    gets its chance to be confirmed, or a better optimum is found, before the fit says it is
    not converged. Returns the records (sorted as ``run_stages`` sorts them), how many starts
    were added and how many agreed before."""
    best = min(r.misfit for r in records if r.stage == stage)
    agreeing = _agreeing(records, stage, best, misfit_threshold(best, n, d))
    waiting = sorted((r for r in records if r.stage < stage), key=lambda r: (-r.stage, r.misfit, r.start))[:last[0]]
    if agreeing >= MIN_AGREEING or not waiting:
        return records, 0, agreeing
    run_stages(problem, engine, waiting, [(len(waiting), last[1])],
               lambda s, k: bars.stage(s, k, more=True, total=len(waiting)), first_stage=stage)
    records.sort(key=lambda r: (-r.stage, r.misfit, r.start))
    return records, len(waiting), agreeing


def _agreeing(records: list[StartRecord], stage: int, best_misfit: float, threshold: float) -> int:
    """Starts that ran ``stage`` and reached ``best_misfit`` within ``threshold``: the agreement
    count, the convergence evidence."""
    return int(sum(r.misfit <= best_misfit + threshold for r in records if r.stage == stage))


def _check_steps(problem: Problem, tests, records, n: int, d: int):
    """``refinement.refine_steps`` at the best start of the latest stage (its misfit sets the
    region's delta chi^2)."""
    best = min((r for r in records if r.stage == records[0].stage), key=lambda r: (r.misfit, r.start))
    return refine_steps(problem.objective, tests, problem.space.to_parameters(best.theta[None, :]),
                        misfit_threshold(best.misfit, n, d) * n)


def _test_fits(tests, noise, parameters: ParameterSet, steps=None) -> list[TestFit]:
    """Each test's noise and NRMSE at ``parameters``, simulated with ``steps`` per sample (per
    test; default: chosen from the signal)."""
    fits = []
    for test, level, m_steps in zip(tests, noise, steps or [None] * len(tests)):
        m = test.measurement
        predicted = simulate(parameters, m.time_s, m.displacement_mm, m.measured_velocity_mm_s,
                             steps_per_sample=m_steps)
        fits.append(TestFit(test.name, test.kind, level, nrmse(predicted, m.force_N)))
    return fits


def _table_fit(table: KdynTable | None, parameters: ParameterSet) -> TableFit | None:
    """The table's rows (weight > 0) against the converged characterisation of ``parameters``,
    and how far the fit's fixed-cycle loop is from it (its largest relative |K*| difference)."""
    if table is None:
        return None
    from identification.dynamic_stiffness import (MAX_CYCLES, STEPS_PER_CYCLE, TOLERANCE, CharacterisationWarning,
                                                  run_sines, stiffness_from_sums)
    from identification.objectives import PreparedTable
    prepared = PreparedTable.of(table)
    rows = prepared.rows
    model = parameters.model.name
    matrix = parameter_matrix([parameters.parameters], model)

    def steady(steps):
        result, _ = run_sines(matrix, model, rows.amplitude_mm, rows.frequency_hz, rows.preload_mm, steps, MAX_CYCLES,
                              TOLERANCE)
        if np.any(result[:, 3] == 1):
            warnings.warn(f"{table.name}: some cases of the fitted set reach no steady state within {MAX_CYCLES} "
                          "cycles", CharacterisationWarning, stacklevel=4)
        if np.any(result[:, 3] == 2):
            warnings.warn(f"{table.name}: the fitted set fails on some cases (overflow or too many substeps); their "
                          "errors are NaN", CharacterisationWarning, stacklevel=4)
        return stiffness_from_sums(result, rows.amplitude_mm)[2:]

    kdyn, angle = steady(STEPS_PER_CYCLE)
    # the fit loop against the steady state at the fit loop's own steps: what its few cycles leave
    fixed, _ = prepared.stiffness(matrix, model)
    converged_fit_steps, _ = steady(prepared.steps_per_cycle)
    return TableFit(table.name, kdyn / rows.kdyn_N_per_mm - 1.0, angle - rows.loss_angle_deg, rows.weight,
                    float(np.max(np.abs(fixed[0] / converged_fit_steps - 1.0))))


def _round(value):
    """Floats as the parameter file stores them (12 significant digits: stable text)."""
    return float(f"{value:.12g}") if isinstance(value, float) else value


class _Progress:
    """tqdm bars for the screening and each least-squares stage (on stderr)."""

    def __init__(self, enabled: bool, settings: SearchSettings, screening_total: int):
        self.enabled = enabled and sys.stderr is not None
        self.settings = settings
        self.screening_total = screening_total
        self._bar = None
        self._stage = None

    def screening(self, count: int):
        self._advance("screening", self.screening_total, "points", count)

    def stage(self, index: int, count: int, again: bool = False, more: bool = False, total: int | None = None):
        starts, evaluations = self.settings.stages[index]
        starts = total or starts
        self._advance(f"stage {index + 1}/{len(self.settings.stages)} ({starts} starts x {evaluations})"
                      + (" again, finer steps" if again else "") + (" on more starts" if more else ""),
                      starts, "starts", count)

    def _advance(self, name, total, unit, count):
        if not self.enabled:
            return
        from tqdm import tqdm
        if self._stage != name:
            self.close()
            self._bar = tqdm(total=total, desc=name, unit=unit, leave=False, file=sys.stderr)
            self._stage = name
        self._bar.update(count)

    def close(self):
        if self._bar is not None:
            self._bar.close()
            self._bar = None
