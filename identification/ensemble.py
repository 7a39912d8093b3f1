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
equal fit); (2) along each principal direction of the scaled residual Jacobian at the best
fit (its right singular vectors), the points at 1, 1/2, 1/4 and 1/10 of the linearised
half-width sqrt(delta_chi2)/s_j on both sides, clipped to the box, of which the farthest
inside the threshold (by the true misfit) is kept: the ends of the confidence region along
the directions the tests determine least. Their predictions' envelope is the prediction
band of ``identification.predict``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

CONFIDENCE = 0.95
DISTINCT = 1e-4
"""Members closer than this (in coordinates scaled by the box's size) are one."""
FRACTIONS = (1.0, 0.5, 0.25, 0.1)
LOAD_SHOWN = 0.3
"""A coordinate loads a direction when its component is at least this (unit vectors)."""


def misfit_threshold(best_misfit: float, residuals: int, parameters: int) -> float:
    """The largest misfit increase (chi^2/n units) within the confidence region."""
    scale = max(1.0, best_misfit * residuals / max(1, residuals - parameters))
    return scale * chi2.ppf(CONFIDENCE, parameters) / residuals


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


def ensemble_candidates(best: np.ndarray, ident: Identifiability, bounds: np.ndarray) -> np.ndarray:
    """Points along each principal direction (see the module docstring), shape
    (2*d*len(FRACTIONS), d), ordered by direction, side, then decreasing distance."""
    rows = []
    for direction, half in zip(ident.directions, ident.half_widths):
        for side in (1.0, -1.0):
            for fraction in FRACTIONS:
                step = side * fraction * min(half, 1e3) * direction
                rows.append(np.clip(best + step, bounds[:, 0], bounds[:, 1]))
    return np.array(rows)


def select_members(best: np.ndarray, ends: list[tuple[np.ndarray, float]], candidates: np.ndarray,
                   candidate_misfits: np.ndarray, limit: float, bounds: np.ndarray) -> list[np.ndarray]:
    """The ensemble's coordinates, best first: distinct start end points within ``limit``
    (a misfit), then per direction and side the farthest candidate within it."""
    span = bounds[:, 1] - bounds[:, 0]
    members = [best]

    def add(theta):
        if all(np.linalg.norm((theta - m) / span) >= DISTINCT for m in members):
            members.append(theta)

    for theta, misfit in ends:
        if misfit <= limit:
            add(theta)
    per_side = len(FRACTIONS)
    for group in range(0, len(candidates), per_side):
        for theta, misfit in zip(candidates[group:group + per_side], candidate_misfits[group:group + per_side]):
            if misfit <= limit:
                add(theta)
                break
    return members
