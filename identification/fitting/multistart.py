"""The default search: screened space-filling starts, then successive halving of bounded
trust-region least squares.

1. Screening: ``screening`` points of a scrambled Sobol sequence over the box (seeded),
   each simulated once, and for a model with a spring and friction some more whose spring and
   friction come from the data (``identification.fitting.loop_start``); they rank the starts.
2. Successive halving: the best ``starts`` of them each get scipy's bounded trust-region
   least squares (``least_squares(method="trf")``) for a few evaluations; the best fraction
   continue from where they stopped with a larger budget, and so on (``stages``). The last
   stage's starts run to convergence; they are the independent starts whose agreement is
   the convergence evidence (``identification.fitting.fit``).

Why this and not a population method alone: the misfit landscape of the proposed model has
a wide bad basin around the optimum (a local search from most random points stalls at
E3 ~ 1.5e-2 in the old units), and differential evolution or a GA spend most of their
evaluations there; trust-region least squares uses the residuals' structure and reaches the
noise floor from a few screened starts. ``benchmarks/bench_fit_reliability.py`` measures it
against CMA-ES with restarts and the previous default.

The Jacobian is exact by default: the forces' sensitivities to the coordinates, computed with
the forces in one simulation (``identification.forward.parameter_jacobian``); ``Problem(jacobian="difference")``
takes forward differences instead, in one population call of the compiled kernel (the point's
residuals reused from the last evaluation). Each start is one task
of the engine (``identification.fitting.engine``): everything is decided by the seed, so any engine
gives the same bits.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np
from scipy.optimize import least_squares
from scipy.stats import qmc

from identification.fitting.objectives import Objective
from identification.fitting.presets import PAPER_GA
from identification.fitting.search_space import SearchSpace

DIFFERENCE_STEP = 1e-6
COST_TOLERANCE = 1e-6
"""scipy's ``ftol``: a start ends when an accepted step (one whose actual reduction is more than
a quarter of the predicted) lowers chi^2 by less than this fraction of itself. That bounds one
step, not the distance to the minimum, so the measured gap is what justifies it: on the
reliability benchmark's random 1 the best start ends a small fraction of the confidence region's
delta chi^2 above scipy's default 1e-8, the final starts agree either way, and the last stage
takes half the simulations (docs/benchmarks.md, "Least-squares tolerance"): with 1e-8
the final starts crawled along flat valleys."""


JACOBIANS = ("exact", "difference")
"""How the least squares and the identifiability get the residuals' Jacobian: ``exact``, the
forces' sensitivities computed with them (``identification.forward.parameter_jacobian``; a dynamic-stiffness
table's rows by differences), or ``difference``, forward differences of DIFFERENCE_STEP."""


@dataclass(frozen=True)
class Problem:
    """What a worker needs: the objective, the box (picklable) and how the Jacobian is taken
    (``jacobian``, one of JACOBIANS)."""
    objective: Objective
    space: SearchSpace
    jacobian: str = "exact"

    def __post_init__(self):
        if self.jacobian not in JACOBIANS:
            raise ValueError(f"jacobian = {self.jacobian!r}: choose one of {', '.join(JACOBIANS)}")

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        return self.objective.residual_matrix(self.space.to_parameters(theta))

    def residuals_and_jacobian(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The residuals (n,) at one point ``theta`` (d,), the same bits as :meth:`residuals`, and
        their exact Jacobian (n, d) with respect to the coordinates: the parameters' derivatives
        (``SearchSpace.to_parameters_and_seeds``) carried through the simulation. The multi-axis
        tests' and a table's rows by forward differences (one simulation of them per coordinate)."""
        theta = np.asarray(theta, dtype=float)
        matrix, seeds = self.space.to_parameters_and_seeds(theta[None, :])
        residual, derivative = self.objective.residual_jacobian(matrix, seeds)
        residual, derivative = residual[0], derivative[0]
        if self.objective.difference_size:
            rows = slice(residual.size - self.objective.difference_size, residual.size)
            steps = difference_steps(self.space, theta)
            shifted = self.objective.difference_residuals(self.space.to_parameters(theta + np.diag(steps)))
            difference = ((shifted - residual[rows]) / steps[:, None]).T
            derivative[rows] = np.where(np.isnan(derivative[rows]), difference, derivative[rows])
        return residual, derivative

    def misfit(self, theta: np.ndarray) -> np.ndarray:
        with np.errstate(over="ignore"):   # failed candidates: huge by design
            return np.sum(self.residuals(theta) ** 2, axis=1)


@dataclass
class StartRecord:
    """One start's last state: pyPESTO's per-start record."""
    start: int                 # rank of its starting point after screening (0 = best)
    theta: np.ndarray          # coordinates reached
    misfit: float
    stage: int                 # last stage it ran in (0-based)
    evaluations: int           # model simulations it used (Jacobians included)
    message: str = ""
    history: list[float] = field(default_factory=list)   # misfit at the end of each stage
    failed: bool = False
    """Its residuals or Jacobian were not finite (or scipy gave up on them): the start is skipped
    from then on, counted (``failed_starts``), and keeps the last point where it was finite."""


@dataclass(frozen=True)
class AnchoredStarts:
    """``count`` more screened points, the first Sobol points with the coordinates ``values``
    ({coordinate index: value}, from the data: ``identification.fitting.loop_start``) set; the
    first of them also with the coordinates ``first`` set (a nested model's fit whole: its values
    and the added element's neutral ones)."""
    values: dict[int, float]
    count: int
    first: dict[int, float] = field(default_factory=dict)
    kept: bool = False
    """Whether the first of them passes a prefix screening whatever its misfit there (a nested
    model's fit: the point the search must not lose)."""


@dataclass(frozen=True)
class PrefixScreening:
    """Every point screened first on ``problem``, the problem on the start of each test
    (``Objective.prefix``), and only the best ``kept`` fraction (in their order) screened whole."""
    problem: Problem
    kept: float


def screen(problem: Problem, engine, count: int, seed: int, progress=None, anchored: AnchoredStarts | None = None,
           prefix: PrefixScreening | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``count`` scrambled Sobol points over the box and their misfits, with the ``anchored``
    starts added. With ``prefix``, only the points it keeps are returned, with the misfits of
    ``problem``: each point's simulation is its own, so a point's misfit has the same bits however
    it was selected."""
    bounds = problem.space.bounds()
    unit = qmc.Sobol(len(bounds), scramble=True, seed=np.random.default_rng(seed)).random(count)
    theta = bounds[:, 0] + unit * (bounds[:, 1] - bounds[:, 0])
    protected = None
    if anchored is not None and anchored.values and anchored.count:
        protected = count if anchored.kept else None
        extra = theta[np.arange(anchored.count) % count].copy()
        for index, value in anchored.values.items():
            extra[:, index] = value
        for index, value in anchored.first.items():
            extra[0, index] = value
        theta = np.vstack([theta, extra])
        count = len(theta)
    if prefix is not None:
        partial = _misfits(prefix.problem, engine, theta, progress)
        chosen = np.argsort(partial, kind="stable")[:max(1, math.ceil(prefix.kept * count))]
        if protected is not None and protected not in chosen:
            chosen[-1] = protected
        chosen = np.sort(chosen)
        theta = theta[chosen]
    return theta, _misfits(problem, engine, theta, progress)


def _misfits(problem: Problem, engine, theta: np.ndarray, progress=None) -> np.ndarray:
    blocks = [theta[i:i + 256] for i in range(0, len(theta), 256)]
    return np.concatenate(engine.map(_misfit_task, blocks, problem, progress=progress and (
        lambda n: progress(n * 256))))


def genetic_algorithm(problem: Problem, engine, seed: int, progress=None,
                      settings: Mapping[str, float] = PAPER_GA) -> tuple[np.ndarray, np.ndarray]:
    """The paper's GA (pymoo: uniform crossover, polynomial mutation with the given
    probability per coordinate) over the box, ``settings`` as ``presets.PAPER_GA`` names them
    (population, generations, crossover_probability, mutation_probability); returns its final
    population and misfits. Each generation's population is evaluated through the engine."""
    population, generations = settings["population"], settings["generations"]
    crossover_probability, mutation_probability = settings["crossover_probability"], settings["mutation_probability"]
    from pymoo.algorithms.soo.nonconvex.ga import GA
    from pymoo.core.problem import Problem as PymooProblem
    from pymoo.operators.crossover.ux import UniformCrossover
    from pymoo.operators.mutation.pm import PolynomialMutation
    from pymoo.optimize import minimize

    bounds = problem.space.bounds()

    class Identification(PymooProblem):
        def __init__(self):
            super().__init__(n_var=len(bounds), n_obj=1, xl=bounds[:, 0], xu=bounds[:, 1])

        def _evaluate(self, theta, out, *args, **kwargs):
            blocks = [theta[i:i + 64] for i in range(0, len(theta), 64)]
            out["F"] = np.concatenate(engine.map(_misfit_task, blocks, problem))
            if progress:
                progress(len(theta))

    algorithm = GA(pop_size=population, crossover=UniformCrossover(prob=crossover_probability),
                   mutation=PolynomialMutation(prob=1.0, prob_var=mutation_probability), eliminate_duplicates=True)
    result = minimize(Identification(), algorithm, ("n_gen", generations), seed=seed, verbose=False)
    return result.pop.get("X"), result.pop.get("F")[:, 0].copy()


def first_records(theta: np.ndarray, misfits: np.ndarray, count: int) -> list[StartRecord]:
    """The ``count`` best screened points as records of starts that have not run yet."""
    order = np.argsort(misfits, kind="stable")
    return [StartRecord(int(rank), theta[index].copy(), float(misfits[index]), -1, 1)
            for rank, index in enumerate(order[:count])]


def run_stages(problem: Problem, engine, records: list[StartRecord], stages, progress=None,
               first_stage: int = 0) -> list[StartRecord]:
    """Successive halving over ``stages`` (numbered from ``first_stage``): each stage continues
    the best of ``records`` by their misfit so far; returns every record, the last stage's
    first, each group sorted by misfit."""
    records = list(records)
    for stage, (starts, evaluations) in enumerate(stages, start=first_stage):
        # a stage run again (after the objective was refined) continues the starts that ran it;
        # a failed start runs no more
        records.sort(key=lambda r: (r.failed, -(r.stage >= stage), r.misfit, r.start))
        running = [r for r in records[:starts] if not r.failed]
        results = engine.map(_least_squares_task, [(r.theta, evaluations) for r in running], problem,
                             progress=progress and (lambda n, s=stage: progress(s, n)))
        for record, (theta_end, misfit, used, message, failed) in zip(running, results):
            record.evaluations += used
            record.message = message
            if failed:      # skipped from here on, at the best finite point it reached
                record.failed = True
                if misfit < record.misfit:
                    record.theta, record.misfit = theta_end, misfit
                continue
            record.theta, record.misfit, record.stage = theta_end, misfit, stage
            record.history.append(misfit)
    records.sort(key=lambda r: (r.failed, -r.stage, r.misfit, r.start))
    return records


def failed_starts(records: list[StartRecord]) -> int:
    """How many starts failed (their residuals or Jacobian not finite): skipped, not raised."""
    return sum(r.failed for r in records)


def difference_steps(space: SearchSpace, theta: np.ndarray) -> np.ndarray:
    """Forward-difference steps of each coordinate, inwards at the upper bounds."""
    high = space.bounds()[:, 1]
    steps = DIFFERENCE_STEP * np.maximum(1.0, np.abs(theta))
    return np.where(theta + steps > high, -steps, steps)


def jacobian(problem: Problem, theta: np.ndarray, at: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The Jacobian of the residuals (n, d) at ``theta`` and the residuals there: exact
    (:meth:`Problem.residuals_and_jacobian`) or, with ``problem.jacobian == "difference"``, by
    forward differences, stepping inwards at the upper bounds (with the residuals ``at`` if
    already known). A problem without ``jacobian`` (a stand-in that gives residuals only) takes
    differences."""
    if _kind(problem) == "exact":
        residual, derivative = problem.residuals_and_jacobian(theta)
        if exact_usable(derivative):
            return derivative, residual
        return difference_jacobian(problem, theta, residual)
    return difference_jacobian(problem, theta, at)


EXACT_JACOBIAN_LIMIT = 1e100
"""An exact Jacobian with an entry beyond this (residuals in noise units per coordinate; a fit's
are of order 1 to 1e4) is replaced by forward differences at that point: where a Bouc-Wen block's
z crosses 0 with n < 1 the gain's derivative n*|z|^(n-1) is infinite, and a sensitivity carried
through it was seen near the largest double (docs/benchmarks.md, "Figures behind the code's
constants"), finite but too large for the least squares' scaling and SVD, which then fail on
infs. Differences take the secant."""


def exact_usable(derivative: np.ndarray) -> bool:
    """Whether an exact Jacobian's entries are all finite and within EXACT_JACOBIAN_LIMIT."""
    with np.errstate(invalid="ignore"):
        return bool(np.all(np.abs(derivative) <= EXACT_JACOBIAN_LIMIT))


def _kind(problem) -> str:
    return getattr(problem, "jacobian", "difference")


def simulations_per_jacobian(problem: Problem, coordinates: int, known: bool) -> int:
    """Simulations one :func:`jacobian` runs: one with sensitivities (exact), or one per
    coordinate, and one more where the residuals at the point are not ``known`` (difference)."""
    return 1 if _kind(problem) == "exact" else coordinates + (not known)


def difference_jacobian(problem: Problem, theta: np.ndarray,
                        at: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Forward-difference Jacobian of the residuals (n, d) at ``theta``, stepping inwards at
    the upper bounds, and the residuals there (``at`` if already known)."""
    steps = difference_steps(problem.space, theta)
    if at is None:
        rows = problem.residuals(np.vstack([theta[None, :], theta + np.diag(steps)]))
        at, shifted = rows[0], rows[1:]
    else:
        shifted = problem.residuals(theta + np.diag(steps))
    return ((shifted - at) / steps[:, None]).T, at


def _misfit_task(problem: Problem, block: np.ndarray) -> np.ndarray:
    return problem.misfit(block)


class NotFiniteError(ArithmeticError):
    """Residuals or a Jacobian that are not finite: the start (or profile) that met them fails."""


def finite_or_raise(values: np.ndarray, what: str) -> np.ndarray:
    """``values`` if every entry is finite, else NotFiniteError naming ``what``."""
    if not np.all(np.isfinite(values)):
        raise NotFiniteError(f"the {what} are not finite")
    return values


SEARCH_FAILURES = (ValueError, ArithmeticError, np.linalg.LinAlgError)
"""What a least-squares solve raises where the residuals or the Jacobian are not finite (scipy's
ValueError "Residuals are not finite in the initial point", an SVD that does not converge, our
NotFiniteError): a failed start, an ordinary event of a search, never the user's error."""


def _least_squares_task(problem: Problem, item) -> tuple[np.ndarray, float, int, str, bool]:
    """Bounded trust-region least squares from ``theta`` for at most ``evaluations`` residual
    evaluations; returns (theta, misfit, simulations used, scipy's message, failed). A start
    whose residuals or Jacobian are not finite fails (``failed`` True, theta and misfit those
    it started from), not an exception."""
    theta0, evaluations = item
    bounds = problem.space.bounds()
    used = 0
    last: dict = {}
    best = {"theta": np.asarray(theta0, dtype=float), "misfit": math.inf}

    def fun(theta):
        nonlocal used
        used += 1
        residuals = problem.residuals(theta[None, :])[0]
        last["theta"], last["residuals"] = theta.copy(), residuals
        with np.errstate(over="ignore"):
            misfit = float(np.sum(residuals ** 2))
        if misfit < best["misfit"]:
            best["theta"], best["misfit"] = theta.copy(), misfit
        return residuals

    def jac(theta):
        nonlocal used
        known = last["residuals"] if np.array_equal(last.get("theta"), theta) else None
        before = used
        used += simulations_per_jacobian(problem, len(theta), known is not None)
        derivative, _ = jacobian(problem, theta, known)
        if _kind(problem) == "exact" and not exact_usable(derivative):
            used = before + 1 + len(theta)   # the exact one, then differences from its residuals
        return finite_or_raise(derivative, "Jacobian's entries")

    try:
        with np.errstate(over="ignore", invalid="ignore"):   # failed candidates: huge residuals by design
            result = least_squares(fun, np.clip(theta0, bounds[:, 0], bounds[:, 1]), jac=jac,
                                   bounds=(bounds[:, 0], bounds[:, 1]), method="trf", x_scale="jac",
                                   ftol=COST_TOLERANCE, max_nfev=evaluations)
    except SEARCH_FAILURES as exc:
        # the start fails; the best finite point it evaluated (if any) is what it found
        return best["theta"], best["misfit"], used, f"failed: {exc}", True
    misfit = float(2.0 * result.cost)
    if not math.isfinite(misfit):
        return best["theta"], best["misfit"], used, "failed: the misfit is not finite", True
    return result.x, misfit, used, result.message, False
