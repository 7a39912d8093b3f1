"""``series``: a compliance in series with the device (what Altair calls a mount's stiffness): the
base and the options before it (the device) sit on a linear spring of compliance
``series_compliance`` [mm/N], so the displacement x splits into the device's displacement u and
the spring's deflection, x - u = series_compliance * F, and the force F is the device's at u.
The rig's offsets (after it) stay outside: its displacement zero comes off x first, its load-cell
zero is added to F. A compliance of 0 is the device alone, bit for bit.

Its one state is ``series_u`` [mm], the device's displacement (x where the spring is relaxed; the
record's first x at the start: the device starts virgin there and the first step settles the
spring, exact where the device's force at the start is 0, as at x = 0).

How it is stepped (``derived_source.series_wrapper_source`` writes the kernels): over a step of
constant velocity v the device moves at the constant velocity w for which the spring's force at
the step's end is the device's, (x1 - u0 - w h) / compliance = F_device(w) (x1 the step's end),
found by a secant and regula-falsi iteration over w on the device's own step (its error bounded
to 1e-12 of the step's travel; a step whose iteration does not close in 60 device steps fails).
A displacement jump is the spring's alone (a device with a dashpot does not move in no time; one
without, the next step settles). In model exchange u is a state with du/dt = w, w the velocity at
which the device's force is the spring's: the device's force is affine in its velocity, F0 + C w
(a dashpot in parallel: C > 0), so w = ((x - u)/compliance - F0)/C; a device whose force does not
grow with its velocity (C = 0: no dashpot across it) has no such rate and is refused there.
"""
from __future__ import annotations

from ..definition import SearchCoordinate
from ..parameter_specs import ParameterSpec
from ..search_coordinates import KIND
from .element import ElementState, OptionElement

SERIES = "series"


def series_specs(count: int = 0) -> tuple[ParameterSpec, ...]:
    return (ParameterSpec("series_compliance", "mm/N", "the compliance in series with the device (1/its "
                          "stiffness; 0: the device alone)", minimum=0.0, why="a negative compliance is unstable"),)


def series_coordinates(count: int) -> tuple[SearchCoordinate, ...]:
    return (SearchCoordinate("series_compliance", KIND.compliance, -3.0, 1.0),)


ELEMENT = OptionElement(
    token=SERIES, word="a compliance in series", order=85, usage=SERIES, specs=series_specs,
    coordinates=series_coordinates, series=True,
    states=lambda count: (ElementState("series_u", "mm", "the device's displacement: x less the series "
                                                         "compliance's deflection"),),
    neutral=(("series_compliance", 0.0),))
