"""The zeros a record shows before any model is fitted: where its stroke is centred, the force it
holds at rest, the mean force of its steady cycles, and whether it is quasi-static.

A bushing, or a friction device, fitted by a model of zero mean (its force odd in a displacement
about its own zero: every model here without the rig's offsets) cannot say a stroke that is not
centred on that zero or a force that is not centred on 0. A rig gives both: its displacement
zero is where the actuator was set, its load cell's zero drifts, and a one-sided stroke (a
damper pushed from 0 to 25 mm, a mount tested about its preload) is common. What is read here:

- the **stroke's centre** [mm]: (max + min)/2 of the displacement of a periodic test (a sine),
  over the record; its **half range** [mm] beside it;
- the **force at rest** [N]: the median force over the record's first samples while the
  displacement has not moved (by less than ``REST_MOTION`` of its range, for at least
  ``MIN_REST_SAMPLES`` samples and ``MIN_REST_S``): what the device holds before it is driven,
  for a bushing at its own zero a load cell's zero, for a friction device the force the test
  before left in it; NaN where the record does not start at rest;
- the **mean force of the cycles** [N]: the mean over the whole cycles between the first and the
  last upward crossing of the stroke's centre (``repeatability.cycle_starts``), so that a ramp-in
  and a part cycle do not weigh;
- **quasi-static**: a periodic test of at most ``QUASI_STATIC_HZ`` (a slow triangle or sine that
  loads and unloads the device: its backbone can be read off it, ``static_curve``);
- the **held force** [N]: the force at rest where it counts (beyond ``OFFSET_FORCE`` of the force's
  half range and ``NOISE_LEVELS`` of its noise level), which a model that can hold a force at rest
  starts a run holding (``held_force``).

Units: mm, N, s, Hz.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from identification.measured.measurements import Measurement
from identification.measured.noise import estimate_noise
from identification.measured.repeatability import cycle_starts

REST_MOTION = 0.002
"""The displacement is at rest while it stays within this fraction of its range of the first sample."""
MIN_REST_SAMPLES = 20
MIN_REST_S = 0.05
"""A rest shorter than these (samples and seconds) is not read: its force is the start of the motion."""
BRIEF_REST_SAMPLES, BRIEF_REST_S = 5, 0.005
"""A start at rest shorter than these is no rest at all (a motion's first samples)."""
OFFSET_FORCE = 0.02
"""A force at rest, or a cycles' mean force, beyond this fraction of the record's force half range..."""
NOISE_LEVELS = 5.0
"""...and beyond this many of its noise levels is an offset no model of zero mean says."""
QUASI_STATIC_HZ = 0.1
"""A periodic test at most this slow is quasi-static (the rate-dependent part of a filled rubber is
a few per cent of its force there; a rig's slow triangle for a static curve runs at 0.01-0.1 Hz)."""


@dataclass(frozen=True)
class RecordOffsets:
    """What one record shows (module docstring): ``centre_mm`` and ``half_range_mm`` of its stroke,
    ``rest_force_N`` (NaN: it does not start at rest) and ``rest_s`` (how long it rests),
    ``cycle_mean_force_N`` (NaN: fewer than one whole cycle), ``force_half_range_N``,
    ``frequency_hz`` of its cycles (NaN: fewer than two crossings), ``start_mm`` its first
    displacement, and ``name``."""
    name: str
    start_mm: float
    centre_mm: float
    half_range_mm: float
    rest_force_N: float
    rest_s: float
    cycle_mean_force_N: float
    force_half_range_N: float
    frequency_hz: float

    @property
    def one_sided(self) -> float:
        """The stroke's centre as a fraction of its half range (0: centred, 1: from 0 one way)."""
        return abs(self.centre_mm) / self.half_range_mm if self.half_range_mm > 0 else 0.0

    @property
    def quasi_static(self) -> bool:
        return math.isfinite(self.frequency_hz) and self.frequency_hz <= QUASI_STATIC_HZ


def _rest(measurement: Measurement) -> tuple[int, float]:
    """(the samples, how long [s]) the displacement rests at its first value (within REST_MOTION
    of its range): the whole record where it never moves."""
    x, t = measurement.displacement_mm, measurement.time_s
    span = float(np.ptp(x))
    moved = np.flatnonzero(np.abs(x - x[0]) > REST_MOTION * span) if span > 0 else np.array([], dtype=int)
    end = int(moved[0]) if moved.size else x.size
    return end, float(t[end - 1] - t[0]) if end > 0 else 0.0


def rest_at_start(measurement: Measurement) -> tuple[float, float]:
    """(the median force [N] while the displacement rests at its first value, how long [s]), or
    (NaN, the rest's length) where the rest is shorter than MIN_REST_SAMPLES and MIN_REST_S."""
    end, rest_s = _rest(measurement)
    if end < MIN_REST_SAMPLES or rest_s < MIN_REST_S:
        return math.nan, rest_s
    return float(np.median(measurement.force_N[:end])), rest_s


def record_offsets(measurement: Measurement) -> RecordOffsets:
    """The offsets one record shows (module docstring); never raises."""
    t, x, force = measurement.time_s, measurement.displacement_mm, measurement.force_N
    high, low = float(np.max(x)), float(np.min(x))
    rest_force, rest_s = rest_at_start(measurement)
    starts = cycle_starts(t, x) if high > low else np.array([])
    mean_force = frequency = math.nan
    if starts.size >= 2:
        inside = (t >= starts[0]) & (t < starts[-1])
        if np.any(inside):
            mean_force = float(np.mean(force[inside]))
        frequency = float(1.0 / np.median(np.diff(starts)))
    return RecordOffsets(measurement.source, float(x[0]), 0.5 * (high + low), 0.5 * (high - low), rest_force, rest_s, mean_force,
                         0.5 * float(np.ptp(force)), frequency)


def rig_zeros(offsets, steps=()) -> tuple[float, float]:
    """(displacement zero [mm], force zero [N]) that a set of records from one rig shows, where a
    model of zero mean sits: the median stroke centre and cycle mean force of the periodic
    records (those with whole cycles, not steps, ``steps`` marking which are); without any, the
    median first displacement and force at rest of those that start at rest; 0 where neither
    says. The centre of a box the fit searches the rig's offsets in, not their fitted values."""
    steps = list(steps) or [False] * len(offsets)
    periodic = [r for r, is_step in zip(offsets, steps) if not is_step and math.isfinite(r.cycle_mean_force_N)]
    if periodic:
        return (float(np.median([r.centre_mm for r in periodic])),
                float(np.median([r.cycle_mean_force_N for r in periodic])))
    resting = [r for r in offsets if math.isfinite(r.rest_force_N)]
    if resting:
        return float(np.median([r.start_mm for r in resting])), float(np.median([r.rest_force_N for r in resting]))
    return 0.0, 0.0


def offset_floor(measurement: Measurement, offsets: RecordOffsets | None = None) -> float:
    """The force [N] an offset of this record must exceed to count: OFFSET_FORCE of its force half
    range and NOISE_LEVELS of its noise level, whichever is more."""
    offsets = offsets or record_offsets(measurement)
    try:
        noise = estimate_noise(measurement.force_N).sigma_N
    except ValueError:
        noise = 0.0
    return max(OFFSET_FORCE * offsets.force_half_range_N, NOISE_LEVELS * noise)


def short_rest(measurement: Measurement) -> tuple[float, float] | None:
    """(the median force [N], how long [s]) of a rest at the start too short to count as one
    (fewer than MIN_REST_SAMPLES samples or shorter than MIN_REST_S) whose force exceeds the
    record's offset floor; None where there is no such rest, or no motion. A start shorter than
    BRIEF_REST_SAMPLES samples or BRIEF_REST_S is no rest at all."""
    if float(np.ptp(measurement.displacement_mm)) <= 0.0:
        return None
    end, rest_s = _rest(measurement)
    if end < BRIEF_REST_SAMPLES or rest_s < BRIEF_REST_S or (end >= MIN_REST_SAMPLES and rest_s >= MIN_REST_S):
        return None
    force = float(np.median(measurement.force_N[:end]))
    return (force, rest_s) if abs(force) > offset_floor(measurement) else None


def held_force(measurement: Measurement) -> float:
    """The force [N] a record holds at rest before it moves (:func:`rest_at_start`) where it counts
    (:func:`offset_floor`): what a model that can hold a force at rest starts holding
    (``BushingModel.resting_state``); NaN where the record does not start at rest or holds no
    more than that (a run then starts relaxed, as it always did)."""
    force, _ = rest_at_start(measurement)
    if math.isfinite(force) and abs(force) > offset_floor(measurement):
        return force
    return math.nan
