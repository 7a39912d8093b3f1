"""How sure a fit is: the parameter sets the data cannot tell apart, and which combinations
the tests leave undetermined.

Threshold. The misfit is chi^2/n with the residuals in units of the noise level
(``objectives``), so a parameter set whose chi^2 exceeds the best by less than

    delta_chi2 = s^2 * chi2.ppf(0.95, d)

is inside the 95 % joint confidence region of the d identifiable parameters (the
likelihood-ratio region; pyPESTO's ensemble cutoff). s^2 = max(1, chi^2_best/(n - d))
widens it where the fit stays above the noise floor (model error, or noise the estimator
missed), as lmfit scales its covariance by the reduced chi-square.

Members, all within the threshold by their true misfit:
(1) the distinct end points of the starts (other basins of equal fit);
(2) the ends of prediction profiles (Kreutz et al., 2012): for each probe (PROBES), the
    parameter sets that make its measure largest and smallest, found by bounded least squares on
    chi^2/2 - w*g, w set so that chi^2 ends near the region's edge. The measures: the rms force
    of tests at the corners of the design's candidates (a 4 mm sine at 40 Hz and at 5 Hz, a 4 mm
    step with a 0.05 s rise), and the energy a 2 mm sine at 1 Hz dissipates (its loop's area):
    at low frequency the loop's width is what the paper's two tests leave least determined, and
    rms forces alone missed it (reliability benchmark, random 9 seed 1: the truth inside the
    region at 0.005 of its delta chi^2, yet outside the band on 13-18 % of the samples of the
    1 Hz sines and the random test; with the energy probe, on none).
    The region's valleys curve: for Table 5 the truth sat at delta chi^2 = 13 (inside 24.9) while
    the straight line to it rose to 42, so no sample around the best fit and no straight push
    reaches it, but a least-squares path along the valley does. With the fit's exact Jacobian
    (``multistart.Problem.jacobian``) its least squares take the exact Jacobian of the fit's
    residuals and the probe's exact gradient (:class:`ProbeMeasure`), else scipy's differences;
(3) MEMBERS posterior draws (emcee, WALKERS walkers, or 2*(d + 1) for d > 15 parameters, from a
    tiny ball around the best fit, STEPS steps of which the first BURN_IN are discarded, differential-evolution and snooker moves as
    emcee recommends for curved posteriors; posterior exp(-chi^2/(2 s^2)), flat over the box),
    each pushed along the ray from the best fit to the farthest of PUSH times its distance
    still inside: draws sit at chi^2 about d above the best, and their envelope is a pointwise
    band, narrower than the region.
Measured on the 3 mm sines of Table 5 (beyond the 2 mm training amplitude, best fit 6-8 % off):
the draws' envelope held the truth on 61-83 % of the samples, with the pushes 71-100 %, with
the profiles 100 % (3 seeds). emcee's acceptance fraction and autocorrelation time are reported
with the fit (``SamplerReport``); the band's coverage over many bushings is measured, not
assumed: ``benchmarks/bench_fit_reliability.py``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

CONFIDENCE = 0.95
DISTINCT = 1e-4
"""Members closer than this (in coordinates scaled by the box's size) are one."""
WALKERS, STEPS, BURN_IN, MEMBERS = 32, 200, 100, 100
"""200 steps: the 100 kept are about five autocorrelation times (about 20 steps on the paper's
tests); with 300 the sampler took 34 s of the 118 s fit of the reliability benchmark's most
expensive bushing (random 1). WALKERS is the least number of walkers: a model of more than 15
free parameters takes more (:func:`walkers_for`)."""


def walkers_for(dimensions: int) -> int:
    """The walkers for ``dimensions`` free parameters: WALKERS, or 2*(d + 1) where that is more.
    emcee's differential-evolution moves (red-blue moves) refuse fewer than twice the dimensions,
    and its start check wants more walkers than dimensions; 32 covers up to 15 parameters, so the
    smaller models sample as before."""
    return max(WALKERS, 2 * (dimensions + 1))


class SamplingFailed(RuntimeError):
    """The posterior could not be sampled from its start (a degenerate ball of walkers, or emcee
    refusing the moves): the ensemble keeps its profiles and start end points only."""
PUSH = (1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0)
PROBES = (("sine", 4.0, 40.0, 0.25, "rms"), ("sine", 4.0, 5.0, 0.4, "rms"), ("step", 4.0, 0.05, 1.0, "rms"),
          ("sine", 2.0, 1.0, 1.0, "energy"))
"""Probes (kind, amplitude mm, frequency Hz or rise time s, duration s, measure) whose measure the
ensemble's extreme members bound: "rms" the rms force [N], "energy" the work done on the bushing,
the integral of F dx [N.mm = mJ] (over whole cycles of a sine: the energy it dissipates)."""
PROFILE_TARGET = 0.9          # aim at this fraction of delta_chi2
PROFILE_ROUNDS = 3            # least-squares solves per probe and sign, each correcting the weight
PROFILE_EVALUATIONS = 12      # residual evaluations per solve
PROFILE_OFFSET = 100.0        # c of the reward residual
START_BALL = 1e-4
"""The walkers' initial spread around the best fit, as a fraction of the box's size."""
LOAD_SHOWN = 0.3
"""A coordinate loads a direction when its component is at least this (unit vectors)."""


def threshold_scale(best_misfit: float, residuals: int, parameters: int) -> float:
    """s^2 = max(1, chi^2_best/(n - d)): the noise variance's correction above the floor."""
    return max(1.0, best_misfit * residuals / max(1, residuals - parameters))


def misfit_threshold(best_misfit: float, residuals: int, parameters: int) -> float:
    """The largest misfit increase (chi^2/n units) within the confidence region."""
    return threshold_scale(best_misfit, residuals, parameters) * chi2.ppf(CONFIDENCE, parameters) / residuals


@dataclass(frozen=True)
class SamplerReport:
    """How the posterior sampling went (emcee's own diagnostics)."""
    acceptance: float              # mean acceptance fraction of the walkers (0.2-0.5 is healthy)
    autocorrelation_steps: float   # largest integrated autocorrelation time estimate [steps]
    kept_steps: int                # steps after the burn-in

    def format(self) -> str:
        return (f"posterior sampling: acceptance {self.acceptance:.2f}, autocorrelation time about "
                f"{self.autocorrelation_steps:.0f} steps of the {self.kept_steps} kept")


@dataclass
class Identifiability:
    """Singular values of the residual Jacobian (noise units, per coordinate) at the best fit."""
    names: tuple[str, ...]
    singular_values: np.ndarray        # descending
    directions: np.ndarray             # (d, d): row j is the unit direction of singular value j
    half_widths: np.ndarray            # how far along each direction chi^2 grows by delta_chi2 (linearised)
    threshold_chi2: float              # delta_chi2

    def weakest(self, count: int = 3) -> list[dict]:
        """The ``count`` least determined directions, weakest first: singular value, linearised
        half-width (coordinate units: decades for stiffnesses, dampings, gains, time
        constants) and the coordinates that load them."""
        out = []
        for j in range(len(self.singular_values) - 1, max(-1, len(self.singular_values) - 1 - count), -1):
            v = self.directions[j]
            loads = {self.names[i]: float(v[i]) for i in np.argsort(-np.abs(v)) if abs(v[i]) >= LOAD_SHOWN}
            out.append({"singular_value": float(self.singular_values[j]), "half_width": float(self.half_widths[j]),
                        "loads": loads})
        return out

    def format(self) -> str:
        relative = self.singular_values / self.singular_values[0]
        lines = ["identifiability (singular values of the scaled residual Jacobian, relative to the largest): "
                 + " ".join(f"{value:.1e}" for value in relative)]
        for entry in self.weakest():
            loads = ", ".join(f"{name} {value:+.2f}" for name, value in entry["loads"].items())
            lines.append(f"  weak direction, singular value {entry['singular_value']:.3g}, +-{entry['half_width']:.3g} "
                         f"within the threshold: {loads}")
        return "\n".join(lines)


def identifiability(jacobian: np.ndarray, names, threshold_chi2: float) -> Identifiability:
    """From the Jacobian of the residuals in noise units (n, d) and delta_chi2."""
    _, values, directions = np.linalg.svd(jacobian, full_matrices=False)
    with np.errstate(divide="ignore"):
        half = np.where(values > 0, math.sqrt(threshold_chi2) / values, np.inf)
    return Identifiability(tuple(names), values, directions, half, threshold_chi2)


def posterior_samples(problem, best: np.ndarray, seed: int, scale: float = 1.0):
    """MEMBERS draws (coordinates) from the posterior exp(-chi^2/(2 scale)) and their misfits,
    and the sampler's diagnostics; see the module docstring (scale: s^2)."""
    import emcee
    bounds = problem.space.bounds()
    n = problem.objective.size

    def log_probability(thetas):
        thetas = np.atleast_2d(thetas)
        inside = problem.space.inside(thetas)
        out = np.full(len(thetas), -np.inf)
        if inside.any():
            misfits = problem.misfit(thetas[inside])
            # a misfit that is not finite is a draw the posterior gives no weight (never NaN,
            # which emcee refuses)
            out[inside] = np.where(np.isfinite(misfits), -0.5 * n * misfits / scale, -np.inf)
        return out

    rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(2)[1])
    span = bounds[:, 1] - bounds[:, 0]
    walkers = walkers_for(len(best))
    start = np.clip(best + START_BALL * span * rng.standard_normal((walkers, len(best))), bounds[:, 0], bounds[:, 1])
    moves = [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
    sampler = emcee.EnsembleSampler(walkers, len(best), log_probability, vectorize=True, moves=moves)
    sampler.random_state = np.random.RandomState(int(rng.integers(2 ** 31))).get_state()
    try:
        sampler.run_mcmc(start, STEPS, progress=False)
    except (ValueError, RuntimeError) as error:     # emcee's start check and its moves' refusals
        raise SamplingFailed(f"the posterior could not be sampled with {walkers} walkers in {len(best)} "
                             f"dimensions from a ball around the best fit: {error}") from error
    chain = sampler.get_chain(discard=BURN_IN, flat=True)
    misfit = -2.0 * scale * sampler.get_log_prob(discard=BURN_IN, flat=True) / n
    chosen = np.sort(rng.choice(len(chain), size=min(MEMBERS, len(chain)), replace=False))
    autocorrelation = float(np.max(sampler.get_autocorr_time(discard=BURN_IN, quiet=True, tol=0)))
    report = SamplerReport(float(np.mean(sampler.acceptance_fraction)), autocorrelation, STEPS - BURN_IN)
    return chain[chosen], misfit[chosen], report


def push_to_boundary(problem, best: np.ndarray, draws: np.ndarray, limit: float) -> tuple[np.ndarray, np.ndarray]:
    """Each draw moved along the ray from ``best`` to the farthest of PUSH times its distance
    whose misfit is within ``limit`` (clipped to the box; the draw itself if none is), and the
    misfits there. One population call of len(draws) x len(PUSH) candidates."""
    bounds = problem.space.bounds()
    factors = np.asarray(PUSH)
    rays = best + factors[None, :, None] * (draws - best)[:, None, :]
    rays = np.clip(rays, bounds[:, 0], bounds[:, 1])
    misfits = problem.misfit(rays.reshape(-1, len(best))).reshape(len(draws), len(factors))
    pushed, pushed_misfits = draws.copy(), np.full(len(draws), np.inf)
    for i in range(len(draws)):
        within = np.flatnonzero(misfits[i] <= limit)
        if within.size:
            pushed[i], pushed_misfits[i] = rays[i, within[-1]], misfits[i, within[-1]]
    return pushed, pushed_misfits


@dataclass(frozen=True)
class ProfileProblem:
    """What a worker needs to find the extreme members of the probes (picklable)."""
    problem: object                  # multistart.Problem
    best: np.ndarray
    best_misfit: float
    limit: float                     # misfit within the region
    ident: Identifiability


def profile_extremes(problem, best: np.ndarray, best_misfit: float, ident: Identifiability, limit: float,
                     engine) -> tuple[np.ndarray, np.ndarray, int]:
    """For each probe and both signs, the member within the region whose probe measure is
    largest or smallest (a prediction profile's end, Kreutz et al.
    2012), one task each; returns their coordinates and misfits (those found), and how many
    profiles failed (residuals, Jacobian or probe not finite: skipped, what they had found kept)."""
    shared = ProfileProblem(problem, best, best_misfit, limit, ident)
    items = [(probe, sign) for probe in PROBES for sign in (1.0, -1.0)]
    results = engine.map(_profile_task, items, shared, chunk_size=1)
    failed = sum(failure for _, failure in results)
    found = [kept for kept, _ in results if kept is not None]
    if not found:
        return np.empty((0, len(best))), np.empty(0), failed
    return np.array([theta for theta, _ in found]), np.array([misfit for _, misfit in found]), failed


class ProbeMeasure:
    """A probe's measure (PROBES: the rms force [N] of a sine or step, or the energy [N*mm] a sine
    dissipates) as a function of the coordinates, and its exact gradient."""

    def __init__(self, space, kind: str, amplitude: float, rate: float, duration: float, measure: str):
        from identification.forward.input_path import prepare_input
        from identification.measured.signals import Sine, Step, sample_times
        self.space, self.measure = space, measure
        protocol = Sine(amplitude, rate, duration) if kind == "sine" else Step(amplitude, rate, duration)
        t = sample_times(duration, 1000.0)
        self.driven = prepare_input(t, *protocol.signals(t), decimate_holds=True)
        self.weights = np.diff(np.append(self.driven.sample_index, t.size))
        self.displacement = self.driven.displacement_mm[self.driven.output_index]

    def of_forces(self, forces: np.ndarray) -> np.ndarray:
        """The measure of (P, samples) forces, (P,)."""
        if self.measure == "energy":   # trapezoidal integral of F dx over the samples
            return np.sum(0.5 * (forces[:, 1:] + forces[:, :-1]) * np.diff(self.displacement), axis=1)
        return np.sqrt(np.average(forces ** 2, axis=1, weights=self.weights))

    def values(self, thetas: np.ndarray) -> np.ndarray:
        """The measure at each row of (P, d) coordinates, (P,)."""
        from identification.forward.simulate import simulate_driven
        space = self.space
        return self.of_forces(simulate_driven(space.to_parameters(np.atleast_2d(thetas)), self.driven,
                                              model=space.bushing))

    def gradient(self, theta: np.ndarray) -> tuple[float, np.ndarray]:
        """The measure at one point (d,) and its gradient (d,): the forces' sensitivities
        (``parameter_jacobian``) through the measure (linear for the energy; d rms = average(w F dF)/rms)."""
        from identification.forward.parameter_jacobian import population_sensitivities
        driven = self.driven
        matrix, seeds = self.space.to_parameters_and_seeds(np.asarray(theta, dtype=float)[None, :])
        forces, sensitivities = population_sensitivities(matrix, seeds, driven, model=self.space.bushing)
        value = float(self.of_forces(forces)[0])
        if self.measure == "energy":
            step = np.diff(self.displacement)[:, None]
            return value, np.sum(0.5 * (sensitivities[0, 1:] + sensitivities[0, :-1]) * step, axis=0)
        return value, np.average(forces[0][:, None] * sensitivities[0], axis=0, weights=self.weights) / value


def _profile_task(shared: ProfileProblem, item):
    """(the profile's end, whether it failed): :func:`_profile`, with residuals, a Jacobian or a
    probe measure that are not finite (a solve pushed where the model blows up) a failed
    profile, counted and skipped, never an exception; what it kept before stays."""
    from identification.fitting.multistart import SEARCH_FAILURES
    found = []
    try:
        return _profile(shared, item, found), False
    except SEARCH_FAILURES:
        return (found[-1] if found else None), True


def _profile(shared: ProfileProblem, item, found: list):
    """Maximise sign*g, g = the probe's measure relative to the best fit's, keeping chi^2 near
    the region's edge: bounded least squares on the residuals [r*sqrt(n), c - (w/c)*sign*g],
    whose cost is chi^2/2 - w*sign*g + const (c large). w starts where the linearisation puts the
    optimum at PROFILE_TARGET x delta_chi2 and is corrected by the chi^2 each solve reaches; the
    farthest solution inside the region is kept (None if none is; each one kept is appended to
    ``found`` as well). Raises NotFiniteError where the probe's measure or gradient at the best
    fit, or a Jacobian, is not finite."""
    from scipy.optimize import least_squares

    from identification.fitting.multistart import NotFiniteError, difference_steps, finite_or_raise
    from identification.fitting.multistart import jacobian as residual_jacobian

    (kind, amplitude, rate, duration, measure), sign = item
    problem, best, ident = shared.problem, shared.best, shared.ident
    space, n = problem.space, problem.objective.size
    probe = ProbeMeasure(space, kind, amplitude, rate, duration, measure)
    probe_measure, probe_gradient = probe.values, probe.gradient

    bounds = space.bounds()
    exact = problem.jacobian == "exact"
    if exact:
        value, gradient = probe_gradient(best)
        values = np.array([value])
        if not (np.isfinite(value) and np.all(np.isfinite(gradient))):
            raise NotFiniteError("the probe's measure or its gradient at the best fit is not finite")
        if value <= 0:
            return None
        gradient = gradient / value                                      # of g = rms/rms_best - 1
    else:
        steps = difference_steps(space, best)
        values = finite_or_raise(probe_measure(np.vstack([best, best + np.diag(steps)])), "probe's measures")
        if values[0] <= 0:
            return None
        gradient = (values[1:] - values[0]) / steps / values[0]         # of g = rms/rms_best - 1
    smallest = 1e-12 * ident.singular_values[0]
    whitened = (ident.directions @ gradient) / np.maximum(ident.singular_values, smallest)
    target = PROFILE_TARGET * ident.threshold_chi2
    weight = math.sqrt(target) / max(float(np.linalg.norm(whitened)), 1e-300)
    c = PROFILE_OFFSET

    def residuals(theta):
        with np.errstate(over="ignore", invalid="ignore"):
            g = probe_measure(theta)[0] / values[0] - 1.0
        reward = c - (weight / c) * sign * g if np.isfinite(g) else c + 1e3
        return np.append(problem.residuals(theta[None, :])[0] * math.sqrt(n), reward)

    def jacobian(theta):
        """The exact Jacobian of ``residuals`` (the fit's, then the reward's row)."""
        fit_rows, _ = residual_jacobian(problem, theta)      # exact, or differences where it diverges
        value, gradient = probe_gradient(theta)
        finite = np.isfinite(value) and np.all(np.isfinite(gradient))   # else the reward is the constant c + 1e3
        reward = -(weight / c) * sign * gradient / values[0] if finite else np.zeros_like(gradient)
        return finite_or_raise(np.vstack([fit_rows * math.sqrt(n), reward[None, :]]), "profile's Jacobian entries")

    theta, kept = best.copy(), None
    for _ in range(PROFILE_ROUNDS):
        if not math.isfinite(weight):   # a solve that barely moved chi^2 asks for an infinite push
            break
        with np.errstate(over="ignore", invalid="ignore"):
            result = least_squares(residuals, theta, jac=jacobian if exact else "2-point",
                                   bounds=(bounds[:, 0], bounds[:, 1]), method="trf",
                                   x_scale="jac", max_nfev=PROFILE_EVALUATIONS)
        misfit = float(problem.misfit(result.x[None, :])[0])
        reached = (misfit - shared.best_misfit) * n
        if misfit <= shared.limit:
            kept, theta = (result.x, misfit), result.x
            found.append(kept)
        if not np.isfinite(reached) or reached <= 0:
            break
        weight *= math.sqrt(target / reached)    # delta chi^2 grows with w^2 (linearised)
    return kept


def select_members(best: np.ndarray, ends: list[tuple[np.ndarray, float]], samples: np.ndarray,
                   sample_misfits: np.ndarray, limit: float, bounds: np.ndarray) -> list[np.ndarray]:
    """The ensemble's coordinates, best first: distinct start end points and (pushed)
    posterior draws whose misfit is within ``limit``."""
    span = bounds[:, 1] - bounds[:, 0]
    members = [best]
    for theta, misfit in [*ends, *zip(samples, sample_misfits)]:
        if misfit <= limit and all(np.linalg.norm((theta - m) / span) >= DISTINCT for m in members):
            members.append(theta)
    return members
