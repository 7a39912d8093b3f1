"""Starts from the data: the spring and the friction of a filled-rubber model from a slow loop.

A model whose box declares ``SearchBox.loop_start`` (a ``definition.SlowLoop``: the
names of its spring's k0, k3, its friction's Ff_max and x2) has a progressive spring
k0*x + k3*x^3 and Berg's friction in parallel with its rate-dependent part. On the training
test whose loop is slowest (the sine of lowest frequency) that rate-dependent part is
smallest, and the rest is nearly linear in the parameters: for a given x2, Berg's friction is
Ff_max times its shape g(x; x2) (the law is homogeneous of degree one in Ff_max and the
reversal forces), so

    F ~ k0*x + k3*x^3 + Ff_max*g(x; x2)

is a linear least-squares problem with k0, k3, Ff_max >= 0 for each x2 (scipy's lsq_linear).
The shapes for a grid of LOOP_TRAVELS values of x2 over the box come from one compiled call of
the model itself, its parameters set to leave the friction alone (``SlowLoop.friction_only``,
Ff_max = 1); the x2 with the smallest residual is then refined between its grid neighbours
(Brent's bounded search in log10 x2).
The fit's screening then adds LOOP_STARTS candidates that take these four values and the
Sobol points' other coordinates (``multistart.screen``).

Units: mm, N, N/mm, N/mm^3.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
from scipy.optimize import lsq_linear, minimize_scalar

from identification.forward.population import simulate_population_held
from identification.measured.rig_tests import RigTest
from identification.fitting.search_space import SearchSpace

LOOP_TRAVELS = 40
"""x2 values tried, log-spaced over the box's travel coordinate."""
LOOP_STARTS = 256
"""Screening candidates anchored at the loop's spring and friction."""
SETTLING_CYCLES = 1.0
"""Left out of the least squares at the test's start: the friction's loop settles in a cycle or two
from rest, and so does a Maxwell element's mean."""


@dataclass(frozen=True)
class LoopStart:
    """What the slow loop gives: the parameters, the test they come from and the fraction of its
    force they leave unexplained (the rate-dependent part, noise, and what the law misses)."""
    parameters: dict[str, float]
    source: str
    unexplained: float

    def describe(self) -> str:
        values = ", ".join(f"{name} = {value:.4g}" for name, value in self.parameters.items())
        return (f"spring and friction from the slow loop of {self.source}: {values} "
                f"({self.unexplained:.1%} of its rms force left to the rest of the model)")


@dataclass(frozen=True)
class FitStart:
    """A start from a fit of a nested model (``compare`` weighing the recommended model's variant:
    an option added to it or left out): that fit's ``parameters`` (the model's units; one the
    variant does not have is not read), the model they were fitted for (``source``), and the
    ``neutral`` values of what the variant adds (``OptionElement.neutral``: with them the variant's
    force is the fit's)."""
    parameters: dict[str, float]
    source: str
    neutral: dict[str, float] = field(default_factory=dict)

    def whole(self) -> "FitStart":
        """The fit itself as the variant's parameters: its values, the added element's neutral."""
        return FitStart({**self.neutral, **self.parameters}, self.source)

    def describe(self) -> str:
        return f"parameters of the {self.source} fit (one start the fit itself, the rest screened)"


def dominant_frequency_hz(test: RigTest) -> float:
    """The test's displacement frequency [Hz] from its mean-crossings (one cycle each two)."""
    x = test.measurement.displacement_mm - np.mean(test.measurement.displacement_mm)
    crossings = np.count_nonzero(np.signbit(x[1:]) != np.signbit(x[:-1]))
    duration = test.measurement.time_s[-1] - test.measurement.time_s[0]
    return crossings / (2.0 * duration) if duration > 0 else math.inf


def slow_loop_start(tests: Sequence[RigTest], space: SearchSpace) -> LoopStart | None:
    """The spring and friction of the slowest sine test's loop (module docstring), or None if the
    model declares no loop start or no sine test has two cycles."""
    loop = space.bushing.search.loop_start
    sines = [t for t in tests if t.kind == "sine" and dominant_frequency_hz(t) > 0]
    if loop is None or not sines:
        return None
    test = min(sines, key=dominant_frequency_hz)
    frequency = dominant_frequency_hz(test)
    m = test.measurement
    if frequency * (m.time_s[-1] - m.time_s[0]) < 2.0:
        return None
    t, x, force = m.time_s, m.displacement_mm, m.force_N
    velocity = np.append(np.diff(x) / np.diff(t), 0.0)       # the secant path through the samples
    low, high = next((c.low, c.high) for c in space.coordinates if c.parameter == loop.travel)
    travels = space.x_ref * 10.0 ** np.linspace(low, high, LOOP_TRAVELS)
    shapes = simulate_population_held([loop.friction_only(x2) for x2 in travels], t, x, velocity,
                                      model=space.bushing)
    kept = t >= t[0] + SETTLING_CYCLES / frequency

    def least_squares(shape):
        return lsq_linear(np.column_stack([x, x ** 3, shape])[kept], force[kept], bounds=(0.0, np.inf))

    def shape_of(x2):
        return simulate_population_held([loop.friction_only(x2)], t, x, velocity, model=space.bushing)[0]

    costs = [least_squares(shape).cost for shape in shapes]
    best = int(np.argmin(costs))
    # between the grid's neighbours of the best, Brent's bounded search in log10(x2)
    logs = np.log10(travels)
    refined = minimize_scalar(lambda u: least_squares(shape_of(10.0 ** u)).cost, method="bounded",
                              bounds=(logs[max(best - 1, 0)], logs[min(best + 1, logs.size - 1)]),
                              options={"xatol": 1e-3})
    x2 = 10.0 ** refined.x if refined.fun < costs[best] else travels[best]
    solution = least_squares(shape_of(x2))
    cost, (k0, k3, limit) = solution.cost, solution.x
    unexplained = math.sqrt(2.0 * cost / np.count_nonzero(kept)) / math.sqrt(float(np.mean(force[kept] ** 2)))
    values = dict(zip(loop.names, (float(k0), float(k3), float(limit), float(x2))))
    return LoopStart(values, test.name, unexplained)


def anchored_coordinates(start, space: SearchSpace) -> dict[int, float]:
    """{coordinate index: value} of a start's parameters (a slow loop's, :class:`LoopStart`, or a
    data sheet's, ``table_start.TableStart``) in the box's coordinates, clipped into the box (a
    stiffness of 0 at the box's lowest); a coordinate whose kind reads a parameter the start does
    not give, or that its values cannot say (a ratio over a stiffness of 0: a Maxwell element's
    time constant at its neutral values), is left to the screening."""
    bounds = space.bounds()
    out = {}
    for i, c in enumerate(space.coordinates):
        if c.parameter in start.parameters and all(name in start.parameters for name in c.kind.reads(c)):
            try:
                value = c.kind.to_coordinate(c, start.parameters[c.parameter], start.parameters, space)
            except ZeroDivisionError:
                continue
            out[i] = float(np.clip(value, bounds[i, 0], bounds[i, 1]))
    return out
