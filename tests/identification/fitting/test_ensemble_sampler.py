"""The posterior's sampler takes any number of free parameters: walkers scaled with the
dimensions (emcee refuses its differential-evolution moves with fewer than twice them), and a
start it cannot sample from is a SamplingFailed that the fit turns into a profile-only band with
a warning, never a traceback."""
import numpy as np
import pytest

from identification.fitting.ensemble import WALKERS, SamplingFailed, posterior_samples, walkers_for


class _Space:
    def __init__(self, bounds):
        self._bounds = np.asarray(bounds, dtype=float)

    def bounds(self):
        return self._bounds

    def inside(self, thetas):
        return np.all((thetas >= self._bounds[:, 0]) & (thetas <= self._bounds[:, 1]), axis=1)


class _Objective:
    size = 1000


class _Gaussian:
    """chi^2/n of a standard normal posterior in every coordinate (an analytic stand-in for a
    fit's problem: n = 1000 residuals, chi^2 = |theta|^2)."""

    def __init__(self, bounds):
        self.space, self.objective = _Space(bounds), _Objective()

    def misfit(self, thetas):
        return np.sum(np.atleast_2d(thetas) ** 2, axis=1) / self.objective.size


def test_the_walkers_are_at_least_twice_the_dimensions_and_never_fewer_than_before():
    assert walkers_for(1) == walkers_for(15) == WALKERS
    for d in (16, 21, 40):
        assert walkers_for(d) >= 2 * d and walkers_for(d) % 2 == 0


@pytest.mark.parametrize("dimensions", [21])
def test_a_model_of_more_than_fifteen_parameters_is_sampled(dimensions):
    # 21 free parameters: a proposed model with a backbone, a Maxwell element and the rig's zeros,
    # which emcee refused with 32 walkers
    problem = _Gaussian([[-5.0, 5.0]] * dimensions)
    draws, misfits, report = posterior_samples(problem, np.zeros(dimensions), seed=0)
    assert draws.shape[1] == dimensions and len(draws) > 0
    assert np.all(np.isfinite(misfits)) and 0.0 < report.acceptance < 1.0


def test_a_start_the_sampler_cannot_leave_is_a_sampling_failure():
    # a coordinate whose box has no width: every walker starts at the same value of it
    problem = _Gaussian([[-5.0, 5.0], [1.0, 1.0], [-5.0, 5.0]])
    with pytest.raises(SamplingFailed, match="3 dimensions"):
        posterior_samples(problem, np.array([0.0, 1.0, 0.0]), seed=0)
