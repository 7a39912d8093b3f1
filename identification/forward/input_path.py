"""The forward model's input: a sampled test turned into the path the kernels are driven along.

The identification's forward model is eqs. 1-5 (any model's equations) driven by a smooth
interpolant of a sampled test; this module prepares that input (``prepare_input``, and
``prepare_vector_input`` for a multi-axis test), ``identification.simulate`` runs it.

A measured test gives the displacement at the sample instants only. The FMU, as a
co-simulation slave, holds the velocity set by the master over each communication step
(``population.simulate_population_held``); fed with a measurement that way, it differs
from the continuous-time model of eqs. 1-5 by 0.2-0.7 times a 1 % force-noise level on a
10 Hz sine at 1 kHz, and by 1-6 times on a 30 Hz sine: more than a fit to the noise floor
can afford. Most of it (a first-order error) is the viscous feedthrough of eq. 5 evaluated
with the interval's velocity instead of the velocity at the sample instant; the rest is
the input path between samples. So the fit drives the same compiled kernel with:

- the input: a cubic spline through the sampled displacement (not-a-knot), or, where the
  test gives its velocity too, the cubic Hermite interpolant of both; each sample interval
  split into ``m`` equal communication steps with the interpolant's displacement at their
  ends and the secant velocity over each (a continuous piecewise-linear path, no jumps),
  where ``m`` is the smallest number such that the input turns by at most
  ``MAX_PHASE_PER_STEP_RAD`` per step (with the test's rms frequency rms(x'')/rms(x'); for a
  displacement measured with noise, x'' over several samples, not the noise's: ``turning_rate``); the
  fit raises it where the candidate's response is sharper than the input
  (``identification.fitting.refinement``);
- the output: eq. 5 at each sample instant with the interpolant's velocity there.

It converges, as the step shrinks, to the continuous-time solution driven by the
interpolant (``tests/identification/forward/test_forward_model.py``: at the truth, below 0.1 times a 1 % noise level
on 1 kHz sines at 10 and 30 Hz, against scipy's Radau on the paper's equations).

Where the displacement holds exactly still for a long run (a step test's hold), the forces
of only every ``HOLD_DECIMATION``-th sample can be asked for (``decimate_holds``): the input
is constant there, so one long communication step is as exact as ten short ones, and the
step test costs a fifth.

Where a periodic test samples each cycle far more finely than a fit needs (a rig's slow sine at
1024 Hz: 4096 samples a cycle at 0.25 Hz), the forces of only every ``stride``-th sample can be
asked for: the path still follows the interpolant through every sample, in steps chosen by the
same turning rule over the stride's interval, so the cost falls with the samples asked for
(``identification.fitting.objectives``: ``FIT_SAMPLES_PER_CYCLE``).

Units: time in s, displacement in mm, velocity in mm/s, force in N.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicHermiteSpline, CubicSpline

from identification.measured.noise import MIN_SAMPLES, estimate_noise

MAX_PHASE_PER_STEP_RAD = 0.07
MAX_STEPS_PER_SAMPLE = 8
NOISY_SHARE = 0.1
"""A displacement whose noise makes more than this share of its sample-scale x'' is read for its
turning over several samples (:func:`turning_rate`)."""
WIDE_PHASE_RAD = 0.1
"""The phase of the input's mean frequency a noisy displacement's wide second difference spans."""
HOLD_DECIMATION = 10
HOLD_SETTLE_SAMPLES = 10
"""Samples next to a change of the displacement (after it and before it) that a decimated hold
keeps: a cubic spline through a ramp's corner rings into the hold by a factor 0.27 per sample."""


@dataclass(frozen=True)
class DrivenInput:
    """A sampled test prepared for the compiled kernel.

    ``time_s``, ``displacement_mm``, ``velocity_mm_s``: the communication points, the
    interpolant's displacement there and the secant velocity of each step (last entry 0);
    ``output_index``: the communication points that are samples whose force is computed,
    ``sample_index``: which samples of the test they are, ``output_velocity_mm_s``: the
    interpolant's velocity there; ``steps_per_sample``: m; ``rest_force_N``: the force the test
    holds at rest before it moves (``offsets.held_force``), NaN: none.
    """
    time_s: np.ndarray
    displacement_mm: np.ndarray
    velocity_mm_s: np.ndarray
    output_index: np.ndarray
    sample_index: np.ndarray
    output_velocity_mm_s: np.ndarray
    steps_per_sample: int
    rest_force_N: float = math.nan
    """The force [N] the run starts holding at rest (a model with a resting state); NaN: relaxed."""
    stride: int = 1
    """The forces of every ``stride``-th sample are asked for (1: every sample's, holds aside);
    ``steps_per_sample`` is then per stride's interval."""
    conditions: tuple[tuple[str, float], ...] = ()
    """The test's conditions, (``Measurement`` field, value): ``temperature_K`` [K] sets a model's
    temperature (``BushingModel.conditions``, ``population.conditioned``); a prepared input takes
    them with ``dataclasses.replace``."""


def steps_per_sample(time_s: np.ndarray, displacement_mm: np.ndarray, velocity_mm_s: np.ndarray,
                     interpolant, stride: int = 1) -> int:
    """m: communication steps per sample interval (per ``stride`` sample intervals) so that the
    input turns by at most MAX_PHASE_PER_STEP_RAD per step at its rms frequency rms(x'')/rms(x')
    (capped at MAX_STEPS_PER_SAMPLE); x'' the interpolant's at the samples, or, where the
    displacement is measured with noise, its second differences over several samples
    (:func:`turning_rate`)."""
    rms_velocity = math.sqrt(float(np.mean(velocity_mm_s ** 2)))
    if rms_velocity == 0.0:
        return 1
    h = float(np.median(np.diff(time_s)))
    rms_acceleration = turning_rate(displacement_mm, h, rms_velocity)
    if rms_acceleration is None:
        rms_acceleration = math.sqrt(float(np.mean(interpolant(time_s, 2) ** 2)))
    phase = rms_acceleration / rms_velocity * h * stride
    return int(min(MAX_STEPS_PER_SAMPLE, max(1, math.ceil(phase / MAX_PHASE_PER_STEP_RAD))))


def turning_rate(displacement_mm: np.ndarray, h: float, rms_velocity: float) -> float | None:
    """rms(x'') [mm/s^2] of a displacement measured with noise, or None where its noise is too
    small to matter (a signal computed, not measured: then the interpolant's x'' at the samples
    counts, which the noise would otherwise dominate).

    At the sample scale white noise of sigma gives the second difference
    (x_k+1 - 2x_k + x_k-1)/h^2 an rms of sqrt(6)*sigma/h^2, which on a rig's slow sine is many
    times the signal's (on the real friction damper's 0.5 Hz sine, 1.5 um of displacement noise
    and the rig's velocity signal read as 1.6e4 mm/s^2 against the sine's 1.5e2). Where that
    share exceeds NOISY_SHARE of the interpolant's rms x'', the second differences over w samples
    count instead, w the widest that keeps WIDE_PHASE_RAD of the input's mean frequency
    rms(x')/rms(x - mean) within the window: their noise is w^2 times smaller. The noise is the
    eighth-difference estimate (``identification.measured.noise``), which a ramp's corners do not
    raise."""
    x = np.asarray(displacement_mm, dtype=float)
    if x.size < max(MIN_SAMPLES, 3):
        return None
    sigma = estimate_noise(x).sigma_N          # the estimator reads any signal; here mm
    spread = math.sqrt(float(np.mean((x - np.mean(x)) ** 2)))
    if spread == 0.0:
        return None
    second = np.diff(x, 2) / h ** 2
    if math.sqrt(6.0) * sigma / h ** 2 <= NOISY_SHARE * math.sqrt(float(np.mean(second ** 2))):
        return None
    w = max(1, int(WIDE_PHASE_RAD / (rms_velocity / spread * h)))
    if 2 * w >= x.size:
        return None
    wide = (x[2 * w:] - 2.0 * x[w:-w] + x[:-2 * w]) / (w * h) ** 2
    return math.sqrt(float(np.mean(wide ** 2)))


def prepare_input(time_s, displacement_mm, velocity_mm_s=None, decimate_holds: bool = False,
                  steps: int | None = None, rest_force_N: float = math.nan, stride: int = 1) -> DrivenInput:
    """The driven input of a sampled test (see the module docstring). ``velocity_mm_s``: the
    test's velocity at the samples if known (then the Hermite interpolant is used);
    ``steps``: force m instead of choosing it; ``rest_force_N``: the force [N] the run starts
    holding at rest (NaN: relaxed); ``stride``: the forces of every stride-th sample only (the
    first, and the holds' as ``decimate_holds`` says)."""
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(displacement_mm, dtype=float)
    if not (t.ndim == 1 and t.shape == x.shape and t.size >= 2):
        raise ValueError(f"time and displacement must be 1-D arrays of equal length >= 2, "
                         f"got shapes {t.shape}, {x.shape}")
    if np.any(np.diff(t) <= 0.0):
        raise ValueError("time must increase from sample to sample")
    if velocity_mm_s is None:
        interpolant = CubicSpline(t, x) if t.size >= 4 else CubicHermiteSpline(t, x, np.gradient(x, t))
    else:
        v = np.asarray(velocity_mm_s, dtype=float)
        if v.shape != t.shape:
            raise ValueError(f"velocity has shape {v.shape}, time {t.shape}")
        interpolant = CubicHermiteSpline(t, x, v)
    sample_velocity = interpolant(t, 1)
    stride = int(stride)
    if stride < 1:
        raise ValueError(f"stride = {stride}: give 1 (every sample's force) or more")
    m = steps or steps_per_sample(t, x, sample_velocity, interpolant, stride)

    keep = _held_samples_to_skip(x) if decimate_holds else np.zeros(t.size, dtype=bool)
    if stride > 1:
        keep |= np.arange(t.size) % stride != 0
    sample_index = np.flatnonzero(~keep)
    # Communication points: m per kept interval between consecutive kept samples that are
    # neighbours or a stride apart along a moving input; one across a decimated hold (there the
    # displacement is constant).
    pieces_t, pieces_x = [t[:1]], [x[:1]]
    for start, end in zip(sample_index[:-1], sample_index[1:]):
        if end > start + 1 and np.any(x[start:end + 1] != x[start]):     # a stride's interval, moving
            fine = t[start] + (t[end] - t[start]) * np.arange(1, m + 1) / m
            fine[-1] = t[end]
            values = interpolant(fine)
            values[-1] = x[end]
        elif end == start + 1 and m > 1:
            fine = t[start] + (t[end] - t[start]) * np.arange(1, m + 1) / m
            fine[-1] = t[end]
            values = interpolant(fine)
            values[-1] = x[end]
        else:
            fine, values = t[end:end + 1], x[end:end + 1]
        pieces_t.append(fine)
        pieces_x.append(values)
    grid_t = np.concatenate(pieces_t)
    grid_x = np.concatenate(pieces_x)
    grid_v = np.append(np.diff(grid_x) / np.diff(grid_t), 0.0)
    output_index = np.searchsorted(grid_t, t[sample_index])
    return DrivenInput(grid_t, grid_x, grid_v, output_index, sample_index, sample_velocity[sample_index], m,
                       float(rest_force_N), stride)


def _held_samples_to_skip(x: np.ndarray) -> np.ndarray:
    """True for the samples whose force a decimated hold does not compute: inside runs of
    exactly equal displacement, more than HOLD_SETTLE_SAMPLES from either end of the run, all
    but every HOLD_DECIMATION-th."""
    skip = np.zeros(x.size, dtype=bool)
    same = np.append(False, x[1:] == x[:-1])   # x_k equals x_(k-1)
    k = 0
    while k < x.size:
        if not same[k]:
            k += 1
            continue
        end = k
        while end + 1 < x.size and same[end + 1]:
            end += 1
        # samples k-1 .. end hold the same displacement
        first, last = k - 1 + HOLD_SETTLE_SAMPLES, end - HOLD_SETTLE_SAMPLES
        if last > first:
            inner = np.arange(first, last + 1)
            skip[inner[(inner - first) % HOLD_DECIMATION != 0]] = True
        k = end + 1
    return skip


@dataclass(frozen=True)
class DrivenVectorInput:
    """A sampled multi-axis test prepared for the compiled kernels: each axis's
    :class:`DrivenInput` (``components``) on one common grid of communication points (the same
    steps per sample for every axis, no decimated holds), and the same arrays stacked by axis:
    ``displacement_mm``, ``velocity_mm_s`` (points, d), ``output_velocity_mm_s`` (outputs, d)."""
    components: tuple[DrivenInput, ...]

    @property
    def time_s(self) -> np.ndarray:
        return self.components[0].time_s

    @property
    def output_index(self) -> np.ndarray:
        return self.components[0].output_index

    @property
    def sample_index(self) -> np.ndarray:
        return self.components[0].sample_index

    @property
    def steps_per_sample(self) -> int:
        return self.components[0].steps_per_sample

    @property
    def displacement_mm(self) -> np.ndarray:
        return np.column_stack([c.displacement_mm for c in self.components])

    @property
    def velocity_mm_s(self) -> np.ndarray:
        return np.column_stack([c.velocity_mm_s for c in self.components])

    @property
    def output_velocity_mm_s(self) -> np.ndarray:
        return np.column_stack([c.output_velocity_mm_s for c in self.components])


def prepare_vector_input(time_s, displacement_mm, velocity_mm_s=None, steps: int | None = None) -> DrivenVectorInput:
    """The driven input of a sampled multi-axis test, ``displacement_mm`` (samples, d) [mm] (and
    its measured ``velocity_mm_s`` (samples, d) [mm/s], if any): each axis as
    :func:`prepare_input` drives it, with the steps per sample the most any axis's signal asks for
    (or ``steps``), so that the axes share one grid. Every sample is an output (a hold is decimated
    only where every axis holds, which the grid cannot share; it is not worth it here)."""
    x = np.atleast_2d(np.asarray(displacement_mm, dtype=float))
    v = None if velocity_mm_s is None else np.atleast_2d(np.asarray(velocity_mm_s, dtype=float))
    axes = range(x.shape[1])
    if steps is None:
        steps = max(prepare_input(time_s, x[:, c], None if v is None else v[:, c]).steps_per_sample for c in axes)
    return DrivenVectorInput(tuple(prepare_input(time_s, x[:, c], None if v is None else v[:, c], steps=steps)
                                   for c in axes))
