"""How sure a fit is: the parameter sets the data cannot tell apart, and which combinations
the tests leave undetermined.

Threshold. The misfit is chi^2/n with the residuals in units of the noise level
(``objectives``), so a parameter set whose chi^2 exceeds the best by less than

    delta_chi2 = s^2 * chi2.ppf(0.95, d)

is inside the 95 % joint confidence region of the d identifiable parameters (the
likelihood-ratio region; pyPESTO's ensemble cutoff). s^2 = max(1, chi^2_best/(n - d))
widens it where the fit stays above the noise floor (model error, or noise the estimator
missed), as lmfit scales its covariance by the reduced chi-square.

Members. (1) the distinct end points of the starts within the threshold (other basins of
equal fit); (2) MEMBERS directions drawn from the posterior exp(-chi^2/(2 s^2)) with a flat
prior over the box, sampled by emcee's ensemble sampler (WALKERS walkers started in a tiny
ball around the best fit, STEPS steps of which the first BURN_IN are discarded;
differential-evolution moves, 80 %, and snooker moves, 20 %, as emcee recommends for curved
posteriors), each pushed outwards along the ray from the best fit to the farthest of the
points at PUSH times its distance that is still within the threshold.

Why pushed: the envelope of posterior draws is a pointwise band. Draws sit where the
posterior's mass is, at chi^2 about d above the best, inside the 95 % region, and their
envelope missed the truth on up to 30 % of the samples of a case beyond the training
amplitude where the truth itself was well inside the region. Pushed to the region's boundary,
along the directions the posterior favours, they span the region, which is what a band must
do to hold every parameter set the tests cannot exclude. Every member is within the threshold
by its true misfit. emcee's acceptance fraction and autocorrelation time are reported with the
fit (``SamplerReport``); the chain is short, so the latter is a rough estimate, and the
band's coverage is measured, not assumed: ``benchmarks/bench_fit_reliability.py``. Their predictions' envelope is the
band of ``identification.predict`` (benchmarks/bench_fit_reliability.py measures how often
it holds the truth).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

CONFIDENCE = 0.95
DISTINCT = 1e-4
"""Members closer than this (in coordinates scaled by the box's size) are one."""
WALKERS, STEPS, BURN_IN, MEMBERS = 32, 300, 100, 100
PUSH = (1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0)
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
    return Identifiability(tuple(names), values, directions, half)


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
            out[inside] = -0.5 * n * problem.misfit(thetas[inside]) / scale
        return out

    rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(2)[1])
    span = bounds[:, 1] - bounds[:, 0]
    start = np.clip(best + START_BALL * span * rng.standard_normal((WALKERS, len(best))), bounds[:, 0], bounds[:, 1])
    moves = [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
    sampler = emcee.EnsembleSampler(WALKERS, len(best), log_probability, vectorize=True, moves=moves)
    sampler.random_state = np.random.RandomState(int(rng.integers(2 ** 31))).get_state()
    sampler.run_mcmc(start, STEPS, progress=False)
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
