"""The force-noise level of a measured test, estimated from the data alone.

Estimator (a difference-based variance estimator, as in Hall, Kay & Titterington, Biometrika
1990, with a robust scale): the normalised fourth-order difference of the force samples,

    d_k = (F_k - 4 F_k+1 + 6 F_k+2 - 4 F_k+3 + F_k+4) / sqrt(70),

has standard deviation sigma for white noise of standard deviation sigma (70 = sum of the
squared coefficients), while a smooth force sampled fast contributes only about
|F| (omega h)^4 / sqrt(70): 2 N for a 15 kN force at 30 Hz sampled at 1 kHz. The noise level
is the median absolute value of d over 0.6745 (the normal distribution's MAD), which
ignores the few samples where the force has a corner (a step's ramp start and end, a
reversal), where d is large.

Assumptions: the noise is white (independent from sample to sample) and additive in N, and
the force is smooth between samples. Noise that the rig's anti-aliasing filter has
correlated over several samples is underestimated (the fit then reports that it did not
reach the floor); a test sampled too slowly for its content is overestimated.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_FOURTH_DIFFERENCE = np.array([1.0, -4.0, 6.0, -4.0, 1.0]) / np.sqrt(70.0)
_NORMAL_MAD = 0.6744897501960817
MIN_SAMPLES = 50


@dataclass(frozen=True)
class NoiseEstimate:
    sigma_N: float          # estimated noise standard deviation [N]
    rms_force_N: float      # rms of the measured force [N]

    @property
    def relative(self) -> float:
        """The noise level as a fraction of the rms force: the NRMSE of a perfect model."""
        return self.sigma_N / self.rms_force_N if self.rms_force_N > 0 else float("inf")


def estimate_noise(force_N) -> NoiseEstimate:
    """Noise standard deviation [N] of a force record sampled at a constant rate (see the
    module docstring). Raises ValueError for fewer than MIN_SAMPLES samples."""
    force = np.asarray(force_N, dtype=float)
    if force.ndim != 1 or force.size < MIN_SAMPLES:
        raise ValueError(f"the noise estimate needs a 1-D force record of at least {MIN_SAMPLES} samples, "
                         f"got shape {force.shape}")
    differences = np.convolve(force, _FOURTH_DIFFERENCE, mode="valid")
    sigma = float(np.median(np.abs(differences)) / _NORMAL_MAD)
    return NoiseEstimate(sigma, float(np.sqrt(np.mean(force ** 2))))
