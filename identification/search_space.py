"""Where the identification searches: a normalised, data-scaled space of 14 coordinates.

Redundancy. In each Bouc-Wen block the map (alpha, A, beta, gamma) ->
(alpha/s, s*A, s^(1-n)*beta, s^(1-n)*gamma) leaves the force unchanged (z scales by s), so
only 14 of the 16 parameters are identifiable (Ma, Zhang & Wen 2004). The search fixes
alpha1 = alpha2 = 1 and maps back to 16 paper parameters with alpha = 1; any other
representative follows from :func:`rescale_hysteresis`.

Coordinates (all dimensionless, scaled by the data so that another bushing, or a friction
damper, needs no hand-tuning):
    log10(k0, k1, k2 / k_ref), log10(c0, c1, c2 / c_ref), log10(A1, A2 / k_ref),
    beta_i * F_ref^n_i / k_ref, gamma_i * F_ref^n_i / k_ref, n1, n2
with k_ref [N/mm] and c_ref [N*s/mm] from a Kelvin-Voigt least-squares fit F = k*x + c*v of
the sine tests and F_ref [N] their peak force. The paper's constraints become bounds
(A >= 1, beta >= 0) and two linear inequalities (beta1 + gamma1 > 0, beta2 - gamma2 > 0).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from fmu_src.bushing_params import PARAMETER_NAMES
from identification.measurements import Measurement

COORDINATES = ("log_k0", "log_k1", "log_k2", "log_c0", "log_c1", "log_c2", "log_A1", "log_A2",
               "beta1", "beta2", "gamma1", "gamma2", "n1", "n2")
_INDEX = {name: i for i, name in enumerate(PARAMETER_NAMES)}


@dataclass(frozen=True)
class KelvinVoigtFit:
    """F = k*x + c*v by linear least squares: k [N/mm], c [N*s/mm]."""
    k: float
    c: float

    @classmethod
    def fit(cls, measurements: Sequence[Measurement]) -> "KelvinVoigtFit":
        x = np.concatenate([m.displacement_mm for m in measurements])
        v = np.concatenate([m.velocity_mm_s for m in measurements])
        force = np.concatenate([m.force_N for m in measurements])
        (k, c), *_ = np.linalg.lstsq(np.column_stack([x, v]), force, rcond=None)
        return cls(float(k), float(c))

    def force(self, displacement_mm, velocity_mm_s):
        return self.k * np.asarray(displacement_mm) + self.c * np.asarray(velocity_mm_s)


@dataclass(frozen=True)
class SearchSpace:
    k_ref: float   # N/mm
    c_ref: float   # N*s/mm
    F_ref: float   # N
    normalise: bool = True
    """False searches log10(alpha1), log10(alpha2) in [-3, 1] too (16 coordinates): only for
    measuring what the normalisation is worth (benchmarks/bench_normalisation.py)."""

    @classmethod
    def from_measurements(cls, sines: Sequence[Measurement], normalise: bool = True) -> "SearchSpace":
        kelvin_voigt = KelvinVoigtFit.fit(sines)
        peak = max(float(np.max(np.abs(m.force_N))) for m in sines)
        amplitude = max(float(np.max(np.abs(m.displacement_mm))) for m in sines)
        # A hysteretic element can show a near-zero or negative Kelvin-Voigt damping or
        # stiffness; fall back to the secant stiffness and a 1 s time scale then.
        k_ref = abs(kelvin_voigt.k) if kelvin_voigt.k > 0 else peak / amplitude
        c_ref = abs(kelvin_voigt.c) if kelvin_voigt.c > 0 else k_ref * 0.01
        return cls(k_ref, c_ref, peak, normalise)

    def bounds(self) -> np.ndarray:
        """(14, 2) lower and upper bounds of the coordinates ((16, 2) without normalisation)."""
        log_A_low = max(np.log10(1.0 / self.k_ref), -4.0)  # A >= 1 N/mm (paper)
        rows = [
            (-3.0, 1.0), (-3.0, 1.0), (-5.0, 0.0),          # k0, k1, k2 / k_ref
            (-4.0, 2.0), (-4.0, 2.0), (-4.0, 2.0),          # c0, c1, c2 / c_ref
            (log_A_low, 1.0), (log_A_low, 1.0),             # A1, A2 / k_ref
            (0.0, 20.0), (0.0, 20.0),                       # beta1, beta2 (>= 0, paper)
            (-20.0, 20.0), (-20.0, 20.0),                   # gamma1, gamma2
            (0.2, 1.5), (0.2, 1.5),                         # n1, n2
        ]
        if not self.normalise:
            rows += [(-3.0, 1.0), (-3.0, 1.0)]              # log10 alpha1, alpha2
        return np.array(rows)

    def to_parameters(self, coordinates: np.ndarray) -> np.ndarray:
        """(P, 14) coordinates -> (P, 16) paper parameters with alpha1 = alpha2 = 1."""
        theta = np.atleast_2d(coordinates)
        out = np.empty((theta.shape[0], len(PARAMETER_NAMES)))
        for i, name in enumerate(("k0", "k1", "k2")):
            out[:, _INDEX[name]] = self.k_ref * 10.0 ** theta[:, i]
        for i, name in enumerate(("c0", "c1", "c2")):
            out[:, _INDEX[name]] = self.c_ref * 10.0 ** theta[:, 3 + i]
        # A >= 1 N/mm (paper); the clamp keeps rounding at the bound from crossing it.
        out[:, _INDEX["A1"]] = np.maximum(self.k_ref * 10.0 ** theta[:, 6], 1.0)
        out[:, _INDEX["A2"]] = np.maximum(self.k_ref * 10.0 ** theta[:, 7], 1.0)
        n1, n2 = theta[:, 12], theta[:, 13]
        out[:, _INDEX["n1"]], out[:, _INDEX["n2"]] = n1, n2
        for column, name, n in ((8, "beta1", n1), (9, "beta2", n2), (10, "gamma1", n1), (11, "gamma2", n2)):
            out[:, _INDEX[name]] = theta[:, column] * self.k_ref / self.F_ref ** n
        if self.normalise:
            out[:, _INDEX["alpha1"]] = out[:, _INDEX["alpha2"]] = 1.0
        else:
            out[:, _INDEX["alpha1"]], out[:, _INDEX["alpha2"]] = 10.0 ** theta[:, 14], 10.0 ** theta[:, 15]
        return out

    def to_coordinates(self, params: Mapping[str, float]) -> np.ndarray:
        """The inverse of :meth:`to_parameters` (after rescaling to alpha1 = alpha2 = 1 when
        normalised)."""
        p = rescale_hysteresis(params, params["alpha1"], params["alpha2"]) if self.normalise else dict(params)
        theta = [np.log10(p[name] / self.k_ref) if p[name] > 0 else -np.inf for name in ("k0", "k1", "k2")]
        theta += [np.log10(p[name] / self.c_ref) for name in ("c0", "c1", "c2")]
        theta += [np.log10(p["A1"] / self.k_ref), np.log10(p["A2"] / self.k_ref)]
        theta += [p[name] * self.F_ref ** p["n" + name[-1]] / self.k_ref
                  for name in ("beta1", "beta2", "gamma1", "gamma2")]
        theta += [p["n1"], p["n2"]]
        if not self.normalise:
            theta += [np.log10(p["alpha1"]), np.log10(p["alpha2"])]
        return np.array(theta)

    @staticmethod
    def constraint_violation(coordinates: np.ndarray) -> np.ndarray:
        """How far each candidate is from beta1 + gamma1 > 0 and beta2 - gamma2 > 0 (0 if not)."""
        theta = np.atleast_2d(coordinates)
        return (np.maximum(0.0, -(theta[:, 8] + theta[:, 10]))
                + np.maximum(0.0, -(theta[:, 9] - theta[:, 11])))


def rescale_hysteresis(params: Mapping[str, float], s1: float, s2: float) -> dict[str, float]:
    """Apply the force-preserving map of each Bouc-Wen block with factors s1, s2:
    (alpha, A, beta, gamma) -> (alpha/s, s*A, s^(1-n)*beta, s^(1-n)*gamma); z becomes s*z."""
    out = dict(params)
    for block, s in (("1", s1), ("2", s2)):
        if not s > 0:
            raise ValueError(f"the scale factor s{block} = {s} must be > 0")
        power = s ** (1.0 - params["n" + block])
        out["alpha" + block] = params["alpha" + block] / s
        out["A" + block] = params["A" + block] * s
        out["beta" + block] = params["beta" + block] * power
        out["gamma" + block] = params["gamma" + block] * power
    return out
