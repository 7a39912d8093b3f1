"""The search of a nonlinear model's parameters (``fit``'s, step by step): the box and the
objective, the global phase (screened Sobol points, with starts read off the data, or the paper's
GA), the least-squares stages with the forward model's steps checked where the result is
decided, the ensemble (profiles, posterior draws pushed to the confidence region's edge) and the
result with its evidence. :func:`run` takes a :class:`SearchRequest` (what one search fits) and an
engine (where its tasks run).
"""
from __future__ import annotations

import math
import os
import threading
import time
import warnings
from dataclasses import dataclass

import numpy as np

from fmu_src.model.registry import BushingModel
from fmu_src.kernels.numba_binding import cache_directory
from fmu_src.parameter_files import ParameterSet
from identification.forward.population import parameter_matrix
from identification.fitting.ensemble import (PROBES, PROFILE_EVALUATIONS, PROFILE_ROUNDS, PUSH, STEPS, SamplingFailed,
                                             identifiability, misfit_threshold, posterior_samples, profile_extremes,
                                             push_to_boundary, select_members, threshold_scale, walkers_for)
from identification.errors import CharacterisationWarning, EnsembleWarning
from identification.fitting.result import MIN_AGREEING, FitResult, RigTestFit, TableFit, agreeing_starts
from identification.measured.kdyn_table import KdynTable
from identification.fitting.loop_start import LOOP_STARTS, FitStart, anchored_coordinates, slow_loop_start
from identification.measured.measurements import Measurement
from identification.measured.multiaxis import vector_nrmse
from identification.fitting.multistart import (AnchoredStarts, PrefixScreening, Problem, StartRecord, failed_starts,
                                               first_records, jacobian, run_stages, screen, simulations_per_jacobian)
from identification.measured.offsets import MIN_REST_S, MIN_REST_SAMPLES, short_rest
from identification.measured.repeatability import estimate_repeatability
from identification.measured.noise import NoiseEstimate
from identification.fitting.objectives import MultiAxisTests, Objective, nrmse
from identification.fitting.presets import PAPER_GA, SearchSettings, describe
from identification.fitting.progress import SearchProgress, notice_later
from identification.fitting.refinement import refine_steps
from identification.fitting.search_space import SearchSpace
from identification.forward.simulate import simulate_record, simulate_multiaxis
from identification.fitting.table_start import sines_as_table, table_start


@dataclass(frozen=True)
class MultiAxisTraining(MultiAxisTests):
    """The multi-axis training tests, each axis's noise level (estimated) and the coupling they
    are run with; an objective's (``MultiAxisTests``) with each test's fit."""

    def components(self) -> list[Measurement]:
        return [c for m in self.measurements for c in m.components()]

    def fits(self, parameters: ParameterSet) -> list[RigTestFit]:
        """Each test's vector NRMSE at ``parameters`` against its noise: the rms of the axes'
        noise levels over the rms force vector (``multiaxis.vector_nrmse``'s units)."""
        fits = []
        for m, levels in zip(self.measurements, self.noise):
            predicted = simulate_multiaxis(parameters, m.time_s, m.displacement_mm, coupling=self.coupling,
                                           velocity_mm_s=m.velocity_mm_s)
            noise = NoiseEstimate(math.sqrt(sum(level.sigma_N ** 2 for level in levels)),
                                  math.sqrt(float(np.mean(np.sum(m.force_N ** 2, axis=1)))))
            fits.append(RigTestFit(m.name, f"{len(m.axes)}-axis", noise, vector_nrmse(predicted, m.force_N),
                                   predicted_N=predicted))
        return fits


def _exact_jacobian_or_why_not(tests, space: SearchSpace) -> tuple[str, str | None]:
    """("exact", None), or ("difference", a note saying why) where the exact Jacobian would not
    pay: a fit to a dynamic-stiffness table alone (its rows are differences either way), or a
    cache folder that cannot be written (every process, every worker would compile the module
    again, a minute or more each)."""
    if not tests:
        return "difference", None
    folder = cache_directory()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        writable = os.access(folder, os.W_OK)
    except OSError:
        writable = False
    if not writable:
        return "difference", (f"note: the compiled models' cache {folder} cannot be written, so the fit takes "
                              "forward differences for its Jacobian (the exact one would be compiled again in every "
                              "process); set BUSHING_CACHE_DIR to a writable folder")
    return "exact", None


class JacobianCompile:
    """The exact Jacobian's module of ``bushing`` in ``lanes`` directions, compiled (or loaded
    from the disk cache) on a thread of this process while the global phase runs on the workers:
    the compile takes one core for half a minute or more on a machine's first fit, and the
    screening needs only the forward model. :meth:`wait` joins it before the least-squares
    stages, whose workers then load it from the disk cache instead of each compiling it. With
    ``progress``, a compile that takes longer than a moment says what it compiles and about how
    long it takes (``parameter_jacobian.expected_compile_seconds``), on stderr, and a wait for it
    shows a bar of the seconds."""

    NOTICE_AFTER_S = 3.0
    """A module still busy after this long is being compiled, not loaded from the cache."""

    def __init__(self, bushing: BushingModel, lanes: int, progress: bool):
        self.bushing, self.lanes, self.progress, self.error = bushing, lanes, progress, None
        self.began = None
        self.message = notice_later(self.NOTICE_AFTER_S, self._notice) if progress else None
        self.thread = threading.Thread(target=self._compile, name="exact Jacobian compile", daemon=True)

    def _expected_s(self) -> float | None:
        from identification.forward.parameter_jacobian import expected_compile_seconds, lane_chunk
        return expected_compile_seconds(self.bushing, lane_chunk(self.lanes))

    def _notice(self) -> str:
        expected = self._expected_s()
        return (f"compiling the exact Jacobian of the {self.bushing.name} model ({self.lanes} directions) beside the "
                f"search: once per machine, {f'about {expected:.0f} s on a 2-core VM' if expected else 'a minute or less'}"
                f"; cached in {cache_directory()}")

    def _compile(self):
        from identification.forward.parameter_jacobian import lane_chunk, sensitivity_module
        try:
            sensitivity_module(self.bushing, lane_chunk(self.lanes))
        except BaseException as error:          # raised again by wait(), in the search's thread
            self.error = error
        finally:
            if self.message:
                self.message.cancel()

    def start(self) -> "JacobianCompile":
        self.began = time.perf_counter()
        if self.message:
            self.message.start()
        self.thread.start()
        return self

    def wait(self) -> None:
        """Until the module is compiled or loaded, with a bar of its seconds where it is still
        compiling; its error, if it failed."""
        from identification.fitting.progress import bar
        seconds = None
        while self.thread.is_alive():
            self.thread.join(0.1)       # in short waits: a Ctrl-C is not held up by the join
            elapsed = time.perf_counter() - self.began
            if seconds is None and self.thread.is_alive() and elapsed > self.NOTICE_AFTER_S:
                expected = self._expected_s() or 60.0
                seconds = bar(max(round(expected), round(elapsed) + 1), f"compiling the {self.bushing.name} model's "
                              "exact Jacobian (once per machine)", "s", self.progress) or False
            if seconds:
                seconds.total = max(seconds.total, round(elapsed) + 1)
                seconds.update(min(round(elapsed), seconds.total) - seconds.n)
        if seconds:
            seconds.close()
        if self.error is not None:
            raise self.error


@dataclass(frozen=True)
class SearchRequest:
    """What one search fits: the training (one-axis tests with their noise, a table, multi-axis
    tests), the model, the preset's settings and name, the seed, the Jacobian wanted, and whether
    the ensemble is sampled."""
    tests: list
    noise: list
    model: BushingModel
    preset: str
    settings: SearchSettings
    seed: int
    table: KdynTable | None = None
    multi: MultiAxisTraining = MultiAxisTraining([], [], "none")
    jacobian_kind: str = "exact"
    sample_ensemble: bool = True
    fixed: tuple[tuple[str, float], ...] = ()     # parameters held at given values (SearchSpace.fixed)
    start: FitStart | None = None
    """A nested model's fit to start from (``compare``'s variants): screened starts anchored at its
    values where this model has them, in place of a start read off the data."""


def run(request: SearchRequest, engine, progress: bool, started: float) -> FitResult:
    """The search of a nonlinear model's parameters (``fit``), on ``engine``, timed from ``started``."""
    return begin(request, engine, progress, started).run()


def begin(request: SearchRequest, engine, progress: bool, started: float) -> "Search":
    """A search that has not run yet: ``run()`` whole (``fit``), or step by step (``compare``
    screens every model before it runs the stages of those still in the race)."""
    return Search(request, engine, progress, started)


class Search:
    """One search, step by step: the box and the objective, the global phase (:meth:`screen`),
    the least-squares stages with the forward model's steps checked and the result
    (:meth:`finish`), the ensemble (there, or later: :meth:`with_ensemble`). Each step reads what
    the ones before it left here; ``notes`` and ``evaluations`` (simulations run) add up, and
    ``seconds`` counts the time spent in the steps (and before the first, from ``started``), not
    the time other searches ran between them."""

    def __init__(self, request: SearchRequest, engine, progress: bool, started: float):
        self.request, self.engine, self.progress, self.started = request, engine, progress, started
        self.notes: list[str] = []
        self.evaluations = 0
        self.seconds = 0.0
        self.jacobian_compile = None
        self.screened = None         # the global phase's points and misfits
        self.first_records = None    # the starts after the first least-squares stage
        self.first_stage_misfit = None  # the best chi^2/n after the first least-squares stage (the
        # screened one where the preset has a single stage, which is the last)
        self.early_records = None    # the starts after every stage but the last
        self.before_last_misfit = None  # the best chi^2/n of those (the first stage's with two stages or one)
        self.problem = None
        self.final_state = None      # what the stages left for the result
        self.result = None

    def run(self) -> FitResult:
        self.screen()
        return self.finish()

    def prepare(self) -> Problem:
        """The box and the objective (once): ``problem``."""
        if self.problem is None:
            self.problem = self._problem()
        return self.problem

    def screen(self, compile_beside: bool = True, since: float | None = None) -> float:
        """The box, the objective and the global phase; the best screened misfit (chi^2/n).
        ``compile_beside``: the exact Jacobian's module compiles on a thread while the workers
        screen (else when :meth:`start_jacobian_compile` or a later step asks). The search's
        time counts from ``since`` (default: its start)."""
        self.prepare()
        if compile_beside:
            self.start_jacobian_compile()
        self.screened = self._global_phase()
        self.bars.close()
        self.seconds += time.perf_counter() - (self.started if since is None else since)
        return self.screened_misfit

    @property
    def screened_misfit(self) -> float:
        """The best misfit (chi^2/n) of the global phase's points."""
        return float(np.min(self.screened[1]))

    def first_stage(self) -> float:
        """The first least-squares stage from the screened points (after the exact Jacobian's
        module is ready); its best misfit (chi^2/n). :meth:`finish` goes on from there."""
        self._timed(self._first_stage)
        return self.first_stage_misfit

    def _timed(self, step) -> None:
        """``step()`` run, its bars closed and its time added to ``seconds``."""
        began = time.perf_counter()
        step()
        self.bars.close()
        self.seconds += time.perf_counter() - began

    def _first_stage(self) -> None:
        if self.first_records is not None:
            return
        self.start_jacobian_compile()
        if self.jacobian_compile is not None:
            self.jacobian_compile.wait()
        stages = self.request.settings.stages
        theta, misfits = self.screened
        self.first_records = first_records(theta, misfits, stages[0][0])
        if len(stages) > 1:     # a single stage is the last, which runs on the fit's loop (_stages)
            self.first_records = run_stages(self.problem, self.engine, self.first_records, stages[:1],
                                            self.bars.stage)
        # read now: the later stages go on with these records
        self.first_stage_misfit = min((r.misfit for r in self.first_records if not r.failed),
                                       default=self.screened_misfit)

    def early_stages(self) -> float:
        """Every least-squares stage but the last (the first, where :meth:`first_stage` has not
        run it); the best misfit (chi^2/n) they reached. :meth:`finish` runs the last from there."""
        self._timed(self._early_stages)
        return self.before_last_misfit

    def _early_stages(self) -> None:
        if self.early_records is not None:
            return
        self._first_stage()
        early = self.request.settings.stages[:-1]
        self.early_records = run_stages(self.problem, self.engine, self.first_records, early[1:], self.bars.stage,
                                        first_stage=1)
        self.before_last_misfit = min((r.misfit for r in self.early_records if not r.failed),
                                      default=self.first_stage_misfit)

    def start_jacobian_compile(self) -> None:
        """Start compiling (or loading) the exact Jacobian's module on a thread, once, where the
        search takes the exact Jacobian (:meth:`screen` chose)."""
        if self.jacobian_kind == "exact" and self.jacobian_compile is None:
            self.jacobian_compile = JacobianCompile(self.space.bushing, len(self.space.names), self.progress).start()

    def finish(self, ensemble: bool | None = None) -> FitResult:
        """The stages from the screened points (the first, where :meth:`first_stage` has not
        run it) and the result; the ensemble sampled if ``ensemble`` (default: the request's
        ``sample_ensemble``)."""
        began = time.perf_counter()
        records, added, agreeing = self._stages()
        # scored by the objective used from here on; a failed start is skipped (failed_starts)
        final = [r for r in records if r.stage == len(self.request.settings.stages) - 1 and not r.failed]
        best = _best_record(final or records)
        if not final:
            self.notes.append(f"note: every start of the last stage failed (residuals or Jacobian not finite); the "
                              f"result is the best finite point the search found (stage "
                              f"{best.stage + 1 if best.stage >= 0 else 0})")
        self.final_state = (records, final, best, added, agreeing, self.evaluations, list(self.notes))
        self.seconds += time.perf_counter() - began
        return self._finished(self.request.sample_ensemble if ensemble is None else ensemble)

    def with_ensemble(self) -> FitResult:
        """The finished search's result again, with the ensemble sampled (profiles, posterior)
        where :meth:`finish` left it out; the same best fit."""
        if self.result is not None and self.result.ensemble_sampled:
            return self.result
        return self._finished(True)

    def _finished(self, ensemble: bool) -> FitResult:
        began = time.perf_counter()
        records, final, best, added, agreeing, evaluations, notes = self.final_state
        self.evaluations, self.notes = evaluations, list(notes)
        self.result = self._result(records, final, best, added, agreeing, ensemble)
        self.seconds += time.perf_counter() - began
        self.result.seconds = self.seconds
        return self.result

    def _problem(self) -> Problem:
        """The box scaled by the data and the objective; the exact Jacobian where it pays."""
        request = self.request
        multi = request.multi
        measurements = [t.measurement for t in request.tests] + multi.components()
        self.space = SearchSpace.from_measurements(measurements, request.model,
                                                   steps=[t.kind == "step" for t in request.tests]
                                                   + [False] * (len(measurements) - len(request.tests)),
                                                   table=request.table, fixed=request.fixed)
        # with a table, the screening and the early stages run its coarser loop (kdyn_table)
        self.jacobian_kind = request.jacobian_kind
        if self.jacobian_kind == "exact":
            self.jacobian_kind, note = _exact_jacobian_or_why_not(request.tests, self.space)
            if note:
                self.notes.append(note)
        objective = Objective(request.tests, request.noise, model=self.space.bushing, table=request.table,
                              search=request.table is not None, multiaxis=multi)
        self.notes += resting_notes(request.tests, objective.rest_forces, self.space.bushing)
        self.notes += temperature_notes(request.tests, self.space.bushing)
        self.n, self.d = objective.size, len(self.space.names)     # residuals, coordinates
        return Problem(objective, self.space, self.jacobian_kind)

    def _method(self) -> str:
        """The search as it ran (``presets.describe`` of its settings), from a nested model's fit
        where it started from one."""
        start = self.request.start
        used = start is not None and not self.request.settings.genetic     # the paper's GA takes no start
        return describe(self.request.settings) + (f"; started from the {start.source} fit" if used else "")

    def _data_start(self):
        """The request's start (a nested model's fit), else one read off the data (a slow loop,
        else a table), or None; a table that gives none says why in a note. The paper's GA takes
        none."""
        request = self.request
        if request.settings.genetic:
            return None
        if request.start is not None:
            return request.start
        loop = slow_loop_start(request.tests, self.space)
        if loop is None:
            table = request.table
            if table is None and self.space.bushing.search.table_start is not None:
                table = sines_as_table(request.tests)       # time series alone: their sines' harmonics
            loop = table_start(table, self.space)
            if isinstance(loop, str):           # the table gives no start, and why
                self.notes.append(loop)
                loop = None
        if loop is not None:
            self.notes.append(f"note: {LOOP_STARTS} of the screened starts take the {loop.describe()}")
        return loop

    def _anchored_starts(self, start) -> AnchoredStarts:
        """The screened starts anchored at a start (``_data_start``'s; none: no point). A nested
        model's fit (``FitStart``) keeps its first point whole through a prefix screening, and is
        one point where it sets every coordinate (its copies would fill the stages' starts)."""
        values = anchored_coordinates(start, self.space) if start else {}
        if not values:
            return AnchoredStarts({}, 0)
        if not isinstance(start, FitStart):
            return AnchoredStarts(values, LOOP_STARTS)
        first = {i: value for i, value in anchored_coordinates(start.whole(), self.space).items() if i not in values}
        count = LOOP_STARTS if len(values) < len(self.space.coordinates) else 1
        self.notes.append(f"note: {count} of the screened starts take the {start.describe()}")
        return AnchoredStarts(values, count, first, kept=True)

    def _global_phase(self):
        """The preset's global phase: its points and their misfits, best first."""
        settings, problem = self.request.settings, self.problem
        anchors = self._anchored_starts(self._data_start())
        points = settings.screening + anchors.count
        prefix = None
        if settings.prefix_fraction is not None and not settings.genetic:
            objective = problem.objective.prefix(settings.prefix_fraction)
            prefix = objective and Problem(objective, self.space, "difference")
        kept = math.ceil(settings.prefix_kept * points) if prefix else 0
        self.bars = SearchProgress(self.progress, settings, settings.global_evaluations(points) + kept)
        if settings.genetic:
            from identification.fitting.multistart import genetic_algorithm
            theta, misfits = genetic_algorithm(problem, self.engine, self.request.seed, self.bars.screening, PAPER_GA)
        else:
            theta, misfits = screen(problem, self.engine, settings.screening, self.request.seed, self.bars.screening,
                                    anchors, prefix and PrefixScreening(prefix, settings.prefix_kept))
        self.evaluations += settings.global_evaluations(points) + kept
        return theta, misfits

    def _stages(self):
        """The least-squares stages from the global phase's best points (after the first stage): (records, starts added to
        the last stage, starts that agreed before). The forward model's steps per sample are
        checked where the result is decided: at the best start before the last stage, and at the
        best fit; if that changes them, the last stage runs once more, and a third check only
        reports (identification.fitting.refinement). A lone best start gets company before the
        check at the best fit (_extend_if_alone)."""
        space, engine, bars = self.space, self.engine, self.bars
        self._early_stages()
        *early, last = self.request.settings.stages
        n, d = self.n, self.d
        records = self.early_records
        refinement = _check_steps(self.problem, records, n, d)
        problem = Problem(refinement.objective.with_fit_loop(), space, self.jacobian_kind)
        records = run_stages(problem, engine, records, [last], bars.stage, first_stage=len(early))
        records, added, agreeing = _extend_if_alone(problem, engine, records, last, len(early), (n, d), bars)
        final_count = last[0] + added
        if added:
            self.notes.append(f"note: only {agreeing} of the {last[0]} final starts reached the best misfit, so {added} "
                              f"more start{'s' if added > 1 else ''} of the earlier stages also ran the last stage")
        refinement_at_best = _check_steps(problem, records, n, d)
        self.evaluations += refinement.evaluations + refinement_at_best.evaluations
        if refinement_at_best.changed:
            problem = Problem(refinement_at_best.objective, space, self.jacobian_kind)
            records = run_stages(problem, engine, records, [(final_count, last[1])],
                                 lambda s, k: bars.stage(s, k, again=True, total=final_count), first_stage=len(early))
            final_check = _check_steps(problem, records, n, d)
            self.evaluations += final_check.evaluations
            if final_check.changed:
                self.notes.append(f"note: at the best fit the forward model would need "
                                  f"{'/'.join(map(str, final_check.objective.steps_per_sample))} steps per sample (it "
                                  f"ran {'/'.join(map(str, problem.objective.steps_per_sample))}); its own error may "
                                  "take more than a tenth of the confidence region")
        bars.close()
        self.evaluations += sum(r.evaluations - 1 for r in records)
        self.problem = problem
        return records, added, agreeing

    def _ensemble(self, best: StartRecord, final: list[StartRecord], ident, threshold: float, sample: bool):
        """The ensemble's members (coordinates, the best first), the posterior's sampler (or None)
        and the failed profile tasks: every set within the confidence threshold the profiles, the
        posterior and the final starts found; the best alone where the ensemble is not sampled."""
        problem, space = self.problem, self.space
        n, d = self.n, self.d
        if not sample:
            return [best.theta], None, 0
        limit = best.misfit + threshold
        extremes, extreme_misfits, failed_profiles = profile_extremes(problem, best.theta, best.misfit, ident, limit,
                                                                      self.engine)
        # here, not on a worker: the compiled kernel runs the walkers on every core of this process
        try:
            draws, _, sampler = posterior_samples(problem, best.theta, self.request.seed,
                                                  threshold_scale(best.misfit, n, d))
            pushed, pushed_misfits = push_to_boundary(problem, best.theta, draws, limit)
            sampled = walkers_for(d) * STEPS + len(draws) * len(PUSH)
        except SamplingFailed as failure:
            warnings.warn(f"{space.bushing.name}: {failure}; the band is the prediction profiles' and the final "
                          "starts' alone (narrower than with the posterior's draws)", EnsembleWarning, stacklevel=2)
            self.notes.append(f"note: {failure}; the ensemble holds the profiles' ends and the final starts only")
            pushed, pushed_misfits, sampler, sampled = np.empty((0, d)), np.empty(0), None, 0
        per_jacobian = simulations_per_jacobian(problem, d, known=False)
        self.evaluations += sampled \
            + len(PROBES) * 2 * per_jacobian * (1 + PROFILE_ROUNDS * PROFILE_EVALUATIONS)
        members = select_members(best.theta, [(r.theta, r.misfit) for r in final],
                                 np.vstack([extremes, pushed]), np.concatenate([extreme_misfits, pushed_misfits]),
                                 limit, space.bounds())
        return members, sampler, failed_profiles

    def _result(self, records, final, best: StartRecord, added: int, agreeing: int, sample: bool) -> FitResult:
        request, problem, space = self.request, self.problem, self.space
        n, d = self.n, self.d
        threshold = misfit_threshold(best.misfit, n, d)
        scaled_jacobian = _identifiability_jacobian(problem, best.theta, self.notes)
        ident = identifiability(scaled_jacobian * np.sqrt(n), space.names, threshold * n)
        self.evaluations += simulations_per_jacobian(problem, d, known=False)
        members, sampler, failed_profiles = self._ensemble(best, final, ident, threshold, sample)
        rows = space.to_model_parameters(np.array(members))
        ensemble = [dict(zip(space.bushing.parameter_names, map(float, row))) for row in rows]
        parameters = ParameterSet(space.bushing, ensemble[0])
        steps = problem.objective.steps_per_sample
        # a strided test's steps are per stride: on every sample, as many as make steps no longer
        every = [-(-m // t.driven.stride) for m, t in zip(steps, problem.objective.tests)]
        fits = test_fits(request.tests, request.noise, parameters, every) + request.multi.fits(parameters)
        steps = steps + [m.driven.steps_per_sample for m in problem.objective.multiaxis]
        result = FitResult(parameters, float(best.misfit), fits, records, threshold,
                           ensemble, ident, request.preset, request.seed, self.evaluations,
                           time.perf_counter() - self.started, self.engine.description, space,
                           final_starts=len(final), sampler=sampler, notes=self.notes, steps_per_sample=steps,
                           table=table_fit(request.table, parameters), added_starts=added,
                           agreed_before_added=agreeing, ensemble_sampled=sample, residuals=n,
                           failed_starts=failed_starts(records) + failed_profiles,
                           coupling=request.multi.coupling if request.multi.measurements else None,
                           screened_misfit=self.screened_misfit, first_stage_misfit=self.first_stage_misfit,
                           before_last_misfit=self.before_last_misfit, method=self._method())
        result.parameters.provenance = result.provenance()
        return result


def _best_record(records: list[StartRecord]) -> StartRecord:
    """The record of the lowest misfit (then the best-screened start) among ``records``; a failed
    start counts with the last point where it was finite (screened points always are)."""
    finite = [r for r in records if np.isfinite(r.misfit)] or records
    return min(finite, key=lambda r: (r.misfit, r.start))


def _identifiability_jacobian(problem: Problem, theta: np.ndarray, notes: list[str]) -> np.ndarray:
    """The residuals' Jacobian at the best fit for the identifiability; entries that are not finite
    (a difference across a blow-up) are taken as 0, with a note."""
    scaled_jacobian, _ = jacobian(problem, theta)
    finite = np.isfinite(scaled_jacobian)
    if not finite.all():
        notes.append(f"note: {int(np.count_nonzero(~finite))} entries of the Jacobian at the best fit are not finite "
                     "and were taken as 0 for the identifiability")
        scaled_jacobian = np.where(finite, scaled_jacobian, 0.0)
    return scaled_jacobian


def _extend_if_alone(problem: Problem, engine, records: list[StartRecord], last: tuple[int, int], stage: int,
                     size: tuple[int, int], bars) -> tuple[list[StartRecord], int, int]:
    """If fewer than MIN_AGREEING of the last stage's starts reach the best misfit within the
    ensemble threshold, up to ``last[0]`` more starts run the last stage too (once): those that
    stopped in the latest earlier stage first, each group by misfit. A lone best start thus
    gets its chance to be confirmed, or a better optimum is found, before the fit says it is
    not converged. ``size``: (residuals, coordinates) of the misfit's threshold. Returns the
    records (sorted as ``run_stages`` sorts them), how many starts were added and how many
    agreed before."""
    best = min((r.misfit for r in records if r.stage == stage and not r.failed), default=np.inf)
    agreeing = agreeing_starts(records, stage, best, misfit_threshold(best, *size)) if np.isfinite(best) else 0
    waiting = sorted((r for r in records if r.stage < stage and not r.failed),
                     key=lambda r: (-r.stage, r.misfit, r.start))[:last[0]]
    if agreeing >= MIN_AGREEING or not waiting:
        return records, 0, agreeing
    run_stages(problem, engine, waiting, [(len(waiting), last[1])],
               lambda s, k: bars.stage(s, k, more=True, total=len(waiting)), first_stage=stage)
    records.sort(key=lambda r: (-r.stage, r.misfit, r.start))
    return records, len(waiting), agreeing


def _check_steps(problem: Problem, records, n: int, d: int):
    """``refinement.refine_steps`` at the best start of the latest stage (its misfit sets the
    region's delta chi^2)."""
    best = _best_record([r for r in records if r.stage == records[0].stage and not r.failed] or records)
    return refine_steps(problem.objective, problem.space.to_parameters(best.theta[None, :]),
                        misfit_threshold(best.misfit, n, d) * n)


def resting_notes(tests, rest_forces, bushing: BushingModel) -> list[str]:
    """The fit's notes on the tests that start at rest holding a force (``offsets.held_force``): the
    model starts them there (its ``resting_state``), or cannot hold one and starts them relaxed; and
    on a step or random test whose rest is too short to count (``offsets.short_rest``)."""
    notes = []
    for test, rest in zip(tests, rest_forces):
        if math.isfinite(rest):
            notes.append(f"note: {test.name} holds {rest:+.4g} N at rest before it moves: the {bushing.name} model "
                         + ("starts it there, its elements stuck holding that force" if bushing.resting_state
                            is not None else "holds no force at rest and starts it relaxed"))
        elif bushing.resting_state is not None and test.kind != "sine" and isinstance(test.measurement, Measurement):
            # a sine that starts at a turning point lingers there as a rest would: no note for it
            short = short_rest(test.measurement)
            if short is not None:
                notes.append(f"note: {test.name} starts at {short[0]:+.4g} N but rests only {short[1] * 1e3:.3g} ms "
                             f"before it moves (a held force needs {MIN_REST_SAMPLES} samples and "
                             f"{MIN_REST_S * 1e3:g} ms at rest): the {bushing.name} model starts it relaxed; a record "
                             "that starts with a longer rest starts it holding its force")
    return notes


TEMPERATURE_SPREAD_K = 5.0
"""Tests whose mean temperatures differ by more than this [K] are at different conditions."""


def temperature_notes(tests, bushing: BushingModel) -> list[str]:
    """The fit's notes on the tests that carry the rubber's temperature (``Measurement.temperature_K``):
    a model with a temperature law (``BushingModel.conditions``) runs each at its mean temperature,
    and says so (and where a test's temperature varies by more than TEMPERATURE_SPREAD_K within it,
    that the law takes its mean); a model without one fits them as one device at one condition, and
    says so (more loudly where the tests' temperatures differ by more than TEMPERATURE_SPREAD_K)."""
    carried = [(test.name, test.measurement.temperature_K) for test in tests
               if isinstance(test.measurement, Measurement) and test.measurement.temperature_K is not None]
    if not carried:
        return []
    means = [float(np.mean(t)) for _, t in carried]
    each = "; ".join(f"{name} {mean - 273.15:.4g} degC" for (name, _), mean in zip(carried, means))
    spread = max(means) - min(means)
    if any(field == "temperature_K" for _, field in bushing.conditions):
        notes = [f"note: the {bushing.name} model runs each training test at its temperature ({each})"]
        varying = [name for name, t in carried if float(np.max(t) - np.min(t)) > TEMPERATURE_SPREAD_K]
        if varying:
            notes.append(f"note: the temperature varies by more than {TEMPERATURE_SPREAD_K:g} K within "
                         f"{', '.join(varying)}: the temperature law takes each test's mean")
        return notes
    if spread > TEMPERATURE_SPREAD_K:
        return [f"note: the training tests are at different temperatures ({each}; {spread:.3g} K apart): the "
                f"{bushing.name} model has no temperature law, so it fits them as one device at one condition, "
                "and its figures mix what the temperature changes with what the model misses; add the option "
                "wlf (a temperature law) or fit each temperature's tests on their own"]
    return [f"note: the training tests carry their temperature ({each}): the {bushing.name} model has no "
            "temperature law; its parameters hold at about that temperature"]


def test_fits(tests, noise, parameters: ParameterSet, steps=None) -> list[RigTestFit]:
    """Each test's noise, repeatability (a sine's) and NRMSE at ``parameters``, simulated with
    ``steps`` per sample (per test; default: chosen from the signal)."""
    fits = []
    for test, level, m_steps in zip(tests, noise, steps or [None] * len(tests)):
        m = test.measurement
        predicted = simulate_record(parameters, m, steps_per_sample=m_steps)
        repeats = estimate_repeatability(m.time_s, m.displacement_mm, m.force_N) if test.kind == "sine" else None
        fits.append(RigTestFit(test.name, test.kind, level, nrmse(predicted, m.force_N), repeats, predicted))
    return fits


def table_fit(table: KdynTable | None, parameters: ParameterSet) -> TableFit | None:
    """The table's rows (weight > 0) against the converged characterisation of ``parameters``,
    and how far the fit's fixed-cycle loop is from it (its largest relative |K*| difference):
    a fitted table, or one held out (``compare``)."""
    if table is None:
        return None
    from identification.forward.dynamic_stiffness import (MAX_CYCLES, STEPS_PER_CYCLE, SteadyStateLoop, run_table_rows,
                                                          stiffness_from_sums)
    from identification.fitting.objectives import PreparedTable
    model = parameters.model
    prepared = PreparedTable.of(table, model)
    rows = prepared.rows
    matrix = parameter_matrix([parameters.parameters], model)

    def steady(steps):
        result = run_table_rows(matrix, model, rows, SteadyStateLoop(steps))[0]
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
