"""``compare``'s race: every model is screened, and only the models that can still win run the
rest of the least-squares stages.

A model's screening here is the search's global phase and its first, short least-squares stage
(the default preset: 8192 Sobol points, then 128 starts of 10 evaluations). The stages after it
lower that stage's best misfit (chi^2/n over the training data) by some factor. A model whose
first-stage misfit, divided by the largest such factor seen on the project's comparison cases
(``RACE_CLOSING``, with a margin), is still above

- the floor's misfit (``FLOOR_FACTOR`` squared, times ``FitResult.floor_misfit`` where a sine's
  device repeats less than its noise says: a fit whose chi^2/n is above it has a test or table
  above its floor), and,
- where no finished model reaches the floor, the misfit that would give it the lowest BIC
  (the recommendation's measure then),

cannot be recommended (``compare.recommend``), so it stops there and its row says why. The models
are finished in the order of their first-stage misfits, best first, so that the bound is set by
the fits most likely to win. A linear model (Kelvin-Voigt) is fitted outright. A model that runs
on is weighed once more before its last stage, the longest (the default preset: 6 starts of 300
evaluations), by the same rule with the factor the last stage alone was seen to close
(``RACE_CLOSING_LAST``): a model whose middle stage left it far from the finished models stops
there.

One thing the bound does not see: where no model reaches the floor, ``recommend`` first keeps the
models that predict the held-out data within 10 % of the best; a model stopped here is assumed
not to predict held-out data better than one that fits the training data far better.

On a machine's first run the models' compiled modules are what takes longest: they compile one
after another on a thread of this process (:class:`ModulePipeline`) while the workers screen and
fit, each before the step that needs it.
"""
from __future__ import annotations

import pickle
import sys
import threading
import time
from dataclasses import dataclass

import numpy as np

from identification.fitting.fit import fit_linear
from identification.fitting.result import FLOOR_FACTOR, FitResult, information_criterion
from identification.fitting.search import Search, SearchRequest, begin

RACE_CLOSING = 10.0
"""The factor by which the least-squares stages after the first may still lower a model's best
misfit: 2.5 times the largest measured. On the project's five comparison cases, every model
(benchmarks/bench_race.py, 35 fits), the later stages lowered it by 4.08x at most (the proposed
model on the paper's Table 5 tests, from 4.34 to 1.06), and by 2.15x at most over the reliability
benchmark's 12 truths x 3 seeds (benchmarks/bench_fit_reliability.py); with a table in the
training the final misfit may even be a little higher (the last stage runs the table's finer
loop). docs/benchmarks.md, "Racing the models"."""

RACE_CLOSING_LAST = 5.0
"""The factor by which the last least-squares stage alone may still lower a model's best misfit
(the best after every earlier stage over the final): on the project's five comparison cases,
every model (benchmarks/bench_race.py --only stages, 43 fits), it lowered it by 1.11x at most (the
free plate on the membrane mount's sheet and sine, 1.243 to 1.119), 1.03x on the paper's Table 5
(the proposed model, 1.101 to 1.064); 5 is 4.5 times that, and above the 2.15x that every later
stage together closed at most over the reliability benchmark's 36 fits, which bounds the last's
there. docs/benchmarks.md, "Racing the models"."""


AFTER_SCREENING = "after its screening"
BEFORE_LAST_STAGE = "before its last stage"


@dataclass(frozen=True)
class Stopped:
    """A model stopped after its screening (or before its last stage): its best screened misfit
    and first-stage misfit (chi^2/n; and before the last stage), the time its stages took [s], and
    why it cannot win."""
    model: str
    free_parameters: int
    screened_misfit: float
    first_stage_misfit: float
    seconds: float
    reason: str
    before_last_misfit: float | None = None     # where it was stopped before its last stage

    @property
    def when(self) -> str:
        """Where in its search it stopped, in words."""
        return AFTER_SCREENING if self.before_last_misfit is None else BEFORE_LAST_STAGE


def out_of_race(first_stage_misfit: float, free_parameters: int, residuals: int, finished: list[FitResult],
                closing: float | None = None, reached: str = "after its first stage") -> str | None:
    """Why a model whose first least-squares stage reached ``first_stage_misfit`` (chi^2/n, with
    ``free_parameters`` over ``residuals``) cannot be recommended against the ``finished`` fits,
    or None while it can; ``closing`` defaults to ``RACE_CLOSING``. Before the last stage: that
    misfit, ``RACE_CLOSING_LAST`` and ``reached`` = "before its last stage"."""
    closing = RACE_CLOSING if closing is None else closing
    if not finished:
        return None
    least = first_stage_misfit / closing            # the lowest misfit its later stages could reach
    floor = FLOOR_FACTOR ** 2 * finished[0].floor_misfit      # the same training data for every model
    if least <= floor:
        return None
    at_floor = [r for r in finished if r.at_floor]
    if at_floor:
        leader = min(at_floor, key=lambda r: r.misfit)
        return (f"chi^2/n {first_stage_misfit:.4g} {reached}: even lowered {closing:g}x it stays above "
                f"the floor's {floor:.3g}, which {leader.model} reached")
    leader = min(finished, key=lambda r: r.information_criterion)
    if information_criterion(least, free_parameters, residuals) > leader.information_criterion:
        return (f"chi^2/n {first_stage_misfit:.4g} {reached}: even lowered {closing:g}x it stays above "
                f"the floor and its BIC above {leader.model}'s")
    return None


class ModulePipeline:
    """The compiled modules the race will need, compiled (or loaded from the disk cache) one after
    another on a thread of this process while the workers screen and fit: the forward models of
    the searches after the first (whose workers compile its own at once), by one misfit at the
    box's centre (what the workers call, compiled with the same types; on a copy of the problem,
    which the main thread is sending to the workers meanwhile), then the exact Jacobians' modules
    in the order the models will be finished (:meth:`reorder`). A search that asks for a module
    the thread is compiling waits for it (``parameter_jacobian.sensitivity_module``), and numba's
    disk cache gives it to the workers. A module that fails here is left to the search that needs
    it, which compiles it again and raises there."""

    def __init__(self, searches: list[Search]):
        self.forward = list(searches[1:])
        self.jacobians = [s for s in searches if s.jacobian_kind == "exact"]
        self.lock = threading.Lock()
        self.thread = threading.Thread(target=self._run, name="compiled modules", daemon=True)

    def start(self) -> "ModulePipeline":
        self.thread.start()
        return self

    def reorder(self, searches: list[Search]) -> None:
        """The Jacobians still to compile, in the order of ``searches`` (the others dropped)."""
        with self.lock:
            self.jacobians = [s for s in searches if s in self.jacobians]

    def _next(self):
        with self.lock:
            if self.forward:
                return _forward_model_of(self.forward.pop(0))
            if self.jacobians:
                return _jacobian_of(self.jacobians.pop(0))
            return None

    def _run(self) -> None:
        while (job := self._next()) is not None:
            try:
                job()
            except Exception:       # left to the search that needs the module
                pass


def _forward_model_of(search: Search):
    def compile_forward():
        problem = pickle.loads(pickle.dumps(search.problem))
        problem.misfit(np.mean(problem.space.bounds(), axis=1)[None, :])
    return compile_forward


def _jacobian_of(search: Search):
    def compile_jacobian():
        from identification.forward.parameter_jacobian import lane_chunk, sensitivity_module
        sensitivity_module(search.space.bushing, lane_chunk(search.d))
    return compile_jacobian


def race_models(requests: list[SearchRequest], engine, race: bool = True, progress: bool = True,
                on_settled=None) -> tuple[dict[str, FitResult], list[Stopped], dict[str, Search]]:
    """Fit the models of ``requests`` (each with its ensemble left out) on ``engine``: a linear
    model outright, every other screened (the global phase, then the first least-squares stage),
    then, best first-stage misfit first, the stages of those still in the race (every one with
    ``race=False``; weighed again before the last stage), their modules compiled beside
    (:class:`ModulePipeline`). Returns (results by model, the models stopped, the finished
    searches by model: ``Search.with_ensemble`` samples an ensemble later).

    ``on_settled(results, stopped)``, if given, is called each time a model is settled (fitted
    or stopped), with the results and the stopped models so far: ``compare`` writes its files
    there, so that a crash or a signal loses only the model in hand."""
    settled = on_settled if on_settled is not None else (lambda results, stopped: None)
    results: dict[str, FitResult] = {}
    searches: dict[str, Search] = {}
    for request in requests:
        bushing = request.model
        if bushing.linear is not None:
            print(f"fitting {bushing.title} (linear least squares) ...", file=sys.stderr)
            results[bushing.name] = _reported(fit_linear(request, time.perf_counter()))
            settled(results, [])
        else:
            searches[bushing.name] = begin(request, engine, progress, time.perf_counter())
            searches[bushing.name].prepare()
    pipeline = ModulePipeline(list(searches.values())).start()
    for search in searches.values():
        print(f"screening {search.request.model.title} ...", file=sys.stderr)
        misfit = search.screen(compile_beside=False, since=time.perf_counter())
        print(f"  best screened misfit {misfit:.4g} in {search.seconds:.0f} s", file=sys.stderr)
    order = sorted(searches, key=lambda model: searches[model].screened_misfit)
    pipeline.reorder([searches[model] for model in order])
    for model in order:
        search = searches[model]
        print(f"first least-squares stage of {search.request.model.title} ...", file=sys.stderr)
        misfit = search.first_stage()
        print(f"  best misfit {misfit:.4g} ({search.seconds:.0f} s so far)", file=sys.stderr)
    order = sorted(searches, key=lambda model: searches[model].first_stage_misfit)
    stopped = []
    for model in order:
        search = searches[model]
        reason = (out_of_race(search.first_stage_misfit, search.d, search.n, list(results.values())) if race
                  else None)
        before_last = None      # weighed again before its last stage where it ran on
        if reason is None:
            print(f"fitting {search.request.model.title} ...", file=sys.stderr)
            if race:
                before_last = search.early_stages()
                reason = out_of_race(before_last, search.d, search.n, list(results.values()), RACE_CLOSING_LAST,
                                     BEFORE_LAST_STAGE)
        if reason is not None:
            stopped.append(Stopped(model, search.d, search.screened_misfit, search.first_stage_misfit,
                                   search.seconds, reason, before_last))
            del searches[model]
            print(f"{search.request.model.title}: out of the race ({reason})", file=sys.stderr)
            settled(results, stopped)
            continue
        results[model] = _reported(search.finish(ensemble=False))
        settled(results, stopped)
    return results, stopped, searches


def _reported(result: FitResult) -> FitResult:
    state = "converged" if result.converged else f"WARNING: {result.warning}"
    print(f"  misfit {result.misfit:.4f} in {result.seconds:.0f} s; {state}", file=sys.stderr)
    return result
