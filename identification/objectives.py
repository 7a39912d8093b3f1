"""The paper's objectives (eqs. 6-9), made dimensionless, for a whole population at once.

The paper's E1 is a mean squared error in N^2 and its E2 a force difference in N; adding
them (eq. 8) mixes units. Here each term is a squared error relative to a force scale of
the measurement it comes from:

- F1 (eq. 6, sine): mean over the samples of (F_exp - F_pre)^2 / mean(F_exp^2), i.e. the
  squared NRMSE. Averaged over the sine files given.
- F2, F3 (eq. 7a/7b, step): ((F_exp - F_pre) / F_exp(T_rise))^2 at the rise time T_rise and at
  the end of the hold (10 s in the paper), each force the mean over a window of +-5 ms so
  that one noisy sample does not decide.
- E3 = w1*F1 + w2*F2 + w3*F3 (eq. 8), default weights 0.5, 0.25, 0.25 (eq. 9); without a
  step test E3 = F1. A random test, when given, adds its squared NRMSE with weight w1 too.

Candidates whose simulation fails (NaN) get an infinite objective.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from identification.compiled_core import simulate_population_held
from identification.measurements import Measurement

WINDOW_S = 0.005
FIT_MAX_SUBSTEPS = 200
"""Substeps per sample after which a candidate counts as failed: a plausible bushing needs
1-5 at 1 kHz; candidates near the blow-up of dz/dxi ~ |z|^n (n > 1) need thousands."""
HOLD_GRID_S = 0.01


@dataclass
class StepTest:
    """A step test and the grid it is simulated on.

    E2 needs the force only around the rise time and at the end, so the simulation uses all
    samples up to 50 ms after the rise and over the last 2 windows, and one every
    HOLD_GRID_S in between; the velocity on this grid is the secant (x_k+1 - x_k)/dt, so the
    piecewise-linear input passes through every measured displacement it keeps.
    """
    measurement: Measurement
    rise_time_s: float

    def __post_init__(self):
        t = self.measurement.time_s
        if not t[0] < self.rise_time_s < t[-1]:
            raise ValueError(f"rise time {self.rise_time_s} s is outside the step test "
                             f"({t[0]} s to {t[-1]} s) in {self.measurement.source}")
        rise_window = np.abs(t - self.rise_time_s) <= WINDOW_S
        end_window = t >= t[-1] - 2 * WINDOW_S
        dense = (t <= self.rise_time_s + 0.05) | (t >= t[-1] - 4 * WINDOW_S)
        sample_step = max(1, int(round(HOLD_GRID_S / float(np.median(np.diff(t))))))
        keep = dense | (np.arange(t.size) % sample_step == 0)
        keep[-1] = True
        self.grid = np.flatnonzero(keep)
        self.grid_time = t[self.grid]
        self.grid_displacement = self.measurement.displacement_mm[self.grid]
        secant = np.diff(self.grid_displacement) / np.diff(self.grid_time)
        self.grid_velocity = np.append(secant, 0.0)
        self.rise_window = rise_window[self.grid]
        self.end_window = end_window[self.grid]
        self.measured_rise = float(np.mean(self.measurement.force_N[rise_window]))
        self.measured_end = float(np.mean(self.measurement.force_N[end_window]))
        self.force_scale = abs(self.measured_rise)
        if self.force_scale == 0.0:
            raise ValueError(f"the measured force at the rise time is zero in {self.measurement.source}")

    def simulate(self, matrix: np.ndarray) -> np.ndarray:
        return simulate_population_held(matrix, self.grid_time, self.grid_displacement, self.grid_velocity,
                                   FIT_MAX_SUBSTEPS)

    def errors(self, matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Relative force errors at the rise time and at the end, per candidate."""
        predicted = self.simulate(matrix)
        rise = (predicted[:, self.rise_window].mean(axis=1) - self.measured_rise) / self.force_scale
        end = (predicted[:, self.end_window].mean(axis=1) - self.measured_end) / self.force_scale
        return rise, end


@dataclass
class Objective:
    """E3 of eq. 8 over the given tests; call it with a (P, 16) parameter matrix."""
    sines: list[Measurement]
    step: StepTest | None = None
    randoms: list[Measurement] = field(default_factory=list)
    weights: tuple[float, float, float] = (0.5, 0.25, 0.25)

    def __post_init__(self):
        if not self.sines:
            raise ValueError("at least one sine test is needed (eq. 6)")
        if any(w < 0 for w in self.weights) or sum(self.weights) <= 0:
            raise ValueError(f"weights {self.weights} must be >= 0 with a positive sum")

    def terms(self, matrix: np.ndarray) -> dict[str, np.ndarray]:
        """F1, F2, F3 and the random term for each candidate (NaN where a simulation failed)."""
        out = {"F1": np.mean([_squared_nrmse(matrix, m) for m in self.sines], axis=0)}
        if self.step is not None:
            rise, end = self.step.errors(matrix)
            out["F2"], out["F3"] = rise ** 2, end ** 2
        if self.randoms:
            out["random"] = np.mean([_squared_nrmse(matrix, m) for m in self.randoms], axis=0)
        return out

    def __call__(self, matrix: np.ndarray) -> np.ndarray:
        terms = self.terms(np.atleast_2d(matrix))
        w1, w2, w3 = self.weights
        if self.step is None:
            total = terms["F1"]
        else:
            total = w1 * terms["F1"] + w2 * terms["F2"] + w3 * terms["F3"]
        if self.randoms:
            total = total + w1 * terms["random"]
        return np.where(np.isfinite(total), total, np.inf)

    def residual_matrix(self, matrix: np.ndarray) -> np.ndarray:
        """Residual vectors of P candidates, shape (P, m); each row's sum of squares is E3.
        Failed simulations give residuals of 1e3."""
        w1, w2, w3 = self.weights if self.step is not None else (1.0, 0.0, 0.0)
        parts = [np.sqrt(w1 / len(self.sines)) * _relative_errors(matrix, m) for m in self.sines]
        if self.step is not None:
            rise, end = self.step.errors(matrix)
            parts.append(np.column_stack([np.sqrt(w2) * rise, np.sqrt(w3) * end]))
        for m in self.randoms:
            parts.append(np.sqrt(self.weights[0] / len(self.randoms)) * _relative_errors(matrix, m))
        residual = np.concatenate(parts, axis=1)
        return np.where(np.isfinite(residual), residual, 1e3)


def _relative_errors(matrix, measurement: Measurement) -> np.ndarray:
    """(F_pre - F_exp) / rms(F_exp) / sqrt(samples): its sum of squares is the squared NRMSE."""
    predicted = simulate_population_held(matrix, measurement.time_s, measurement.displacement_mm,
                                    measurement.velocity_mm_s, FIT_MAX_SUBSTEPS)
    scale = np.sqrt(np.mean(measurement.force_N ** 2)) * np.sqrt(measurement.force_N.size)
    return (predicted - measurement.force_N) / scale


def _squared_nrmse(matrix, measurement: Measurement) -> np.ndarray:
    with np.errstate(over="ignore", invalid="ignore"):  # diverging candidates: inf, rejected later
        return np.sum(_relative_errors(matrix, measurement) ** 2, axis=1)


def nrmse(predicted: np.ndarray, measured: np.ndarray) -> float:
    """RMS of the difference over the RMS of the measurement (the stricter error)."""
    return float(np.sqrt(np.mean((predicted - measured) ** 2)) / np.sqrt(np.mean(measured ** 2)))


def rms_error(predicted: np.ndarray, measured: np.ndarray) -> float:
    """The paper's eq. 10: (RMS(F_exp) - RMS(F_pre)) / RMS(F_exp)."""
    rms_measured = np.sqrt(np.mean(measured ** 2))
    return float((rms_measured - np.sqrt(np.mean(predicted ** 2))) / rms_measured)
