"""A hydraulic mount whose decoupler is a free plate in a cage: inside its free travel the plate
lets the fluid pass without pumping it through the inertia track, at the cage it engages
(Flower 1985; Singh, Kim and Ravindra 1992; Geisberger, Khajepour and Golnaraghi 2002), with the
rubber's progressive spring.

    F   = k0*x + k3*x^3 + c0*dx/dt + f1 + kb*(x - y - u)                 the force [N]
    df1/dt = k1*dx/dt - (k1/c1)*f1                                       the rubber's Maxwell element
    P   = kb*(x - y) - kc*y                                              the chambers' pressure difference,
                                                                         plate held at its centre [N]
    u   = P/K - kcage/(K*(K + kcage)) * D(P),   K = kb + kc + kd         the plate's travel [mm]
    D(P) = W*(softplus((P - K*gap)/W) - softplus((-P - K*gap)/W)),   W = K*width
    dp  = P - (kb + kc)*u                                                what drives the track [N]
    dy/dt = w,   mf*dw/dt = dp - cf*w - ct*|w|*w                         the fluid in the inertia track

The plate is massless: it sits where the pressure across it, P - (kb + kc)*u, balances its weak
centring spring kd*u and, beyond its free travel gap, the cage kcage*(|u| - gap). That balance
is piecewise linear in P, and u above is its solution with the cage's corner rounded by a
softplus over a width of about ``width`` [mm] of plate travel (D is the dead zone of the
pressure: 0 inside +-K*gap, P -+ K*gap beyond: ``elements.dead_zone``). So, while |P| < K*gap, the plate follows the
pressure (u = P/K), the track sees only dp = P*kd/K, a few percent of it, and the fluid path is
the bulge in series with the bellows, almost without damping; beyond, the plate rests on its cage
and the column is driven by nearly the whole pressure: the loss-angle peak near the track's
resonance sqrt((kb + kc)/mf)/(2*pi) and the stiffness notch below it. The centring spring kd is
what brings the column back to rest (without it, the column would have a line of equilibria
inside the gap).

With width > 0 every kernel is smooth (the softplus is analytic; |w|*w has the continuous
derivative 2*|w|); width = 0 is the hard cage, whose corner at |P| = K*gap the model states as its
two switches, P - K*gap and P + K*gap [N] (the event indicators of model exchange; with width > 0
they mark where the cage engages). The saturating membrane of ``hydraulic_model`` is the other
decoupler kind; with gap = 0 this one is a linear membrane of stiffness kd + kcage.

Units N-mm-s; the state is ``(y, w, f1)`` as in ``hydraulic_model`` (fluid displacement [mm] and
velocity [mm/s] in the mount's coordinates, the Maxwell force [N]), stepped by the same kernels
(``elements.track_step`` with the plate as its decoupler law, ``elements.FREE_PLATE``): the
Maxwell element exactly, the fluid column by the classical Runge-Kutta method on substeps of at
most ``elements.THETA_TRACK`` over its fastest rate, which bounds the engaged column's too
(the plate only softens what the column feels).

With the default set a sine from rest settles within ``settling_s`` = 2 s: inside the gap the
column returns to centre with the time constant cf*K/((kb + kc)*kd), 0.27 s.
"""
from __future__ import annotations

import math

from ..model.parameter_specs import SPRING, ParameterSpec
from ..model.elements import (FREE_PLATE, maxwell_decay, maxwell_step, track_acceleration, track_force,
                               track_step, track_substeps)
from ..model.integration import NOT_FINITE, OK, TOO_MANY_SUBSTEPS
from ..model.definition import BushingModel, SearchBox, SearchCoordinate, StateSpec, TrackStart
from ..model.search_coordinates import KIND
from .berg_model import CUBIC
from .hydraulic_model import PARAMETER_SPECS as MEMBRANE_SPECS, POSITIVE

SHARED = {spec.name: spec for spec in MEMBRANE_SPECS}
"""The rubber's and the fluid column's specs, as the membrane mount declares them."""

PARAMETER_SPECS = (
    SHARED["k0"],
    ParameterSpec("k3", "N/mm^3", "the rubber's cubic stiffness: the progressive spring k0*x + k3*x^3", **CUBIC),
    *(SHARED[name] for name in ("c0", "k1", "c1", "kb", "kc", "mf", "cf", "ct")),
    ParameterSpec("gap", "mm", "the decoupler plate's free travel each way before it meets its cage "
                  "(0: a membrane of stiffness kd + kcage)", minimum=0.0, why="a travel is a magnitude"),
    ParameterSpec("width", "mm", "the width of plate travel over which the cage engages (0: a hard cage, "
                  "a corner at |u| = gap)", minimum=0.0, why="a width is a magnitude"),
    ParameterSpec("kcage", "N/mm", "the cage's stiffness against the plate beyond its free travel", **SPRING),
    ParameterSpec("kd", "N/mm", "the plate's weak centring stiffness within its travel", **POSITIVE,
                  why="a plate without one leaves the fluid column no rest position"),
)


# ---------------------------------------------------------------------------- kernels
def prepare(p):
    """(k0, k3, c0, k1, rate1 = k1/c1, kb, kc, mf, cf, ct, decoupler) from the 14 values in
    ``PARAMETER_SPECS`` order; the decoupler a free plate (``elements.decoupler_travel``):
    (FREE_PLATE, K*gap, K*width, kcage/(K*(K + kcage)), 1/K) with K = kb + kc + kd."""
    k0, k3, c0, k1, c1, kb, kc, mf, cf, ct, gap, width, kcage, kd = p
    stiffness = kb + kc + kd
    return (k0, k3, c0, k1, k1 / c1, kb, kc, mf, cf, ct,
            (FREE_PLATE, stiffness * gap, stiffness * width, kcage / (stiffness * (stiffness + kcage)), 1.0 / stiffness))


def initial_state(m, x0):
    """At rest at x0 [mm]: the chambers' pressures equal (P = 0: y = kb*x0/(kb + kc), the plate
    centred), the fluid still, the Maxwell element relaxed."""
    k0, k3, c0, k1, rate1, kb, kc, mf, cf, ct, decoupler = m
    return (kb * x0 / (kb + kc), 0.0, 0.0)


def force(m, state, x, v):
    """F = k0*x + k3*x^3 + c0*v + f1 + kb*(x - y - u) [N], positive for positive x."""
    k0, k3, c0, k1, rate1, kb, kc, mf, cf, ct, decoupler = m
    y, w, f1 = state
    bulge, drive = track_force(kb, kc, decoupler, y, x)
    return k0 * x + k3 * x * x * x + c0 * v + f1 + bulge


def jump(m, state, jump_mm):
    """An instantaneous displacement jump: the fluid cannot move in no time (its mass) and the
    plate follows the pressure (it is massless); the Maxwell spring takes the jump."""
    k0, k3, c0, k1, rate1, kb, kc, mf, cf, ct, decoupler = m
    y, w, f1 = state
    return (y, w, f1 + k1 * jump_mm), OK


def integrate(m, state, x, v, h, max_substeps):
    """Over the step x + v*t: the Maxwell force exactly, the fluid column by the classical
    Runge-Kutta method on equal substeps (module docstring); returns (state, substeps, status)."""
    k0, k3, c0, k1, rate1, kb, kc, mf, cf, ct, decoupler = m
    y, w, f1 = state
    n = track_substeps(kb, kc, mf, cf, ct, w, h)
    if n > max_substeps:
        return state, n, TOO_MANY_SUBSTEPS
    y, w = track_step(kb, kc, mf, cf, ct, decoupler, y, w, x, v, h, n)
    new = (y, w, maxwell_step(f1, k1, maxwell_decay(rate1, h), v, h))
    if not (math.isfinite(new[0]) and math.isfinite(new[1]) and math.isfinite(new[2])):
        return new, n, NOT_FINITE
    return new, n, OK


def derivatives(m, state, x, v):
    """(dy/dt, dw/dt, df1/dt) [mm/s, mm/s^2, N/s] (model exchange)."""
    k0, k3, c0, k1, rate1, kb, kc, mf, cf, ct, decoupler = m
    y, w, f1 = state
    return (w, track_acceleration(kb, kc, mf, cf, ct, decoupler, y, w, x), k1 * v - rate1 * f1)


def switches(m, state, x, v):
    """(P - K*gap, P + K*gap) [N]: where either changes sign the plate meets or leaves its cage."""
    k0, k3, c0, k1, rate1, kb, kc, mf, cf, ct, decoupler = m
    law, free, width, cage, compliance = decoupler
    y, w, f1 = state
    pressure = kb * (x - y) - kc * y
    return (pressure - free, pressure + free)


SEARCH = SearchBox(
    (SearchCoordinate("k0", KIND.stiffness, -3.0, 1.0), SearchCoordinate("k3", KIND.cubic, 0.0, 2.0),
     SearchCoordinate("c0", KIND.damping, -5.0, 1.0),
     SearchCoordinate("k1", KIND.stiffness, -4.0, 1.0),
     SearchCoordinate("c1", KIND.time_constant, -math.inf, 4.0, over=("k1",)),
     SearchCoordinate("kb", KIND.stiffness, -3.0, 1.0), SearchCoordinate("kc", KIND.stiffness, -4.0, 0.5),
     SearchCoordinate("mf", KIND.resonance, math.log10(0.3), math.log10(300.0), over=("kb", "kc")),
     SearchCoordinate("cf", KIND.damping_ratio, -3.0, 0.5, over=("kb", "kc"), partner="mf"),
     SearchCoordinate("ct", KIND.quadratic_damping, -6.0, 1.0),
     SearchCoordinate("gap", KIND.travel, -4.0, 0.5), SearchCoordinate("width", KIND.travel, -5.0, -1.0),
     SearchCoordinate("kcage", KIND.stiffness, -2.0, 2.0), SearchCoordinate("kd", KIND.stiffness, -2.5, 0.0)),
    table_start=TrackStart(static="k0", stiffness="kb", compliance="kc", mass="mf", damping="cf", travel="gap",
                           engagement="width", cage="kcage", centring="kd"))
"""The fit's box, as ``hydraulic_model``'s for the rubber and the track; the cubic term as
k3*X^2/k_ref (0 to 2), the plate's free travel and its engagement width against the largest
amplitude X (1e-4 to 3 X and 1e-5 to 0.1 X), the cage and the centring spring against k_ref,
log10 all. The centring spring stays above 10^-2.5 k_ref: a weaker one would leave the
column unsettled after the fit loop's settling time, a steady state the fit must not be able to
trade for a transient. A data sheet gives starts for the track, the gap, the width and the cage
(identification/fitting/table_start.py)."""


MODEL = BushingModel(
    "hydraulic_free_decoupler", "HydraulicFreeDecoupler",
    "Hydraulic mount with a free decoupler plate: rubber, inertia track, plate in a cage",
    PARAMETER_SPECS,
    (StateSpec("y", 0, "m", "the fluid column's displacement, in the mount's coordinates"),
     StateSpec("w", 1, "m/s", "the fluid column's velocity, in the mount's coordinates"),
     StateSpec("f1", 2, "N", "force of the rubber's Maxwell element")),
    "params_hydraulic_free_decoupler.json", prepare, initial_state, jump, integrate, force, derivatives, switches,
    switch_specs=(StateSpec("P_minus_free", 0, "N", "pressure difference less the plate's free travel times K: "
                            "where it changes sign the plate meets or leaves the cage (positive side)"),
                  StateSpec("P_plus_free", 1, "N", "pressure difference plus the plate's free travel times K: "
                            "where it changes sign the plate meets or leaves the cage (negative side)")),
    search=SEARCH, plot_style=("C9", "-"), rank=55, settling_s=2.0,
    description="Hydraulic engine mount with a free decoupler plate (one axis): a rubber path (progressive spring, "
                "dashpot, Maxwell element) in parallel with a fluid path (bulge stiffness, inertia track with linear "
                "and turbulent damping, lower chamber, a plate free within +-gap, then caged); FMI ports in SI units, "
                "parameters in N-mm-s.",
    static_spring=("k0", "k3"))
