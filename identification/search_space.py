"""Where the identification searches: a normalised, data-scaled space per model.

Redundancy. In each Bouc-Wen block the map (alpha, A, beta, gamma) ->
(alpha/s, s*A, s^(1-n)*beta, s^(1-n)*gamma) leaves the force unchanged (z scales by s), so
only 14 of the proposed model's 16 parameters are identifiable (Ma, Zhang & Wen 2004), 8 of
Spencer's 9 dynamic ones and 6 of the single Bouc-Wen's 7. The search fixes every alpha = 1
and maps back with alpha = 1; any other representative follows from
:func:`rescale_hysteresis`. Spencer's x0 (a constant force) is fixed at 0.

Coordinates (all dimensionless, scaled by the data so that another bushing, or a friction
damper, needs no hand-tuning): log10(k / k_ref) of the stiffnesses and the gains A,
log10(c / c_ref) of the dampings, beta * F_ref^n / k_ref and gamma * F_ref^n / k_ref of the
shape parameters, and n itself, with k_ref [N/mm] and c_ref [N*s/mm] from a Kelvin-Voigt
least-squares fit F = k*x + c*v of the sine tests and F_ref [N] their peak force. The
paper's constraints become bounds (A >= 1, beta >= 0) and linear inequalities on the shape
coordinates (beta1 + gamma1 > 0, beta2 - gamma2 > 0; beta + gamma > 0 for the baselines).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from fmu_src.bushing_models import get_model
from identification.compiled_core import parameter_matrix
from identification.measurements import Measurement



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
class Coordinate:
    parameter: str
    kind: str        # "stiffness" (log10 of k/k_ref), "damping" (log10 of c/c_ref), "gain"
                     # (log10 of A/k_ref, A >= 1), "shape" (value*F_ref^n/k_ref), "exponent"
    low: float
    high: float
    exponent: str = ""   # for "shape": the parameter n of the same block


def _proposed_coordinates():
    return (Coordinate("k0", "stiffness", -3.0, 1.0), Coordinate("k1", "stiffness", -3.0, 1.0),
            Coordinate("k2", "stiffness", -5.0, 0.0), Coordinate("c0", "damping", -4.0, 2.0),
            Coordinate("c1", "damping", -4.0, 2.0), Coordinate("c2", "damping", -4.0, 2.0),
            Coordinate("A1", "gain", -4.0, 1.0), Coordinate("A2", "gain", -4.0, 1.0),
            Coordinate("beta1", "shape", 0.0, 20.0, "n1"), Coordinate("beta2", "shape", 0.0, 20.0, "n2"),
            Coordinate("gamma1", "shape", -20.0, 20.0, "n1"), Coordinate("gamma2", "shape", -20.0, 20.0, "n2"),
            Coordinate("n1", "exponent", 0.2, 1.5), Coordinate("n2", "exponent", 0.2, 1.5))


# Per model: the searched coordinates, the alphas fixed at 1 by the normalisation, the
# parameters fixed at 0, and the constraints as {coordinate parameter: coefficient} > 0.
MODEL_SPACES = {
    "proposed": (_proposed_coordinates(), ("alpha1", "alpha2"), (),
                 ({"beta1": 1.0, "gamma1": 1.0}, {"beta2": 1.0, "gamma2": -1.0})),
    # Spencer's gamma sits where eq. 1 has beta (bushing_models): gamma >= 0, gamma + beta > 0.
    "spencer": ((Coordinate("k0", "stiffness", -5.0, 1.0), Coordinate("k1", "stiffness", -3.0, 1.0),
                 Coordinate("c0", "damping", -4.0, 2.0), Coordinate("c1", "damping", -4.0, 2.0),
                 Coordinate("A", "gain", -4.0, 1.0), Coordinate("gamma", "shape", 0.0, 20.0, "n"),
                 Coordinate("beta", "shape", -20.0, 20.0, "n"), Coordinate("n", "exponent", 0.2, 1.5)),
                ("alpha",), ("x0",), ({"gamma": 1.0, "beta": 1.0},)),
    "bouc_wen": ((Coordinate("k0", "stiffness", -3.0, 1.0), Coordinate("c0", "damping", -4.0, 2.0),
                  Coordinate("A", "gain", -4.0, 1.0), Coordinate("beta", "shape", 0.0, 20.0, "n"),
                  Coordinate("gamma", "shape", -20.0, 20.0, "n"), Coordinate("n", "exponent", 0.2, 1.5)),
                 ("alpha",), (), ({"beta": 1.0, "gamma": 1.0},)),
}


@dataclass(frozen=True)
class SearchSpace:
    k_ref: float   # N/mm
    c_ref: float   # N*s/mm
    F_ref: float   # N
    normalise: bool = True
    """False searches log10(alpha) in [-3, 1] too: only for measuring what the normalisation
    is worth (benchmarks/bench_normalisation.py)."""
    model: str = "proposed"

    @classmethod
    def from_measurements(cls, sines: Sequence[Measurement], normalise: bool = True,
                          model: str = "proposed") -> "SearchSpace":
        if model not in MODEL_SPACES:
            raise ValueError(f"no search space for the {model!r} model; choose one of {', '.join(MODEL_SPACES)} "
                             "(kelvin_voigt is fitted by linear least squares)")
        kelvin_voigt = KelvinVoigtFit.fit(sines)
        peak = max(float(np.max(np.abs(m.force_N))) for m in sines)
        amplitude = max(float(np.max(np.abs(m.displacement_mm))) for m in sines)
        # A hysteretic element can show a near-zero or negative Kelvin-Voigt damping or
        # stiffness; fall back to the secant stiffness and a 1 s time scale then.
        k_ref = abs(kelvin_voigt.k) if kelvin_voigt.k > 0 else peak / amplitude
        c_ref = abs(kelvin_voigt.c) if kelvin_voigt.c > 0 else k_ref * 0.01
        return cls(k_ref, c_ref, peak, normalise, model)

    @property
    def coordinates(self) -> tuple[Coordinate, ...]:
        searched, alphas, _, _ = MODEL_SPACES[self.model]
        if self.normalise:
            return searched
        return searched + tuple(Coordinate(name, "alpha", -3.0, 1.0) for name in alphas)

    @property
    def bushing(self):
        return get_model(self.model)

    def bounds(self) -> np.ndarray:
        """(d, 2) lower and upper bounds of the coordinates (d = 14 for the proposed model)."""
        log_A_low = max(np.log10(1.0 / self.k_ref), -4.0)  # A >= 1 N/mm (paper)
        return np.array([(max(c.low, log_A_low), c.high) if c.kind == "gain" else (c.low, c.high)
                         for c in self.coordinates])

    def to_model_parameters(self, coordinates: np.ndarray) -> np.ndarray:
        """(P, d) coordinates -> (P, m) parameters of the model, in its parameter order."""
        theta = np.atleast_2d(coordinates)
        names = self.bushing.parameter_names
        out = np.zeros((theta.shape[0], len(names)))   # fixed parameters (x0) stay 0
        index = {name: i for i, name in enumerate(names)}
        column = {c.parameter: i for i, c in enumerate(self.coordinates)}
        for name in MODEL_SPACES[self.model][1]:
            out[:, index[name]] = 1.0
        for i, c in enumerate(self.coordinates):
            if c.kind == "stiffness":
                out[:, index[c.parameter]] = self.k_ref * 10.0 ** theta[:, i]
            elif c.kind == "damping":
                out[:, index[c.parameter]] = self.c_ref * 10.0 ** theta[:, i]
            elif c.kind == "gain":
                # A >= 1 N/mm (paper); the clamp keeps rounding at the bound from crossing it.
                out[:, index[c.parameter]] = np.maximum(self.k_ref * 10.0 ** theta[:, i], 1.0)
            elif c.kind == "shape":
                out[:, index[c.parameter]] = theta[:, i] * self.k_ref / self.F_ref ** theta[:, column[c.exponent]]
            elif c.kind == "exponent":
                out[:, index[c.parameter]] = theta[:, i]
            else:  # "alpha"
                out[:, index[c.parameter]] = 10.0 ** theta[:, i]
        return out

    def to_parameters(self, coordinates: np.ndarray) -> np.ndarray:
        """(P, d) coordinates -> (P, 16) parameters of the core that simulate the model
        (for the proposed model, its own 16 parameters with alpha1 = alpha2 = 1)."""
        rows = self.to_model_parameters(coordinates)
        if self.model == "proposed":
            return rows
        names, bushing = self.bushing.parameter_names, self.bushing
        return parameter_matrix([bushing.core_parameters(dict(zip(names, row))) for row in rows])

    def to_coordinates(self, params: Mapping[str, float]) -> np.ndarray:
        """The inverse of :meth:`to_model_parameters` (after rescaling every alpha to 1 when
        normalised)."""
        p = dict(params)
        if self.normalise and self.model == "proposed":
            p = rescale_hysteresis(p, p["alpha1"], p["alpha2"])
        elif self.normalise:
            p = _rescale_block(p, "", p["alpha"])
        theta = []
        for c in self.coordinates:
            value = p[c.parameter]
            if c.kind == "stiffness" or c.kind == "gain":
                theta.append(np.log10(value / self.k_ref) if value > 0 else -np.inf)
            elif c.kind == "damping":
                theta.append(np.log10(value / self.c_ref))
            elif c.kind == "shape":
                theta.append(value * self.F_ref ** p[c.exponent] / self.k_ref)
            elif c.kind == "exponent":
                theta.append(value)
            else:
                theta.append(np.log10(value))
        return np.array(theta)

    def constraint_matrix(self) -> np.ndarray:
        """(constraints, d): candidate theta is feasible where matrix @ theta > 0. The shape
        coordinates share one positive scale per block, so the signs carry over."""
        column = {c.parameter: i for i, c in enumerate(self.coordinates)}
        constraints = MODEL_SPACES[self.model][3]
        matrix = np.zeros((len(constraints), len(self.coordinates)))
        for row, constraint in enumerate(constraints):
            for name, coefficient in constraint.items():
                matrix[row, column[name]] = coefficient
        return matrix

    def constraint_violation(self, coordinates: np.ndarray) -> np.ndarray:
        """How far each candidate is from the constraints (0 if it meets them)."""
        theta = np.atleast_2d(coordinates)
        return np.maximum(0.0, -(theta @ self.constraint_matrix().T)).sum(axis=1)


def rescale_hysteresis(params: Mapping[str, float], s1: float, s2: float) -> dict[str, float]:
    """Apply the force-preserving map of each Bouc-Wen block with factors s1, s2:
    (alpha, A, beta, gamma) -> (alpha/s, s*A, s^(1-n)*beta, s^(1-n)*gamma); z becomes s*z."""
    return _rescale_block(_rescale_block(params, "1", s1), "2", s2)


def _rescale_block(params: Mapping[str, float], block: str, s: float) -> dict[str, float]:
    """The force-preserving map of the block whose parameter names end in ``block``
    ('1' or '2'; empty for the single-block models)."""
    if not s > 0:
        raise ValueError(f"the scale factor s{block} = {s} must be > 0")
    out = dict(params)
    power = s ** (1.0 - params["n" + block])
    out["alpha" + block] = params["alpha" + block] / s
    out["A" + block] = params["A" + block] * s
    out["beta" + block] = params["beta" + block] * power
    out["gamma" + block] = params["gamma" + block] * power
    return out
