"""Fit a model's parameters: global search in the normalised space, then a local polish.

``fit(objective, model="proposed") -> FitResult``; the baselines ``spencer`` and
``bouc_wen`` go the same way in their own spaces, ``kelvin_voigt`` by linear least squares
(:func:`fit_kelvin_voigt`). The ``default`` preset runs scipy's differential evolution
with the whole population evaluated in one compiled call (``vectorized=True``); the
``paper`` preset runs the paper's genetic algorithm (population 300, 200 generations,
uniform crossover with probability 0.8, mutation probability 0.05 per coordinate) from
pymoo. Both then polish with scipy's bounded ``least_squares`` on the residuals whose sum of
squares is E3, from the best mutually distant candidates of the final population. The paper's constraints beta1 + gamma1 > 0 and beta2 - gamma2 > 0 are
a penalty (an infeasible candidate scores 1e3 + its violation, worse than any feasible one);
A >= 1 and beta >= 0 are bounds (``search_space``).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import differential_evolution, least_squares

from fmu_src.bushing_models import get_model
from identification.compiled_core import parameter_matrix
from identification.objectives import Objective
from identification.search_space import KelvinVoigtFit, SearchSpace

PRESETS = {
    # popsize is scipy's multiplier: 15 x 14 coordinates = 210 candidates per generation.
    # rand1bin with dithered mutation explores more than scipy's best1bin: on the synthetic
    # Table 5 tests it reached the noise floor for 3 of 3 seeds, best1bin for 1 of 3.
    "default": {"popsize": 15, "maxiter": 100, "strategy": "rand1bin", "mutation": (0.5, 1.0),
                "recombination": 0.9},
    # The paper's GA (VisualDOC): 300 x 200 = 60,000 evaluations. "Probability of mutation 0.05"
    # is read per coordinate (polynomial mutation), every individual being a candidate for it.
    "paper": {"popsize": 300, "maxiter": 200, "crossover_probability": 0.8, "mutation_probability": 0.05},
}
INFEASIBLE = 1e3
POLISH_STARTS = 6


@dataclass
class FitResult:
    parameters: dict[str, float]          # the model's, paper units, alpha = 1 representative
    objective: float                      # E3 (dimensionless, see objectives)
    terms: dict[str, float]
    evaluations: int
    seconds: float
    preset: str
    seed: int
    space: SearchSpace | None   # None for the linear Kelvin-Voigt fit
    history: list[float] = field(default_factory=list)  # best E3 after each generation
    search_objective: float = float("nan")  # the global search's best E3, before the polish
    model: str = "proposed"

    def provenance(self) -> dict:
        if self.model == "kelvin_voigt":
            return {"method": "linear least squares F = k*x + c*v on the sine (and random) tests",
                    "objective_E3": self.objective, "terms": self.terms, "seconds": round(self.seconds, 2)}
        search = ("the paper's GA (pymoo)" if self.preset == "paper" else "differential evolution (rand1bin)")
        return {"method": f"{search} + least_squares polish from the best {POLISH_STARTS} distinct "
                          f"candidates (preset {self.preset!r})",
                "seed": self.seed, "objective_E3": self.objective, "global_search_E3": self.search_objective,
                "terms": self.terms,
                "evaluations": self.evaluations, "seconds": round(self.seconds, 2),
                "search_space": {"k_ref_N_per_mm": self.space.k_ref, "c_ref_Ns_per_mm": self.space.c_ref,
                                 "F_ref_N": self.space.F_ref},
                "note": ("alpha = 1 in every Bouc-Wen block: the (alpha, A, beta, gamma) redundancy "
                         "(search_space.rescale_hysteresis gives the equivalent sets)" if self.space.normalise
                         else "searched without normalisation: alpha free (redundant)")}


def fit(objective: Objective, preset: str = "default", seed: int = 0, progress: bool = True,
        space: SearchSpace | None = None, popsize: int | None = None, maxiter: int | None = None,
        model: str = "proposed") -> FitResult:
    """Identify the parameters of ``model`` minimising ``objective``; ``popsize``/``maxiter``
    override the preset."""
    model = get_model(model).name
    if model == "kelvin_voigt":
        return fit_kelvin_voigt(objective)
    if preset not in PRESETS:
        raise ValueError(f"unknown preset {preset!r}; choose one of {', '.join(PRESETS)}")
    settings = dict(PRESETS[preset])
    settings.update({k: v for k, v in (("popsize", popsize), ("maxiter", maxiter)) if v is not None})
    space = space or SearchSpace.from_measurements(objective.sines, model=model)
    bounds = space.bounds()
    evaluations = 0
    history: list[float] = []

    def penalised(theta: np.ndarray) -> np.ndarray:
        nonlocal evaluations
        theta = np.atleast_2d(theta)
        evaluations += theta.shape[0]
        violation = space.constraint_violation(theta)
        values = np.full(theta.shape[0], np.inf)
        feasible = violation == 0.0
        if feasible.any():
            values[feasible] = objective(space.to_parameters(theta[feasible]))
        values[~feasible] = INFEASIBLE + violation[~feasible]
        return values

    bar = _progress_bar(settings["maxiter"], progress)
    started = time.perf_counter()

    def on_generation(best_value):
        history.append(float(best_value))
        bar.set_postfix_str(f"E3 {best_value:.3e}, {evaluations} evaluations")
        bar.update(1)

    if preset == "paper":
        population, energies = _genetic_algorithm(penalised, space, bounds, settings, seed, on_generation)
    else:
        search = differential_evolution(
            lambda columns: penalised(columns.T), bounds, vectorized=True, updating="deferred",
            popsize=settings["popsize"], maxiter=settings["maxiter"], strategy=settings["strategy"],
            mutation=settings["mutation"], recombination=settings["recombination"], seed=seed,
            polish=False, init="sobol", tol=1e-8, callback=_de_callback(on_generation))
        population, energies = search.population, search.population_energies
    bar.close()

    # The polish does much of the work: run it from the best few mutually distant candidates
    # of the final population (differential evolution can settle in one basin); keep the best.
    starts = _diverse_starts(population, energies, bounds, POLISH_STARTS)
    best_index = int(np.argmin(energies))
    best, best_value = population[best_index], float(energies[best_index])
    search_value = best_value
    for start in starts:
        polished, value, used = _polish(objective, space, start, bounds)
        evaluations += used
        if value < best_value:
            best, best_value = polished, value
    matrix = space.to_parameters(best)
    terms = {name: float(values[0]) for name, values in objective.terms(matrix).items()}
    parameters = dict(zip(space.bushing.parameter_names, map(float, space.to_model_parameters(best)[0])))
    return FitResult(parameters, float(objective(matrix)[0]), terms, evaluations, time.perf_counter() - started,
                     preset, seed, space, history, search_value, space.model)


def fit_kelvin_voigt(objective: Objective) -> FitResult:
    """F = k*x + c*v by linear least squares on the sine and random tests (no optimizer; the
    step test, dominated by relaxation a linear spring cannot show, is left out). E3 is
    reported on all tests, as for the other models."""
    started = time.perf_counter()
    line = KelvinVoigtFit.fit([*objective.sines, *objective.randoms])
    parameters = {"k": line.k, "c": line.c, "preload": 0.0}
    matrix = parameter_matrix([get_model("kelvin_voigt").core_parameters(parameters)])
    terms = {name: float(values[0]) for name, values in objective.terms(matrix).items()}
    return FitResult(parameters, float(objective(matrix)[0]), terms, 1, time.perf_counter() - started,
                     "linear", 0, None, model="kelvin_voigt")


def _de_callback(on_generation):
    # scipy hands the OptimizeResult only to a callback whose parameter has this exact name.
    def callback(intermediate_result):
        on_generation(intermediate_result.fun)
    return callback


def _genetic_algorithm(penalised, space, bounds, settings, seed, on_generation):
    """The paper's GA with pymoo; returns the final population and its objective values."""
    from pymoo.algorithms.soo.nonconvex.ga import GA
    from pymoo.core.callback import Callback
    from pymoo.core.problem import Problem
    from pymoo.operators.crossover.ux import UniformCrossover
    from pymoo.operators.mutation.pm import PolynomialMutation
    from pymoo.optimize import minimize

    constraints = space.constraint_matrix()

    class Identification(Problem):
        def __init__(self):
            super().__init__(n_var=bounds.shape[0], n_obj=1, n_ieq_constr=constraints.shape[0],
                             xl=bounds[:, 0], xu=bounds[:, 1])

        def _evaluate(self, theta, out, *args, **kwargs):
            # pymoo handles the constraints itself (feasible first): g <= 0 is feasible.
            out["F"] = np.minimum(penalised(theta), INFEASIBLE)
            out["G"] = -(theta @ constraints.T)

    class Progress(Callback):
        def notify(self, algorithm):
            on_generation(float(algorithm.opt.get("F").min()))

    algorithm = GA(pop_size=settings["popsize"], crossover=UniformCrossover(prob=settings["crossover_probability"]),
                   mutation=PolynomialMutation(prob=1.0, prob_var=settings["mutation_probability"]),
                   eliminate_duplicates=True)
    result = minimize(Identification(), algorithm, ("n_gen", settings["maxiter"]), seed=seed,
                      callback=Progress(), verbose=False)
    population = result.pop.get("X")
    energies = result.pop.get("F")[:, 0].copy()
    energies[result.pop.get("CV")[:, 0] > 0.0] = np.inf
    return population, energies


def _diverse_starts(population, energies, bounds, count, min_distance=0.1):
    """The best candidates that are at least ``min_distance`` apart (in coordinates scaled by
    the bound ranges): the best few of a population often sit in one basin."""
    scaled = (population - bounds[:, 0]) / (bounds[:, 1] - bounds[:, 0])
    chosen: list[int] = []
    for i in np.argsort(energies):
        if not np.isfinite(energies[i]) or energies[i] >= INFEASIBLE:
            break
        if all(np.linalg.norm(scaled[i] - scaled[j]) >= min_distance for j in chosen):
            chosen.append(int(i))
            if len(chosen) == count:
                break
    return [population[i] for i in chosen]


def _polish(objective: Objective, space: SearchSpace, start: np.ndarray, bounds: np.ndarray):
    """Bounded least squares from ``start``; the forward-difference Jacobian is one population
    call (the point and its 14 perturbations). Returns (coordinates, E3, evaluations)."""
    low, high = bounds[:, 0], bounds[:, 1]
    evaluations = 0

    def residuals_of(theta_rows):
        nonlocal evaluations
        evaluations += len(theta_rows)
        return objective.residual_matrix(space.to_parameters(theta_rows))

    def fun(theta):
        return residuals_of(theta[None, :])[0]

    def jac(theta):
        steps = 1e-6 * np.maximum(1.0, np.abs(theta))
        steps = np.where(theta + steps > high, -steps, steps)  # stay inside the bounds
        stencil = theta + np.diag(steps)
        rows = residuals_of(np.vstack([theta[None, :], stencil]))
        return ((rows[1:] - rows[0]) / steps[:, None]).T

    result = least_squares(fun, np.clip(start, low, high), jac=jac, bounds=(low, high), method="trf",
                           x_scale="jac", max_nfev=200)
    if space.constraint_violation(result.x)[0] > 0.0:
        return result.x, np.inf, evaluations
    return result.x, 2.0 * result.cost, evaluations


def _progress_bar(total: int, enabled: bool):
    from tqdm import tqdm
    return tqdm(total=total, desc="generations", unit="gen", disable=not enabled, leave=False)
