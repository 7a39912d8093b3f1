"""``series``: a compliance in series with the device (what Altair calls a mount's stiffness): the
base and the options before it (the device) sit on a linear spring of compliance
``series_compliance`` [mm/N], so the displacement x splits into the device's displacement u and
the spring's deflection, x - u = series_compliance * F, and the force F is the device's at u.
The rig's offsets (after it) stay outside: its displacement zero comes off x first, its load-cell
zero is added to F. A compliance of 0 is the device alone, bit for bit.

Its one state is ``series_u`` [mm], the device's displacement. A run starts with the device
virgin where the spring holds its force at rest, u + series_compliance * F_device(u) = x (less
the rig's zero; secants over u); a run started holding a force F deflects the spring by
series_compliance * F.

How it is stepped (``derived_source.series_wrapper_source`` writes the kernels): over a step of
constant velocity v the device moves at the constant velocity w for which the spring's force at
the step's end is the device's, (x1 - u0 - w h) / compliance = F_device(w) (x1 the step's end):
a Newton step from w = v on the residual's slope estimated from the device's force (its dashpot
and stiffness), then secants and regula falsi over w on the device's own step, until the residual
is within 1e-12 of the step's travel (a floor of rounding) or stands still, then one secant more
through the two latest points, kept where it is no worse (its tangents are the converged step's).
Each of the device's steps gets the substeps a step may take; a step whose iteration does not
close in 63 device steps fails (said as too many substeps). This is backward Euler in the
device's travel: first order in the step where the device's relaxation time on the spring is
near the step. A displacement jump is the spring's alone (a device with a dashpot does not move
in no time; one without, the next step settles). In model exchange u is a state with du/dt = w,
w the velocity at which the device's force is the spring's: every device's force is affine in
its velocity, F0 + C w (a dashpot in parallel: C > 0), so w = ((x - u)/compliance - F0)/C; a
device whose force does not grow with its velocity (C = 0: Berg's model, or a dashpot set to 0)
has no such rate, and the FMU's model exchange says its derivative is not finite.
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
