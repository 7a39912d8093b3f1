"""A bushing's static force-deflection curve read off a quasi-static test: the backbone's knots.

A slow triangle or ramp that loads and unloads the bushing traces two branches: the force while
the displacement rises and while it falls. Their mean at a displacement is the elastic part, the
*backbone* (``fmu_src.model.derived``: ``backbone<K>``); half their difference is what the
hysteresis adds (the friction's level, for a filled rubber or a friction device).

At each knot x_i each branch's force is the value at x_i of the straight line fitted by least
squares to its samples within ``WINDOW`` of the nearest knot spacing of x_i (noise averages out,
a test with several passes is averaged over them, and a steep slope does not bias it), the knot's
force the mean of the two. The window trades noise for curvature: across a corner of the curve
whose slope changes by dk it reads dk*a/4 high (a its half width: 3 N for 250 N/mm over
+-0.05 mm), while a slow triangle at 200 Hz puts some 10 to 50 samples of each pass into it. A backbone is monotone: where noise makes the knots' forces
decrease somewhere, they are replaced by their isotonic regression (scipy), and the curve says
so. The first loading from rest, up to the first reversal, is not on the loop (the hysteresis
starts from nothing there) and is left out. Near the ends of the range the branch that leaves an
end has only just reversed, and its hysteresis has not yet turned (an 80 N friction of stiffness
600 N/mm takes 0.27 mm): at the two end knots the backbone is the branch that arrives there, less
the half difference of the next knot in. The knots: given, or ``count`` of them evenly spaced
over the range both branches cover, ``INSET`` of that range in from its ends, the one nearest 0
moved to 0 where 0 lies inside (so that a backbone pinned to pass through 0 there, with the rig's
load-cell zero fitted beside it, has a knot to pin).

Units: displacement mm, force N. Every problem is a ``MeasurementError`` naming the test, the knot
and what is missing.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from identification.errors import MeasurementError
from identification.measured.measurements import Measurement

DEFAULT_KNOTS = 9
"""Knots when none are given: enough for a void's corner and a bump stop on a +-5 mm curve."""
MIN_SAMPLES_PER_BRANCH = 3
"""Samples of each branch a knot needs within its window."""
WINDOW = 0.05
"""A knot's window, each way, as a fraction of its nearest knot spacing."""
INSET = 0.02
"""The default knots' distance from the ends of the range both branches cover, as a fraction of it."""


@dataclass(frozen=True)
class StaticCurve:
    """The backbone read off a quasi-static test: knots [mm], their forces [N] (the branches'
    mean), the branches' half difference there [N] (what the hysteresis adds), whether the forces
    were made monotone (``adjusted``) and the test's name."""
    knots_mm: np.ndarray
    forces_N: np.ndarray
    half_width_N: np.ndarray
    adjusted: bool
    source: str = ""

    @property
    def count(self) -> int:
        return int(self.knots_mm.size)

    def parameters(self, pinned_at_zero: bool = False) -> dict[str, float]:
        """The backbone's parameters (``backbone_x1``... [mm], ``backbone_F1``... [N]); with
        ``pinned_at_zero`` the forces less the force at the knot at 0 (whose force a rig's
        load-cell zero then carries)."""
        forces = self.forces_N - (self.force_at_zero if pinned_at_zero else 0.0)
        out = {f"backbone_x{i + 1}": float(x) for i, x in enumerate(self.knots_mm)}
        out.update({f"backbone_F{i + 1}": float(f) for i, f in enumerate(forces)})
        return out

    @property
    def force_at_zero(self) -> float:
        """The force [N] at the knot at 0 mm (MeasurementError if there is none)."""
        at = np.flatnonzero(self.knots_mm == 0.0)
        if at.size == 0:
            raise MeasurementError(f"{self.source}: no knot at 0 mm to pin the backbone at (knots "
                                   f"{', '.join(f'{x:g}' for x in self.knots_mm)} mm)")
        return float(self.forces_N[at[0]])

    def describe(self) -> str:
        knots = ", ".join(f"{x:g}" for x in self.knots_mm)
        return (f"backbone of {self.count} knots read off {self.source} (at {knots} mm; the branches' half difference "
                f"{np.min(self.half_width_N):.4g} to {np.max(self.half_width_N):.4g} N"
                + ("; made monotone" if self.adjusted else "") + ")")


def default_knots(low: float, high: float, count: int) -> np.ndarray:
    """``count`` knots over [low, high] mm, INSET of the range in from its ends, the one nearest 0
    at 0 where 0 lies inside."""
    inset = INSET * (high - low)
    knots = np.linspace(low + inset, high - inset, count)
    if knots[0] < 0.0 < knots[-1]:
        knots[np.argmin(np.abs(knots))] = 0.0
    return knots


def read_static_curve(measurement: Measurement, knots_mm=None, count: int = DEFAULT_KNOTS) -> StaticCurve:
    """The backbone of a quasi-static test (module docstring) at ``knots_mm`` (increasing, mm),
    or at ``count`` knots spread over its range."""
    x = np.asarray(measurement.displacement_mm, dtype=float)
    force = np.asarray(measurement.force_N, dtype=float)
    name = measurement.source or "the quasi-static test"
    rising = np.gradient(x, measurement.time_s)
    moving = np.flatnonzero(rising != 0.0)
    turns = moving[1:][np.sign(rising[moving[1:]]) != np.sign(rising[moving[:-1]])] if moving.size else moving
    on_loop = np.arange(x.size) >= (turns[0] if turns.size else x.size)      # after the first reversal
    up, down = on_loop & (rising > 0.0), on_loop & (rising < 0.0)
    if np.count_nonzero(up) < MIN_SAMPLES_PER_BRANCH or np.count_nonzero(down) < MIN_SAMPLES_PER_BRANCH:
        raise MeasurementError(f"{name}: a quasi-static test must load and unload the bushing (a triangle or a "
                               "ramp up and back); this one moves one way only")
    low = max(np.min(x[up]), np.min(x[down]))
    high = min(np.max(x[up]), np.max(x[down]))
    if knots_mm is None:
        if count < 2:
            raise MeasurementError(f"{name}: a backbone needs 2 knots or more, not {count}")
        knots = default_knots(low, high, count)
    else:
        knots = np.asarray(knots_mm, dtype=float)
        if knots.ndim != 1 or knots.size < 2 or np.any(np.diff(knots) <= 0.0):
            raise MeasurementError(f"backbone knots {list(knots_mm)} [mm]: give 2 or more, increasing")
    spacing = np.diff(knots)
    window = WINDOW * np.minimum(np.append(spacing, np.inf), np.insert(spacing, 0, np.inf))
    branches = []
    for mask, word in ((up, "loading"), (down, "unloading")):
        means = []
        for knot, half in zip(knots, window):
            near = mask & (np.abs(x - knot) <= half)
            if np.count_nonzero(near) < MIN_SAMPLES_PER_BRANCH:
                raise MeasurementError(f"{name}: the {word} branch has {np.count_nonzero(near)} samples within "
                                       f"{half:.3g} mm of the knot at {knot:g} mm (it needs "
                                       f"{MIN_SAMPLES_PER_BRANCH}); the test covers {low:.3g} to {high:.3g} mm both "
                                       "ways: give knots inside that, or fewer")
            offset = x[near] - knot
            if np.ptp(offset) > 0.0:    # the line's value at the knot
                slope, intercept = np.polyfit(offset, force[near], 1)
                means.append(float(intercept))
            else:
                means.append(float(np.mean(force[near])))
        branches.append(np.array(means))
    loading, unloading = branches
    forces = 0.5 * (loading + unloading)
    if knots.size >= 3:       # the end knots from the branch that arrives there (module docstring)
        forces[0] = unloading[0] + 0.5 * (loading[1] - unloading[1])
        forces[-1] = loading[-1] - 0.5 * (loading[-2] - unloading[-2])
    adjusted = bool(np.any(np.diff(forces) < 0.0))
    if adjusted:
        from scipy.optimize import isotonic_regression
        forces = np.asarray(isotonic_regression(forces).x, dtype=float)
    return StaticCurve(knots, forces, 0.5 * (loading - unloading), adjusted, name)
