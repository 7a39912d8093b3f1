"""The force-noise estimate from the data alone (identification/measured/noise.py)."""
import numpy as np
import pytest

from conftest import paper_parameters
from identification.measured.noise import estimate_noise
from identification.measured.signals import Random, Sine, Step, sample_times
from identification.forward.simulate import simulate


@pytest.mark.parametrize("protocol, duration_s", [(Sine(2.0, 10.0), 1.0), (Sine(2.0, 30.0), 1.0),
                                                  (Step(2.0, 0.4, 10.0), 10.0), (Step(3.0, 0.1, 2.0), 2.0),
                                                  (Random(2.0, 5.0, seed=7), 5.0)])
@pytest.mark.parametrize("fraction", [0.005, 0.01, 0.02])
def test_noise_of_synthetic_tests_is_estimated_within_8_percent(protocol, duration_s, fraction):
    # Known white noise on the continuous-time Table 5 model, sampled at 1 kHz. The issue's
    # tolerance is +-20 %; measured on these: within 7 %.
    t = sample_times(duration_s, 1000.0)
    force = simulate(paper_parameters("table5"), t, *protocol.signals(t))
    sigma = fraction * np.sqrt(np.mean(force ** 2))
    noisy = force + np.random.default_rng(3).normal(0.0, sigma, t.size)
    estimate = estimate_noise(noisy)
    assert estimate.sigma_N == pytest.approx(sigma, rel=0.08)
    assert estimate.relative == pytest.approx(fraction, rel=0.08)


@pytest.mark.parametrize("fraction, low, high", [(0.002, 1.1, 1.35), (0.005, 1.03, 1.15), (0.01, 1.0, 1.08)])
def test_harmonics_near_the_nyquist_frequency_read_as_noise(fraction, low, high):
    # The documented limit: at 3 mm and 30 Hz the noise-free Table 5 force has harmonics up to
    # the 1 kHz sampling's Nyquist frequency, which read as 0.07 % noise; low noise levels are
    # then overestimated (by a quarter at 0.2 %; the fit's floor check is then lenient).
    t = sample_times(1.0, 1000.0)
    force = simulate(paper_parameters("table5"), t, *Sine(3.0, 30.0).signals(t))
    assert 5e-4 < estimate_noise(force).relative < 1e-3
    sigma = fraction * np.sqrt(np.mean(force ** 2))
    noisy = force + np.random.default_rng(3).normal(0.0, sigma, t.size)
    assert low < estimate_noise(noisy).sigma_N / sigma < high


def test_too_short_a_record_is_refused():
    with pytest.raises(ValueError, match="at least 50 samples"):
        estimate_noise(np.ones(20))
