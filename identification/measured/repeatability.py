"""What a periodic test repeats from cycle to cycle: the floor no model driven by the
displacement can go below.

A model driven by the displacement alone gives the same force on every cycle of a steady sine.
Whatever in the measured force changes from one steady cycle to the next (the rig's chatter, a
device that does not quite repeat) no such model can follow, however good. Its size is the
*repeatability*:

    sigma_rep = sqrt( mean over consecutive steady cycles and over the samples of a cycle of
                      (F_c+1(tau) - (F_c(tau) + F_c+2(tau))/2)^2 / 1.5 ),

the rms of the part of the force that does not repeat: for white noise of standard deviation
sigma it is sigma (the second difference of three independent samples has variance
1.5*sigma^2), and a slow drift of the cycles, which a model follows (a long relaxation: 0.27 % of
the rms force from cycle to cycle in the noise-free Table 5 force on the 2 mm, 10 Hz sine),
cancels. Where only two consecutive steady cycles exist (a rig's sine with three cycles at full
range), the first difference (F_c+1 - F_c)^2 / 2 takes its place. Expressed,
as the noise level is, as a fraction of the whole record's rms force, it is the NRMSE of a model
that repeats the device's mean cycle exactly.

The cycles. Their boundaries are the displacement's upward crossings of its mid level
((max + min)/2), counted only after the displacement has been below the mid level by a quarter of
its half range, so that noise at a crossing cannot start a second cycle (a Schmitt trigger); the
crossing time is interpolated between the two samples. A cycle is *steady* when its displacement
range is within ``AMPLITUDE_TOLERANCE`` of the largest cycle's, and so was the range of the cycle
before it: the first cycle at full range still carries the start from rest or the end of a
ramp-in, which a model driven by the displacement follows (measured on the real friction
damper's 1 Hz, 1.5 in sine: 24 % of the rms force between the first and second cycles at full
range, 6.8 % between the second and third). Cycle c+1 is read at the times of
cycle c's samples shifted by the difference of their start times, interpolated linearly between
its samples: for white noise this reads sigma_rep low by at most 13 % (half a sample's shift),
and exactly for a force that repeats.

Fewer than two consecutive steady cycles (a sine too short, or no sine at all) give no
repeatability: the floor is then the noise level alone, and the
:class:`Repeatability` says why (``reason``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

AMPLITUDE_TOLERANCE = 0.02
"""A cycle whose displacement range is within 2 % of the largest cycle's is steady (the ramp-in
and ramp-out cycles of a rig's sine are not)."""
MIN_GROUPS = 1
"""Groups of consecutive steady cycles (three, or else two) the estimate needs."""
TRIGGER_FRACTION = 0.25
"""The Schmitt trigger's band: a crossing counts after the displacement has been a quarter of its
half range below the mid level."""


@dataclass(frozen=True)
class Repeatability:
    """What a periodic test repeats: ``sigma_N`` the rms force that differs between consecutive
    steady cycles [N] (``nan`` where it cannot be told: ``reason`` says why), ``rms_force_N``
    the record's rms force [N], ``period_s`` the median cycle [s], ``groups`` the groups of
    consecutive steady cycles it is taken over, ``differences`` their order (2: second differences
    of three cycles, 1: differences of two)."""
    sigma_N: float
    rms_force_N: float
    period_s: float = float("nan")
    groups: int = 0
    reason: str = ""
    differences: int = 0

    @property
    def known(self) -> bool:
        return bool(np.isfinite(self.sigma_N))

    @property
    def relative(self) -> float:
        """sigma_N as a fraction of the record's rms force (nan where unknown)."""
        return self.sigma_N / self.rms_force_N if self.rms_force_N > 0 else float("nan")

    def describe(self) -> str:
        """In words, for reports."""
        if not self.known:
            return f"repeatability unknown ({self.reason})"
        what = "triple" if self.differences == 2 else "pair"
        return (f"{self.relative:.2%} of the rms force differs between consecutive steady cycles "
                f"({self.groups} {what}{'s' if self.groups != 1 else ''} of {self.period_s:.4g} s cycles)")


def cycle_starts(time_s, displacement_mm) -> np.ndarray:
    """The start times [s] of the displacement's cycles: its upward crossings of the mid level,
    each after the displacement has been TRIGGER_FRACTION of its half range below it (module
    docstring); interpolated between samples."""
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(displacement_mm, dtype=float)
    mid = 0.5 * (np.max(x) + np.min(x))
    low = mid - TRIGGER_FRACTION * 0.5 * (np.max(x) - np.min(x))
    starts = []
    armed = False
    for k in range(1, x.size):
        if x[k - 1] < low:
            armed = True
        if armed and x[k - 1] < mid <= x[k]:
            starts.append(t[k - 1] + (mid - x[k - 1]) / (x[k] - x[k - 1]) * (t[k] - t[k - 1]))
            armed = False
    return np.array(starts)


def estimate_repeatability(time_s, displacement_mm, force_N) -> Repeatability:
    """The repeatability of a sine test (module docstring): never raises; a record without
    two consecutive steady cycles gives ``sigma_N = nan`` and the reason."""
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(displacement_mm, dtype=float)
    force = np.asarray(force_N, dtype=float)
    rms = float(np.sqrt(np.mean(force ** 2))) if force.size else 0.0
    if t.size < 3 or not (np.ptp(x) > 0):
        return Repeatability(float("nan"), rms, reason="the displacement does not move")
    starts = cycle_starts(t, x)
    if starts.size < 3:
        return Repeatability(float("nan"), rms, reason=f"{max(starts.size - 1, 0)} full cycle(s) in the record; "
                             f"three at full range are needed")
    ranges = np.array([np.ptp(x[(t >= a) & (t < b)]) for a, b in zip(starts[:-1], starts[1:])])
    full = ranges >= (1.0 - AMPLITUDE_TOLERANCE) * np.max(ranges)
    steady = full & np.concatenate([[False], full[:-1]])      # at the full range after a cycle at it
    period = float(np.median(np.diff(starts)))
    triples = [c for c in range(ranges.size - 2) if steady[c] and steady[c + 1] and steady[c + 2]]
    if triples:
        # second differences F_c+1 - (F_c + F_c+2)/2: a slow drift of the cycles (a long relaxation the
        # model follows) cancels; white noise of sigma gives variance 1.5*sigma^2
        groups, variance = [(c, (-0.5, 1.0, -0.5)) for c in triples], 1.5
    else:
        groups, variance = [(c, (-1.0, 1.0)) for c in range(ranges.size - 1) if steady[c] and steady[c + 1]], 2.0
    if len(groups) < MIN_GROUPS:
        return Repeatability(float("nan"), rms, period, 0,
                             f"{int(np.count_nonzero(steady))} steady cycle(s) of {ranges.size} (a cycle at "
                             f"full range, within {AMPLITUDE_TOLERANCE:.0%} of the largest, after another); two "
                             "consecutive ones are needed")
    squares, samples = 0.0, 0
    for c, weights in groups:
        inside = (t >= starts[c]) & (t < starts[c + 1])
        difference = np.zeros(int(np.count_nonzero(inside)))
        for j, weight in enumerate(weights):
            difference += weight * np.interp(t[inside] + (starts[c + j] - starts[c]), t, force)
        squares += float(np.sum(difference ** 2))
        samples += difference.size
    return Repeatability(float(np.sqrt(squares / samples / variance)), rms, period, len(groups),
                         differences=len(weights) - 1)
