"""A hydraulic bushing or mount: a rubber path in parallel with a fluid path through an inertia
track, amplitude-selective through a decoupler (the lumped-parameter model of Flower 1985; Singh,
Kim and Ravindra 1992; Geisberger, Khajepour and Golnaraghi 2002).

    F   = k0*x + c0*dx/dt + f1 + kb*(x - y - u)                       the force [N]
    df1/dt = k1*dx/dt - (k1/c1)*f1                                     the rubber's Maxwell element
    P   = kb*(x - y) - kc*y                                            the chambers' pressure difference,
                                                                       decoupler closed [N]
    u   = gap*tanh(P/((kb + kc + kd)*gap))   (u = 0 where gap = 0)    the decoupler's travel [mm]
    dp  = P - (kb + kc)*u                                              what drives the track [N]
    dy/dt = w,   mf*dw/dt = dp - cf*w - ct*|w|*w                       the fluid in the inertia track

Every fluid quantity is in the mount's own coordinates (the track's fluid displacement times its
area over the piston area: what the mount's top would travel to pump that volume): y [mm] and
w [mm/s] the fluid column's displacement and velocity, u [mm] the decoupler's. The upper
chamber's walls bulge with stiffness kb [N/mm]; the lower chamber (the bellows) takes the volume
that passes with stiffness kc [N/mm]; mf [N.s^2/mm] is the fluid column's effective mass, cf
[N.s/mm] and ct [N.s^2/mm^2] its linear and turbulent damping. The decoupler is a soft membrane
(stiffness kd [N/mm]) that takes small volume changes without pumping much fluid through the
track: while |P| is small against (kb + kc + kd)*gap, u follows P/(kb + kc + kd) and the track
sees dp = P*kd/(kb + kc + kd), a fraction of the pressure; beyond, the membrane rests on its cage
(|u| -> gap) and the fluid column moves with the whole pressure, which gives the loss-angle peak
near the track's resonance sqrt((kb + kc)/mf)/(2*pi) and the stiffness notch below it. The
membrane's stiffness is what brings the column back to rest: a membrane with none would leave
the column a line of equilibria (any y with u = -y). The tanh engages the cage smoothly,
so the kernels are differentiable everywhere (|w|*w has the continuous derivative 2*|w|): the
model has no switches.

Without the decoupler (gap = 0) and the turbulent term (ct = 0) the model is linear, with the
complex stiffness

    K*(omega) = k0 + i*omega*c0 + k1*i*omega*c1/(k1 + i*omega*c1)
                + kb*(kc - mf*omega^2 + i*omega*cf)/(kb + kc - mf*omega^2 + i*omega*cf).

Units N-mm-s; the state is ``(y, w, f1)``: the fluid column's displacement [mm] and velocity
[mm/s] and the Maxwell force [N]. How it is stepped: the Maxwell element exactly
(``elements.maxwell_step``); the fluid column by the classical Runge-Kutta method
(``elements.track_step``, which the free decoupler's model shares) on
substeps of at most ``elements.THETA_TRACK`` over its fastest rate (its natural frequency plus its damping
rate), with x + v*t exact within each: the column's equations are not stiff (the decoupler is
algebraic), so a 1 ms step at a 10 Hz track takes one substep.

A sine from rest settles slowly where the decoupler engages partly (with the default set at
0.1 mm and 8 Hz the first harmonic is 2.8 % off after 6 cycles, 0.6 % after 10, 0.01 % after 20),
so the model declares ``settling_s`` = 2 s: a fit's loop on a data sheet runs each row that long.
"""
from __future__ import annotations

import math

from ..model.parameter_specs import DAMPING, SPRING, ParameterSpec
from ..model.elements import (MEMBRANE, maxwell_decay, maxwell_step, track_acceleration, track_force, track_step,
                               track_substeps)
from ..model.integration import NOT_FINITE, OK, TOO_MANY_SUBSTEPS
from ..model.definition import BushingModel, SearchBox, SearchCoordinate, StateSpec, TrackStart
from ..model.search_coordinates import KIND

POSITIVE = dict(minimum=0.0, exclusive=True)

PARAMETER_SPECS = (
    ParameterSpec("k0", "N/mm", "the rubber's static stiffness", **SPRING),
    ParameterSpec("c0", "N.s/mm", "the rubber's viscous damping", **DAMPING),
    ParameterSpec("k1", "N/mm", "spring of the rubber's Maxwell element", **SPRING),
    ParameterSpec("c1", "N.s/mm", "dashpot of the rubber's Maxwell element (relaxation time c1/k1)",
                  **POSITIVE, why="it sets the Maxwell element's rate k1/c1"),
    ParameterSpec("kb", "N/mm", "the upper chamber's bulge stiffness: the fluid path's stiffness when the "
                  "fluid cannot move", **POSITIVE, why="the fluid path acts through it (a mount without "
                  "one is the rubber path alone: another model)"),
    ParameterSpec("kc", "N/mm", "the lower chamber's (bellows') stiffness against the volume pumped", **SPRING),
    ParameterSpec("mf", "N.s^2/mm", "the inertia track's fluid as an effective mass at the mount",
                  **POSITIVE, why="the fluid column's equation divides by it"),
    ParameterSpec("cf", "N.s/mm", "the inertia track's linear (laminar) damping", **DAMPING),
    ParameterSpec("ct", "N.s^2/mm^2", "the inertia track's turbulent damping, force ct*|w|*w",
                  minimum=0.0, why="a negative turbulent damping adds energy", bound_powers=(0, 2)),
    ParameterSpec("gap", "mm", "the decoupler's free travel (0: no decoupler, the fluid always pumps)",
                  minimum=0.0, why="a travel is a magnitude"),
    ParameterSpec("kd", "N/mm", "the decoupler membrane's stiffness within its travel", **POSITIVE,
                  why="a membrane without stiffness leaves the fluid column no rest position"),
)


# ---------------------------------------------------------------------------- kernels
def prepare(p):
    """(k0, c0, k1, rate1 = k1/c1, kb, kc, mf, cf, ct, decoupler) from the 11 values in
    ``PARAMETER_SPECS`` order; the decoupler a membrane (``elements.decoupler_travel``):
    (MEMBRANE, gap, kb + kc + kd, 0, 0)."""
    k0, c0, k1, c1, kb, kc, mf, cf, ct, gap, kd = p
    return (k0, c0, k1, k1 / c1, kb, kc, mf, cf, ct, (MEMBRANE, gap, kb + kc + kd, 0.0, 0.0))


def initial_state(m, x0):
    """At rest at x0 [mm]: the chambers' pressures equal (P = 0: y = kb*x0/(kb + kc), the
    decoupler centred), the fluid still, the Maxwell element relaxed."""
    k0, c0, k1, rate1, kb, kc, mf, cf, ct, decoupler = m
    return (kb * x0 / (kb + kc), 0.0, 0.0)


def force(m, state, x, v):
    """F = k0*x + c0*v + f1 + kb*(x - y - u) [N], positive for positive x."""
    k0, c0, k1, rate1, kb, kc, mf, cf, ct, decoupler = m
    y, w, f1 = state
    bulge, drive = track_force(kb, kc, decoupler, y, x)
    return k0 * x + c0 * v + f1 + bulge


def jump(m, state, jump_mm):
    """An instantaneous displacement jump: the fluid cannot move in no time (its mass) and the
    decoupler follows the pressure (it is algebraic); the Maxwell spring takes the jump."""
    k0, c0, k1, rate1, kb, kc, mf, cf, ct, decoupler = m
    y, w, f1 = state
    return (y, w, f1 + k1 * jump_mm), OK


def integrate(m, state, x, v, h, max_substeps):
    """Over the step x + v*t: the Maxwell force exactly, the fluid column by the classical
    Runge-Kutta method on equal substeps (module docstring); returns (state, substeps, status)."""
    k0, c0, k1, rate1, kb, kc, mf, cf, ct, decoupler = m
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
    k0, c0, k1, rate1, kb, kc, mf, cf, ct, decoupler = m
    y, w, f1 = state
    return (w, track_acceleration(kb, kc, mf, cf, ct, decoupler, y, w, x), k1 * v - rate1 * f1)


def switches(m, state, x, v):
    """No switches, (): the equations have no branch (module docstring)."""
    return ()


SEARCH = SearchBox(
    (SearchCoordinate("k0", KIND.stiffness, -3.0, 1.0), SearchCoordinate("c0", KIND.damping, -5.0, 1.0),
     SearchCoordinate("k1", KIND.stiffness, -4.0, 1.0),
     SearchCoordinate("c1", KIND.time_constant, -math.inf, 4.0, over=("k1",)),
     SearchCoordinate("kb", KIND.stiffness, -3.0, 1.0), SearchCoordinate("kc", KIND.stiffness, -4.0, 0.5),
     SearchCoordinate("mf", KIND.resonance, math.log10(0.3), math.log10(300.0), over=("kb", "kc")),
     SearchCoordinate("cf", KIND.damping_ratio, -3.0, 0.5, over=("kb", "kc"), partner="mf"),
     SearchCoordinate("ct", KIND.quadratic_damping, -6.0, 1.0),
     SearchCoordinate("gap", KIND.travel, -4.0, 0.5), SearchCoordinate("kd", KIND.stiffness, -4.0, 1.0)),
    table_start=TrackStart(static="k0", stiffness="kb", compliance="kc", mass="mf", damping="cf", travel="gap"))
"""The fit's box: the track's mass as its resonance frequency sqrt((kb + kc)/mf)/(2*pi) [Hz]
(0.3-300 Hz, log10), its linear damping as the resonance's damping ratio
cf/(2*sqrt((kb + kc)*mf)) (1e-3 to 3, log10), the turbulent damping against the data's
c_ref^2/(k_ref*x_ref) and the decoupler's gap against the largest amplitude, log10 both. A data
sheet gives starts for the track, the bulge, the bellows, the static spring and the gap
(identification/fitting/table_start.py)."""


MODEL = BushingModel(
    "hydraulic", "HydraulicBushing", "Hydraulic bushing or mount: rubber, inertia track, decoupler",
    PARAMETER_SPECS,
    (StateSpec("y", 0, "m", "the fluid column's displacement, in the mount's coordinates"),
     StateSpec("w", 1, "m/s", "the fluid column's velocity, in the mount's coordinates"),
     StateSpec("f1", 2, "N", "force of the rubber's Maxwell element")),
    "params_hydraulic_mount.json", prepare, initial_state, jump, integrate, force, derivatives, switches,
    search=SEARCH, plot_style=("C6", "-"), rank=50, settling_s=2.0,
    description="Hydraulic bushing or engine mount (one axis): a rubber path (spring, dashpot, Maxwell element) "
                "in parallel with a fluid path (bulge stiffness, inertia track with linear and turbulent damping, "
                "lower chamber, decoupler); FMI ports in SI units, parameters in N-mm-s.",
    static_spring=("k0",))
