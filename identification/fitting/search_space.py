"""Where the identification searches: a box of dimensionless coordinates, scaled by the data.

Redundancy. In each Bouc-Wen block the map (alpha, A, beta, gamma) ->
(alpha/s, s*A, s^(1-n)*beta, s^(1-n)*gamma) leaves the force unchanged (z scales by s), so
only 14 of the proposed model's 16 parameters are identifiable (Ma, Zhang & Wen 2004), 8 of
Spencer's 9 dynamic ones and 6 of the single Bouc-Wen's 7. The search fixes every alpha = 1
and maps back with alpha = 1; any other representative follows from
:func:`rescale_hysteresis`. Spencer's x0 (a constant force) is fixed at 0.

Scales, from the data (so that another bushing, or a friction damper, needs no
hand-tuning): k_ref [N/mm] and c_ref [N*s/mm] of a Kelvin-Voigt least-squares fit
F = k*x + c*v of the tests other than steps (of the steps if there are no others), F_ref [N]
their peak force, tau_ref = c_ref/k_ref [s].

Coordinates, each with bounds (the box; each model declares its own in its module,
``BushingModel.search``, a ``definition.SearchBox``): each coordinate's kind
(``fmu_src.model.search_coordinates``: stiffness, gain, damping, time constant, slower, shape, shape
sum, exponent, force, travel, cubic, power law) holds its map to the parameter, its inverse and
its bounds; this module scales them by the data and runs them in order. The time constants'
lower bound is TIME_CONSTANT_FLOOR times the sample interval: faster modes are invisible in the
samples and made fits drift to stiff corners (c1 -> 0.002 N*s/mm, a time constant near 1e-7 s
at 1 kHz) that no data support and that make every solver stiff.

Every constraint is a bound, so bounded least squares and any box optimizer can search
the space as it is. ``tests/identification/fitting/test_search_space.py`` checks that the paper's Tables 2, 4, 5,
each parameter moved by +-50 %, lie inside with a margin.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Mapping, Sequence

import numpy as np
from scipy.optimize import lsq_linear

from fmu_src.model.registry import BushingModel, DEFAULT_MODEL, MODELS, resolve_model
from fmu_src.model.definition import SearchCoordinate
from fmu_src.model.options.rig import RIG
from fmu_src.model.search_coordinates import evaluation_order
from identification.errors import IdentificationError
from identification.measured.measurements import Measurement

COMPLEX_STEP = 1e-30
"""The imaginary step of :meth:`SearchSpace.to_parameters_and_seeds` (no cancellation: any tiny
step is exact to rounding)."""
TIME_CONSTANT_FLOOR = 0.01
"""The smallest time constant searched, as a fraction of the (shortest) sample interval."""


@dataclass(frozen=True)
class KelvinVoigtFit:
    """F = k*x + c*v by linear least squares: k [N/mm], c [N*s/mm]."""
    k: float
    c: float

    @classmethod
    def fit(cls, measurements: Sequence[Measurement], nonnegative: bool = False) -> "KelvinVoigtFit":
        """Unconstrained (a scale for the search: a hysteretic force may show a negative c),
        or with k, c >= 0 (``nonnegative``: a Kelvin-Voigt bushing's parameters)."""
        x = np.concatenate([m.displacement_mm for m in measurements])
        v = np.concatenate([m.velocity_mm_s for m in measurements])
        force = np.concatenate([m.force_N for m in measurements])
        design = np.column_stack([x, v])
        if nonnegative:
            k, c = lsq_linear(design, force, bounds=(0.0, np.inf)).x
        else:
            (k, c), *_ = np.linalg.lstsq(design, force, rcond=None)
        return cls(float(k), float(c))

    def force(self, displacement_mm, velocity_mm_s):
        return self.k * np.asarray(displacement_mm) + self.c * np.asarray(velocity_mm_s)


def _rig_zeros(measurements, steps, model: BushingModel, fixed: dict) -> tuple[float, float]:
    """(x_zero [mm], F_zero [N]): where the records are centred (``offsets.rig_zeros``), for a model
    with the rig's offsets (a held displacement zero is its own centre); (0, 0) for any other."""
    if model.options is None or RIG not in model.options:
        return 0.0, 0.0
    from identification.measured.offsets import record_offsets, rig_zeros
    x_zero, F_zero = rig_zeros([record_offsets(m) for m in measurements], steps)
    return float(fixed.get("rig_displacement_zero", x_zero)), F_zero


@dataclass(frozen=True)
class SearchSpace:
    """The box of one model scaled by the data. ``model``: the model's name, or the model (a
    ``BushingModel``, kept under its name): resolved once, here, as ``bushing``, which a worker
    receives by its name (the registry pickles a model so)."""
    k_ref: float                  # N/mm
    c_ref: float                  # N*s/mm
    F_ref: float                  # N
    sample_interval_s: float      # the shortest median sample interval of the tests
    model: str = DEFAULT_MODEL
    x_ref: float = 1.0            # mm: the tests' largest displacement amplitude
    fixed: tuple[tuple[str, float], ...] = ()
    """Parameters held at given values instead of searched ((name, value) pairs in the model's
    units: a backbone's stated knot positions, a value the user knows)."""
    x_zero: float = 0.0           # mm: where the records' stroke is centred (a model with the rig's offsets)
    F_zero: float = 0.0           # N: where their force is centred
    """The origin of the rig's offsets' box (``search_coordinates``' rig kinds): what the records
    show (``offsets.rig_zeros``) for a model with the rig's offsets, else 0."""

    def __post_init__(self):
        bushing = resolve_model(self.model)
        if not isinstance(self.model, str):
            object.__setattr__(self, "model", bushing.name)
        object.__setattr__(self, "_bushing", bushing)
        object.__setattr__(self, "fixed", tuple((str(name), float(value)) for name, value in dict(self.fixed).items()))
        unknown = sorted(name for name, _ in self.fixed if name not in bushing.parameter_names)
        if unknown:
            raise IdentificationError(f"fixed parameters {unknown} are not parameters of the {bushing.name} model; "
                                      f"its parameters: {', '.join(bushing.parameter_names)}")
        bad = [f"{name} = {value}" for name, value in self.fixed if not math.isfinite(value)]
        if bad:
            raise IdentificationError(f"fixed parameters must be finite numbers: {', '.join(bad)}")

    @classmethod
    def from_measurements(cls, measurements: Sequence[Measurement], model: str | BushingModel = DEFAULT_MODEL,
                          steps: Sequence[bool] = (), table=None, fixed=()) -> "SearchSpace":
        """The space for these tests; ``steps`` marks which are step tests (left out of the
        scales unless all are). ``table``: a dynamic-stiffness table (``kdyn_table.KdynTable``),
        which sets the scales when no test other than steps is given (:meth:`from_table`).
        ``fixed``: parameters held at given values (a mapping or (name, value) pairs)."""
        fixed = tuple(dict(fixed).items())
        model = resolve_model(model)
        if model.search is None:
            searched = [name for name, bushing in MODELS.items() if bushing.search is not None]
            linear = f" ({model.name} is fitted by linear least squares: fitting.fit)" if model.linear else ""
            raise ValueError(f"no search space for the {model.name!r} model; choose one of {', '.join(searched)}"
                             + linear)
        steps = list(steps) or [False] * len(measurements)
        scaling = [m for m, is_step in zip(measurements, steps) if not is_step]
        if table is not None:
            from_table = cls.from_table(table, model)
            if not scaling:
                peak = max([from_table.F_ref] + [float(np.max(np.abs(m.force_N))) for m in measurements])
                interval = min([from_table.sample_interval_s] + [float(np.median(np.diff(m.time_s)))
                                                                 for m in measurements])
                return cls(from_table.k_ref, from_table.c_ref, peak, interval, model, from_table.x_ref, fixed)
        scaling = scaling or list(measurements)
        x_zero, F_zero = _rig_zeros(measurements, steps, model, dict(fixed))
        if x_zero or F_zero:    # the scales of the records about their centres, where the rig's offsets put the model
            scaling = [replace(m, displacement_mm=m.displacement_mm - x_zero, force_N=m.force_N - F_zero)
                       for m in scaling]
        kelvin_voigt = KelvinVoigtFit.fit(scaling)
        peak = max(float(np.max(np.abs(m.force_N))) for m in scaling)
        amplitude = max(float(np.max(np.abs(m.displacement_mm))) for m in scaling)
        if not (peak > 0 and amplitude > 0):
            raise IdentificationError(f"the tests {', '.join(m.source for m in scaling)} have a peak force of "
                                      f"{peak:g} N and a peak displacement of {amplitude:g} mm: both must be > 0 "
                                      "to scale the search")
        # A hysteretic element can show a near-zero or negative Kelvin-Voigt damping or
        # stiffness; fall back to the secant stiffness and a 10 ms time scale then.
        k_ref = abs(kelvin_voigt.k) if kelvin_voigt.k > 0 else peak / amplitude
        c_ref = abs(kelvin_voigt.c) if kelvin_voigt.c > 0 else k_ref * 0.01
        interval = min(float(np.median(np.diff(m.time_s))) for m in measurements)
        if table is not None:
            interval = min(interval, from_table.sample_interval_s)
        return cls(k_ref, c_ref, peak, interval, model, amplitude, fixed, x_zero, F_zero)

    @classmethod
    def from_table(cls, table, model: str | BushingModel = DEFAULT_MODEL) -> "SearchSpace":
        """Scales from a dynamic-stiffness table's rows of weight > 0: k_ref the median storage
        stiffness K', c_ref the median K''/omega (the Kelvin-Voigt c of each row), F_ref the
        largest |K*|*X, the interval that of the fit's sine loop at the highest frequency."""
        from identification.measured.kdyn_table import FIT_STEPS_PER_CYCLE
        kept = table.weight > 0
        angle = np.radians(table.loss_angle_deg[kept])
        storage = table.kdyn_N_per_mm[kept] * np.cos(angle)
        damping = table.kdyn_N_per_mm[kept] * np.sin(angle) / (2 * math.pi * table.frequency_hz[kept])
        k_ref = float(np.median(storage)) if np.median(storage) > 0 else float(np.median(table.kdyn_N_per_mm[kept]))
        c_ref = float(np.median(damping)) if np.median(damping) > 0 else k_ref * 0.01
        peak = float(np.max(table.kdyn_N_per_mm[kept] * table.amplitude_mm[kept]))
        interval = 1.0 / (FIT_STEPS_PER_CYCLE * float(np.max(table.frequency_hz[kept])))
        amplitude = float(np.max(table.amplitude_mm[kept]))
        return cls(k_ref, c_ref, peak, interval, model, amplitude)

    @property
    def coordinates(self) -> tuple[SearchCoordinate, ...]:
        """The model's box's coordinates but those of fixed parameters."""
        fixed = {name for name, _ in self.fixed}
        return tuple(c for c in self.bushing.search.coordinates if c.parameter not in fixed)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(c.parameter for c in self.coordinates)

    @property
    def bushing(self) -> BushingModel:
        """The model (resolved once, when the space is made)."""
        return self._bushing

    @property
    def tau_ref(self) -> float:
        return self.c_ref / self.k_ref

    @property
    def shortest_time_constant_s(self) -> float:
        return TIME_CONSTANT_FLOOR * self.sample_interval_s

    def bounds(self) -> np.ndarray:
        """(d, 2) lower and upper bounds of the coordinates (d = 14 for the proposed model): each
        kind's (``search_coordinates``), some tightened by the data (A >= 1 N/mm, the time
        constants' floor)."""
        return np.array([c.kind.bounds(c, self) for c in self.coordinates], dtype=float)

    def to_model_parameters(self, coordinates: np.ndarray) -> np.ndarray:
        """(P, d) coordinates -> (P, m) parameters of the model, in its parameter order, each by
        its coordinate's kind, in an order where what a kind reads is mapped first. Complex
        coordinates give complex parameters (the same map: how :meth:`to_parameters_and_seeds`
        differentiates it by complex step)."""
        theta = np.atleast_2d(np.asarray(coordinates, dtype=complex if np.iscomplexobj(coordinates) else float))
        names = self.bushing.parameter_names
        value = {name: np.zeros(theta.shape[0]) for name in names}   # parameters held at 0 (x0) stay 0
        for name in self.bushing.search.unit_weights:
            value[name] = np.ones(theta.shape[0])
        for name, held in self.bushing.search.held + self.fixed:
            value[name] = np.full(theta.shape[0], held)
        column = {c.parameter: i for i, c in enumerate(self.coordinates)}
        for c in evaluation_order(self.coordinates):
            value[c.parameter] = c.kind.to_parameter(c, theta[:, column[c.parameter]], value, self)
        return np.column_stack([value[name] for name in names])

    def to_parameters(self, coordinates: np.ndarray) -> np.ndarray:
        """(P, d) coordinates -> (P, m) parameters of the model, what its compiled kernels take
        (``population.parameter_matrix``; for the proposed model alpha1 = alpha2 = 1)."""
        return np.ascontiguousarray(self.to_model_parameters(coordinates))

    def to_parameters_and_seeds(self, coordinates: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(P, d) coordinates -> the (P, m) parameters (:meth:`to_parameters`, the same bits) and
        their derivatives (P, m, d) along each coordinate: column j of row i is dp/dtheta_j at
        theta_i, in the parameters' units per coordinate unit. By complex step of the map itself
        (its parameters at theta + i*COMPLEX_STEP*e_j, imaginary part over the step): exact to
        rounding, as the map is analytic in theta except at the gains' clamp A >= 1 N/mm (0 below
        it, the derivative of the clamp's constant)."""
        theta = np.atleast_2d(np.asarray(coordinates, dtype=float))
        count, d = theta.shape
        shifted = theta[:, None, :] + 1j * COMPLEX_STEP * np.eye(d)[None, :, :]     # (P, d, d)
        with np.errstate(invalid="ignore", over="ignore"):
            values = self.to_model_parameters(shifted.reshape(count * d, d)).reshape(count, d, -1)
        return self.to_parameters(theta), np.ascontiguousarray(np.transpose(values.imag, (0, 2, 1)) / COMPLEX_STEP)

    def to_coordinates(self, params: Mapping[str, float]) -> np.ndarray:
        """The inverse of :meth:`to_model_parameters` (after rescaling every alpha to 1)."""
        p = dict(params)
        for weight in self.bushing.search.unit_weights:   # each Bouc-Wen block's alpha, rescaled to 1
            p = _rescale_block(p, weight[len("alpha"):], p[weight])
        return np.array([c.kind.to_coordinate(c, p[c.parameter], p, self) for c in self.coordinates])

    def inside(self, coordinates: np.ndarray) -> np.ndarray:
        """Whether each row of coordinates lies in the box."""
        theta = np.atleast_2d(coordinates)
        bounds = self.bounds()
        return np.all((theta >= bounds[:, 0]) & (theta <= bounds[:, 1]), axis=1)

    def time_constant(self, values, parameter: str):
        """The time constant [s] of the dashpot ``parameter`` (a time-constant coordinate) in
        ``values`` (a mapping of parameters or of their columns): its value over the
        stiffnesses it works against."""
        over = next(c.over for c in self.coordinates if c.parameter == parameter)
        return values[parameter] / sum(values[name] for name in over)


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
