"""The fit's objective: least squares over every sample of every training test, in noise units.

For candidate parameters the residual of sample k of test i is

    r_ik = (F_model,ik - F_measured,ik) / sigma_i / sqrt(n),

with sigma_i the test's force-noise level (``identification.measured.noise``, estimated from the
data) and n the number of residuals of all tests. The objective, the *misfit*, is the sum
of their squares: chi^2/n, the mean squared residual in units of the noise variance. It is
about 1 at the true parameters (the noise floor) and (NRMSE_i/noise_i)^2 averaged over the
samples. Minimising it is maximum likelihood for white Gaussian noise, which is what makes
the ensemble's chi^2 threshold (``identification.fitting.ensemble``) meaningful.

Why not the paper's E3 (eqs. 6-9: the sine's mean squared error plus the step's force at two
instants)? Two instants leave the step's relaxation curve between them free, so a fit can
match E3 and still miss the step test elsewhere; every sample counts here. The paper's eq. 7
point errors are reported by ``identification.analysis.paper_verification``.

The model is simulated with the forward model (``identification.forward.input_path``) on each
test as sampled, with held stretches of a step decimated: the residuals are those of the
samples that remain (about 14 % of a 10 s step). A sine sampled more finely than
``FIT_SAMPLES_PER_CYCLE`` a cycle (a rig's slow sine at 1024 Hz) counts every ``stride``-th
sample's force only, each weighing ``stride`` samples (its noise level divided by
sqrt(stride), n counting the samples it stands for): chi^2/n keeps its scale, where the misfit is
a model's (smooth over a stride) and where it is white noise, and the cost falls with the
samples asked for. A candidate whose simulation fails
(overflow, more than FIT_MAX_SUBSTEPS substeps in a communication step) gets residuals of
FAILED_RESIDUAL noise levels from there on: worse than any candidate that runs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from fmu_src.model.parameter_specs import ParameterError
from fmu_src.model.registry import BushingModel, DEFAULT_BUSHING, required_model
from identification.forward.input_path import DrivenInput, DrivenVectorInput, prepare_input, prepare_vector_input
from identification.measured.kdyn_table import (FIT_CYCLES, FIT_STEPS_PER_CYCLE, KDYN_UNCERTAINTY, LOSS_ANGLE_UNCERTAINTY_DEG,
                                                SEARCH_CYCLES, SEARCH_STEPS_PER_CYCLE, KdynTable)
from identification.measured.multiaxis import MultiAxisMeasurement, coupled_axes
from identification.measured.noise import NoiseEstimate, estimate_noise
from identification.measured.offsets import held_force, record_offsets
from identification.measured.rig_tests import RigTest
from identification.forward.simulate import simulate_driven, simulate_driven_vector

FIT_MAX_SUBSTEPS = 100
"""Substeps per communication step after which a candidate counts as failed: a plausible
bushing needs 1-5 at 1 kHz; candidates near the blow-up of dz/dxi ~ |z|^n (n > 1) need thousands."""
FAILED_RESIDUAL = 1e3
MIN_NOISE_FRACTION = 1e-3
"""Noise levels below 0.1 % of a test's rms force are taken as 0.1 %: the forward model's own
accuracy at 1 kHz is about 0.04 % (tests/identification/forward/test_forward_model.py), so a fit cannot resolve less."""
MIN_PREFIX_SAMPLES = 50
"""The shortest prefix of a test a candidate is first screened on (``Objective.prefix``)."""
FIT_SAMPLES_PER_CYCLE = 256
"""A sine's forces counted per cycle, at least: a finer one counts every stride-th sample (stride
the samples a cycle over this, rounded down). A loop of the paper's tests has 100 (10 Hz at
1 kHz); the real friction damper's 0.25 Hz sines at 1024 Hz have 4096."""


@dataclass(frozen=True)
class PreparedTest:
    """What the objective keeps of one training test (lean: it is sent to every worker)."""
    name: str
    driven: DrivenInput
    measured_N: np.ndarray      # the measured force at driven.sample_index
    sigma_N: float              # the noise level the residuals are divided by


@dataclass(frozen=True)
class PreparedMultiAxis:
    """What the objective keeps of one multi-axis training test (``identification.measured.multiaxis``):
    its driven input, the measured force vectors at the samples (samples, d), each axis's noise
    level (d,) and how many of its leading axes the model runs coupled (its coupled form on their
    displacement vector; the others one model per axis: ``multiaxis.coupled_axes``)."""
    name: str
    driven: DrivenVectorInput
    measured_N: np.ndarray
    sigma_N: np.ndarray
    coupled_axes: int

    @classmethod
    def of(cls, measurement: MultiAxisMeasurement, noise: Sequence[NoiseEstimate], coupling: str,
           steps: int | None = None) -> "PreparedMultiAxis":
        driven = prepare_vector_input(measurement.time_s, measurement.displacement_mm, measurement.velocity_mm_s,
                                      steps=steps)
        sigma = np.array([max(level.sigma_N, MIN_NOISE_FRACTION * level.rms_force_N) for level in noise])
        return cls(measurement.name, driven, measurement.force_N[driven.sample_index], sigma,
                   coupled_axes(coupling, measurement))

    @property
    def size(self) -> int:
        return self.measured_N.size

    def residuals(self, matrix: np.ndarray, model: BushingModel) -> np.ndarray:
        """(P, samples x d): each sample's force vector error, axis by axis, in its axis's noise
        units (NaN from where a candidate fails)."""
        predicted = simulate_driven_vector(matrix, self.driven, FIT_MAX_SUBSTEPS, model, self.coupled_axes)
        return ((predicted - self.measured_N) / self.sigma_N).reshape(matrix.shape[0], -1)


SEARCH_SETTLING = 0.25
"""The share of a model's settling time the search's table loop runs (the hydraulic model: 0.5 s
against the fit loop's 2 s). It only chooses the basins the fit loop refines: at the truth on the
synthetic mount's sheet it stays near the steady state, and the fit from that sheet reaches the
same result with either, faster (docs/benchmarks.md, "Figures behind the code's constants")."""


@dataclass(frozen=True)
class PreparedTable:
    """The rows of a dynamic-stiffness table the objective counts (weight > 0) and its loop:
    ``cycles`` per row."""
    rows: KdynTable
    steps_per_cycle: int
    cycles: np.ndarray

    @classmethod
    def of(cls, table: KdynTable, model: BushingModel, search: bool = False) -> "PreparedTable":
        """With the fit's loop, or the search's coarser one (``search``): FIT_CYCLES (SEARCH_CYCLES)
        per row, or more where the model takes longer to settle (``BushingModel.settling_s``; the
        search, which only chooses the basins the fit loop refines, SEARCH_SETTLING of that time)."""
        steps, cycles = (SEARCH_STEPS_PER_CYCLE, SEARCH_CYCLES) if search else (FIT_STEPS_PER_CYCLE, FIT_CYCLES)
        rows = table.kept()
        settling = model.settling_s * (SEARCH_SETTLING if search else 1.0)
        return cls(rows, steps, np.maximum(cycles, np.ceil(settling * rows.frequency_hz)).astype(np.int64))

    @property
    def size(self) -> int:
        return 2 * len(self.rows)

    def stiffness(self, matrix: np.ndarray, model: str | BushingModel) -> tuple[np.ndarray, np.ndarray]:
        """|K*| [N/mm] and the loss angle [deg] of P candidates on every row, each (P, rows):
        ``cycles`` cycles of ``steps_per_cycle`` steps from rest (``identification.measured.kdyn_table``)."""
        from identification.forward.dynamic_stiffness import SteadyStateLoop, run_table_rows, stiffness_from_sums
        rows = self.rows
        result = run_table_rows(matrix, required_model(model), rows,
                                SteadyStateLoop(self.steps_per_cycle, self.cycles, 0.0, FIT_MAX_SUBSTEPS))
        _, _, kdyn, angle = stiffness_from_sums(result, rows.amplitude_mm)
        failed = result[..., 3] == 2
        return np.where(failed, np.nan, kdyn), np.where(failed, np.nan, angle)

    def residuals(self, matrix: np.ndarray, model: str | BushingModel) -> np.ndarray:
        """(P, 2*rows): relative |K*| errors over KDYN_UNCERTAINTY, then loss-angle errors over
        LOSS_ANGLE_UNCERTAINTY_DEG, each times its row's weight (NaN where a candidate fails)."""
        kdyn, angle = self.stiffness(matrix, model)
        rows = self.rows
        with np.errstate(invalid="ignore", over="ignore"):
            return np.hstack([(kdyn / rows.kdyn_N_per_mm - 1.0) * (rows.weight / KDYN_UNCERTAINTY),
                              (angle - rows.loss_angle_deg) * (rows.weight / LOSS_ANGLE_UNCERTAINTY_DEG)])


@dataclass(frozen=True)
class MultiAxisTests:
    """Multi-axis tests (``identification.measured.multiaxis``) an objective fits: the
    ``measurements``, each axis's noise level per test (``noise``; None: estimated from each
    axis's force) and the ``coupling`` the model runs with on them (none, radial, spherical:
    ``multiaxis.coupled_axes``)."""
    measurements: Sequence[MultiAxisMeasurement] = ()
    noise: Sequence[Sequence[NoiseEstimate]] | None = None
    coupling: str = "none"


class Objective:
    """Misfit (chi^2/n) of candidate parameter sets of ``model``; see the module docstring."""

    def __init__(self, tests: Sequence[RigTest], noise: Sequence[NoiseEstimate] | None = None,
                 steps: Sequence[int | None] | None = None, model: BushingModel = DEFAULT_BUSHING,
                 table: KdynTable | None = None, search: bool = False, multiaxis: MultiAxisTests = MultiAxisTests()):
        """``steps``: communication steps per sample of each test (None: chosen from the
        signal, ``input_path.steps_per_sample``); ``identification.fitting.refinement`` raises them
        where a candidate's response needs it. ``table``: a dynamic-stiffness table whose rows
        add two residuals each (``identification.measured.kdyn_table``), with the search's coarser loop
        if ``search``. Candidates are (P, m) matrices of ``model``'s parameters in its order
        (``population.parameter_matrix``). ``model``: the model (``bushing``; ``model`` is its
        name), which a worker receives by its name (the registry pickles a model as its name).
        ``multiaxis``: multi-axis tests (``MultiAxisTests``), each axis's force a residual in that
        axis's noise units, the model run on them with their coupling; their steps per sample are
        the signal's (the refinement does not change them). A model that can hold a force at rest
        starts each test holding the force the test holds before it moves (``offsets.held_force``;
        ``rest_forces``, NaN where none)."""
        if not tests and table is None and not multiaxis.measurements:
            raise ValueError("the objective needs at least one training test, multi-axis test or dynamic-stiffness "
                             "table")
        noise = list(noise) if noise is not None else [estimate_noise(t.measurement.force_N) for t in tests]
        if len(noise) != len(tests):
            raise ValueError(f"{len(noise)} noise levels for {len(tests)} tests")
        steps = list(steps) if steps is not None else [None] * len(tests)
        if len(steps) != len(tests):
            raise ValueError(f"{len(steps)} step counts for {len(tests)} tests")
        _check_conditions(tests, required_model(model))
        self.rest_forces = [held_force(t.measurement) for t in tests]
        self.strides = [fit_stride(t) for t in tests]
        self.noise = noise
        self.bushing = required_model(model)
        self.model = self.bushing.name
        self.tests = _prepared_tests(tests, noise, steps, self.rest_forces, self.strides)
        self.rig_tests = list(tests)     # what it was made of: with_steps, prefix, with_fit_loop derive from them
        self._source_table = table
        self.search = search and table is not None
        self.table = PreparedTable.of(table, self.bushing, search) if table is not None else None
        noise = [list(levels) for levels in multiaxis.noise] if multiaxis.noise is not None else \
            [[estimate_noise(m.force_N[:, c]) for c in range(m.force_N.shape[1])] for m in multiaxis.measurements]
        self._source_multiaxis = MultiAxisTests(tuple(multiaxis.measurements), noise, multiaxis.coupling)
        self.coupling = multiaxis.coupling
        self.multiaxis = [PreparedMultiAxis.of(m, levels, multiaxis.coupling)
                          for m, levels in zip(multiaxis.measurements, noise)]
        self.size = (sum(t.measured_N.size * t.driven.stride for t in self.tests) + sum(m.size for m in self.multiaxis)
                     + (self.table.size if self.table else 0))

    def with_steps(self, steps: Sequence[int]) -> "Objective":
        """The same objective with other steps per sample (the table's loop as it is)."""
        return Objective(self.rig_tests, self.noise, steps, self.bushing, self._source_table, self.search,
                         self._source_multiaxis)

    def prefix(self, fraction: float) -> "Objective | None":
        """The same objective on the first ``fraction`` of each test's samples (at least
        MIN_PREFIX_SAMPLES), with the same noise levels and steps per sample: a cheap first look
        at a candidate (``multistart.screen``). None where it has a table or multi-axis tests,
        whose cost no prefix of the time series lowers."""
        if self.table is not None or self.multiaxis:
            return None
        cut = []
        for test in self.rig_tests:
            m = test.measurement
            k = min(len(m), max(MIN_PREFIX_SAMPLES, math.ceil(fraction * len(m))))
            # a prefix of a step may end inside its ramp: as a plain time series, whose kind checks nothing
            cut.append(RigTest(replace(m, time_s=m.time_s[:k], displacement_mm=m.displacement_mm[:k],
                                       force_N=m.force_N[:k], velocity_mm_s=m.velocity_mm_s[:k],
                                       # the whole test's mean: the condition it runs at
                                       temperature_K=None if m.temperature_K is None
                                       else np.full(k, m.mean_temperature_K))))
        prefix = Objective(cut, self.noise, self.steps_per_sample, self.bushing)
        # the whole tests' forces at rest and strides (a prefix's own would judge them on less:
        # a cycle of a slow sine is longer than its prefix), its tests prepared again with them
        prefix.rest_forces, prefix.strides = list(self.rest_forces), list(self.strides)
        prefix.tests = _prepared_tests(cut, self.noise, self.steps_per_sample, prefix.rest_forces, prefix.strides)
        prefix.size = sum(t.measured_N.size * t.driven.stride for t in prefix.tests)
        return prefix

    def with_fit_loop(self) -> "Objective":
        """The same objective with the table's fit loop instead of its search loop (itself if it
        has none)."""
        if not self.search:
            return self
        return Objective(self.rig_tests, self.noise, self.steps_per_sample, self.bushing, self._source_table,
                         False, self._source_multiaxis)

    def __getstate__(self):
        """Everything but the tests it was made of (a worker evaluates; only the process that made
        it derives others); the model goes by its name (the registry pickles it so)."""
        return {name: value for name, value in self.__dict__.items() if name != "rig_tests"}

    def __setstate__(self, state):
        self.__dict__.update(state)
        self.rig_tests = None

    @property
    def steps_per_sample(self) -> list[int]:
        """Communication steps per sample interval of each test's forward model."""
        return [t.driven.steps_per_sample for t in self.tests]

    def residual_matrix(self, matrix: np.ndarray) -> np.ndarray:
        """Residuals of P candidates, shape (P, n); each row's sum of squares is its misfit."""
        scale = 1.0 / math.sqrt(self.size)
        parts = []
        for test in self.tests:
            predicted = simulate_driven(matrix, test.driven, FIT_MAX_SUBSTEPS, self.bushing)
            parts.append((predicted - test.measured_N) * (scale / test.sigma_N))
        residual = np.concatenate(parts + [self._difference_part(matrix)], axis=1)
        return np.where(np.isfinite(residual), residual, FAILED_RESIDUAL * scale)

    @property
    def difference_size(self) -> int:
        """The last residuals, the multi-axis tests' and the table's, which have no sensitivities:
        a Jacobian takes them by differences (:meth:`difference_residuals`)."""
        return sum(m.size for m in self.multiaxis) + (self.table.size if self.table else 0)

    def _difference_part(self, matrix: np.ndarray) -> np.ndarray:
        """The multi-axis tests' and the table's residuals, scaled, NaN where a candidate fails."""
        scale = 1.0 / math.sqrt(self.size)
        parts = [m.residuals(matrix, self.bushing) * scale for m in self.multiaxis]
        if self.table is not None:
            parts.append(self.table.residuals(matrix, self.bushing) * scale)
        return np.concatenate(parts, axis=1) if parts else np.empty((matrix.shape[0], 0))

    def residual_jacobian(self, matrix: np.ndarray, seeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Residuals of P candidates (P, n), the same bits as :meth:`residual_matrix`, and their
        derivatives (P, n, K) along K directions ``seeds`` (P, m, K: each direction's derivative
        of the m parameters), computed with them (``identification.forward.parameter_jacobian``). A failed
        candidate's residuals are the constant FAILED_RESIDUAL from where it fails: derivative 0
        there, and so is a derivative that overflows where the force does not. A table's rows get
        NaN derivatives, and so do the multi-axis tests' (``difference_size``): the caller takes those
        by differences (:meth:`difference_residuals`); the coupled kernels and the table's steady-state
        loop have no sensitivities."""
        from identification.forward.parameter_jacobian import population_sensitivities
        scale = 1.0 / math.sqrt(self.size)
        parts, derivatives = [], []
        for test in self.tests:
            predicted, sensitivity = population_sensitivities(matrix, seeds, test.driven, FIT_MAX_SUBSTEPS,
                                                              self.bushing)
            parts.append((predicted - test.measured_N) * (scale / test.sigma_N))
            derivatives.append(sensitivity * (scale / test.sigma_N))
        parts.append(self._difference_part(matrix))
        derivatives.append(np.full((matrix.shape[0], self.difference_size, seeds.shape[2]), np.nan))
        residual = np.concatenate(parts, axis=1)
        failed = ~np.isfinite(residual)
        # a failed residual is a constant (derivative 0); a derivative that overflows where the
        # force does not (a candidate far out in the box) is taken as 0 too, so that a least-squares
        # step from there stays finite
        derivative = np.concatenate(derivatives, axis=1)
        derivative = np.where(failed[:, :, None] | ~np.isfinite(derivative), 0.0, derivative)
        rows = slice(residual.shape[1] - self.difference_size, residual.shape[1])
        derivative[:, rows] = np.where(failed[:, rows, None], 0.0, np.nan)
        return np.where(failed, FAILED_RESIDUAL * scale, residual), derivative

    def difference_residuals(self, matrix: np.ndarray) -> np.ndarray:
        """The last ``difference_size`` residuals of :meth:`residual_matrix` alone (the multi-axis
        tests', then the table's), shape (P, difference_size): the same bits."""
        residual = self._difference_part(matrix)
        return np.where(np.isfinite(residual), residual, FAILED_RESIDUAL / math.sqrt(self.size))

    def __call__(self, matrix: np.ndarray) -> np.ndarray:
        """Misfit of each of P candidates, shape (P,)."""
        return np.sum(self.residual_matrix(np.atleast_2d(matrix)) ** 2, axis=1)

    def test_misfits(self, matrix: np.ndarray) -> np.ndarray:
        """(NRMSE_i/noise_i)^2 on the residual samples of each test, shape (P, tests); with a
        table, a last column: its mean squared residual (in uncertainty units); multi-axis tests'
        columns come between, each the mean over its samples and axes."""
        residual = self.residual_matrix(np.atleast_2d(matrix)) * math.sqrt(self.size)
        bounds = np.cumsum([0] + [t.measured_N.size for t in self.tests] + [m.size for m in self.multiaxis]
                           + ([self.table.size] if self.table else []))
        weights = [t.driven.stride for t in self.tests] + [1] * (len(bounds) - 1 - len(self.tests))
        return np.column_stack([np.mean(residual[:, a:b] ** 2, axis=1) / w
                                for a, b, w in zip(bounds[:-1], bounds[1:], weights)])


def fit_stride(test: RigTest) -> int:
    """Every how many samples a test's force counts in the fit: a sine's samples a cycle over
    FIT_SAMPLES_PER_CYCLE, rounded down (1 at or below it, and for every other kind of test)."""
    if test.kind != "sine":
        return 1
    m = test.measurement
    frequency = record_offsets(m).frequency_hz
    if not math.isfinite(frequency) or frequency <= 0.0:
        return 1
    per_cycle = 1.0 / (frequency * float(np.median(np.diff(m.time_s))))
    return max(1, int(per_cycle // FIT_SAMPLES_PER_CYCLE))


def _check_conditions(tests, bushing: BushingModel) -> None:
    """ParameterError naming the test, for a test whose condition (its temperature) the model's
    parameter refuses (outside a temperature law's range)."""
    specs = {spec.name: spec for spec in bushing.specs}
    for test in tests:
        given = dict(getattr(test.measurement, "conditions", ()))
        for parameter, field in bushing.conditions:
            if field in given and (error := specs[parameter].range_error(given[field])) is not None:
                raise ParameterError(f"{test.name}: its {field} sets the {bushing.name} model's {error}")


def _prepared_tests(tests, noise, steps, rests, strides) -> list[PreparedTest]:
    """Each test as the objective keeps it: its driven input (its steps per sample, the force it
    holds at rest, its stride) and the measured forces it is compared at, with the noise level
    they count with (divided by sqrt(stride): each stands for stride samples)."""
    prepared = []
    for test, level, m_steps, rest, stride in zip(tests, noise, steps, rests, strides):
        m = test.measurement
        driven = replace(prepare_input(m.time_s, m.displacement_mm, m.measured_velocity_mm_s, decimate_holds=True,
                                       steps=m_steps, rest_force_N=rest, stride=stride), conditions=m.conditions)
        sigma = max(level.sigma_N, MIN_NOISE_FRACTION * level.rms_force_N)
        prepared.append(PreparedTest(test.name, driven, m.force_N[driven.sample_index],
                                     sigma / math.sqrt(stride) if stride > 1 else sigma))
    return prepared


def nrmse(predicted: np.ndarray, measured: np.ndarray) -> float:
    """RMS of the difference over the RMS of the measurement (the stricter error); infinite where
    the prediction is not finite somewhere (a simulation that failed from there on)."""
    if not np.all(np.isfinite(predicted)):
        return math.inf
    return float(np.sqrt(np.mean((predicted - measured) ** 2)) / np.sqrt(np.mean(measured ** 2)))


def rms_level_error(predicted: np.ndarray, measured: np.ndarray) -> float:
    """The paper's eq. 10: (RMS(F_exp) - RMS(F_pre)) / RMS(F_exp), a difference of RMS *levels*.

    It compares only the two signals' RMS values, so it is blind to phase and sign (a force of
    the wrong sign scores 0); :func:`nrmse` is the error the fit uses. Kept to compare with
    the paper's tables."""
    rms_measured = np.sqrt(np.mean(measured ** 2))
    return float((rms_measured - np.sqrt(np.mean(predicted ** 2))) / rms_measured)
