"""Berg's rubber-bushing model (Berg, Vehicle System Dynamics 30, 1998): a progressive elastic
spring, a smooth rate-independent friction and two Maxwell elements in parallel.

    F = k0*x + k3*x^3 + F_f + f1 + f2
    F_f: Berg's friction (elements.friction_force), from the last reversal (x_s, F_s):
         moving up   F_f = F_s + (x - x_s)*(Ff_max - F_s)/(x2*(1 - beta) + (x - x_s)),
         moving down F_f = F_s + (x - x_s)*(Ff_max + F_s)/(x2*(1 + beta) - (x - x_s)),
         beta = F_s/Ff_max; from rest F_f = Ff_max*x/(x2 + |x|)
    df_i/dt = k_i*dx/dt - (k_i/c_i)*f_i       (spring k_i in series with dashpot c_i)

The friction is what filled rubber shows as the Fletcher-Gent (Payne) effect: its stiffness
Ff_max/x2 at a reversal counts fully in small loops and less in large ones, so the dynamic
stiffness falls with amplitude, and its loop area does not depend on frequency. The Maxwell
elements carry the rate dependence and the relaxation after a step; k3 the progressive
stiffening at large deflection.

Units N-mm-s: x in mm, forces in N, k0, k1, k2 in N/mm, k3 in N/mm^3, c1, c2 in N.s/mm, x2 in mm.
The state is ``(travel, F_s, direction, f1, f2)``: the travel x - x_s [mm] since the last
reversal, the friction force there [N], the direction of the motion since (+1, -1, 0 at rest)
and the Maxwell forces [N]. A reversal is where the displacement's direction changes: at the
start of a step whose velocity is against the direction, or at a jump against it; in model
exchange the velocity's sign change is an event (``switches``) and ``update`` makes the reversal.
Everything is exact over a step with constant velocity: the friction is algebraic in the travel
and the Maxwell elements are linear.
"""
from __future__ import annotations

import math

from ..model.parameter_specs import SPRING, ParameterSpec
from ..model.elements import (friction_force, friction_jump_turn, friction_turn, maxwell_decay, maxwell_step,
                              vector_friction_force, vector_friction_jump_turn, vector_friction_turn)
from ..model.integration import NOT_FINITE, OK, vector_dot
from ..model.definition import BushingModel, CoupledKernels, SearchBox, SearchCoordinate, SlowLoop, StateSpec
from ..model.search_coordinates import KIND

FRICTION_LIMIT = dict(minimum=0.0, why="a friction force limit is a magnitude", bound_powers=(0, 0))
HALF_TRAVEL = dict(minimum=0.0, exclusive=True, why="it divides the friction law: the travel to half the limit")
CUBIC = dict(minimum=0.0, why="a negative cubic term softens without bound", bound_powers=(3, 0))
MAXWELL_DASHPOT = dict(minimum=0.0, exclusive=True, why="it sets the Maxwell element's rate k/c")

PARAMETER_SPECS = (
    ParameterSpec("k0", "N/mm", "linear elastic stiffness", **SPRING),
    ParameterSpec("k3", "N/mm^3", "cubic elastic stiffness: the progressive spring k0*x + k3*x^3", **CUBIC),
    ParameterSpec("Ff_max", "N", "friction force limit: Berg's friction tends to +-Ff_max far from a reversal",
                  **FRICTION_LIMIT),
    ParameterSpec("x2", "mm", "friction travel from rest to half the limit (stiffness Ff_max/x2 at a reversal)",
                  **HALF_TRAVEL),
    ParameterSpec("k1", "N/mm", "spring of the first Maxwell element", **SPRING),
    ParameterSpec("c1", "N.s/mm", "dashpot of the first Maxwell element (relaxation time c1/k1)", **MAXWELL_DASHPOT),
    ParameterSpec("k2", "N/mm", "spring of the second Maxwell element", **SPRING),
    ParameterSpec("c2", "N.s/mm", "dashpot of the second Maxwell element (relaxation time c2/k2)", **MAXWELL_DASHPOT),
)


# ---------------------------------------------------------------------------- kernels
def prepare(p):
    """(k0, k3, Ff_max, x2, k1, rate1 = k1/c1, k2, rate2 = k2/c2) from the 8 values in
    ``PARAMETER_SPECS`` order."""
    k0, k3, limit, half_travel, k1, c1, k2, c2 = p
    return (k0, k3, limit, half_travel, k1, k1 / c1, k2, k2 / c2)


def initial_state(m, x0):
    """At rest at x0 [mm]: no travel since a reversal, no friction or Maxwell force
    (F = k0*x0 + k3*x0^3, the elastic force, held while x0 is)."""
    return (0.0, 0.0, 0.0, 0.0, 0.0)


def force(m, state, x, v):
    """F = k0*x + k3*x^3 + F_f + f1 + f2 [N], positive for positive x."""
    k0, k3, limit, half_travel, k1, rate1, k2, rate2 = m
    travel, reversal, direction, f1, f2 = state
    return k0 * x + k3 * x * x * x + friction_force(limit, half_travel, travel, reversal, direction) + f1 + f2


def update(m, state, x, v):
    """At an event (v changed sign): the friction reverses if v runs against its direction."""
    k0, k3, limit, half_travel, k1, rate1, k2, rate2 = m
    travel, reversal, direction, f1, f2 = state
    travel, reversal, direction = friction_turn(limit, half_travel, travel, reversal, direction, v)
    return (travel, reversal, direction, f1, f2)


def jump(m, state, jump_mm):
    """An instantaneous displacement jump: a reversal first if it runs against the motion (and is
    more than rounding, ``elements.ROUNDING_JUMP_MM``), then
    the friction travels it and the Maxwell springs take it (their dashpots cannot move in no time)."""
    k0, k3, limit, half_travel, k1, rate1, k2, rate2 = m
    travel, reversal, direction, f1, f2 = state
    travel, reversal, direction = friction_jump_turn(limit, half_travel, travel, reversal, direction, jump_mm)
    return (travel + jump_mm, reversal, direction, f1 + k1 * jump_mm, f2 + k2 * jump_mm), OK


def integrate(m, state, x, v, h, max_substeps):
    """Over the step x + v*t: a reversal at its start if v runs against the motion, then the
    travel grows by v*h and the Maxwell forces follow exactly; returns (state, 1, status)."""
    k0, k3, limit, half_travel, k1, rate1, k2, rate2 = m
    travel, reversal, direction, f1, f2 = update(m, state, x, v)
    new = (travel + v * h, reversal, direction, maxwell_step(f1, k1, maxwell_decay(rate1, h), v, h),
           maxwell_step(f2, k2, maxwell_decay(rate2, h), v, h))
    if not (math.isfinite(new[0]) and math.isfinite(new[3]) and math.isfinite(new[4])):
        return new, 1, NOT_FINITE
    return new, 1, OK


def derivatives(m, state, x, v):
    """(d travel/dt, 0, 0, df1/dt, df2/dt) [mm/s, N/s, 1/s, N/s, N/s] (model exchange): the
    reversal force and direction change only at events (``update``)."""
    k0, k3, limit, half_travel, k1, rate1, k2, rate2 = m
    travel, reversal, direction, f1, f2 = state
    return (v, 0.0, 0.0, k1 * v - rate1 * f1, k2 * v - rate2 * f2)


def switches(m, state, x, v):
    """v [mm/s]: where it changes sign the friction reverses."""
    return (v,)


# ---------------------------------------------------------------------------- coupled kernels
# On a displacement vector (3-vectors): the progressive spring is radial, (k0 + k3*|x|^2)*x; the
# friction is elements.vector_friction_force, Berg's law along a line; the Maxwell elements act
# on each component. The state is (travel d, F_s, f1, f2), 3-vectors: a reversal needs no direction
# of its own (where d = 0 the force is F_s whichever way the motion goes).
def initial_state_coupled(m, x0):
    """At rest at x0: no travel since a reversal, no friction or Maxwell force."""
    return tuple(0.0 for i in range(12))


def elastic_force_coupled(k0, k3, x):
    """The radial progressive spring (k0 + k3*|x|^2)*x [N], a 3-vector."""
    r2 = vector_dot(x, x)
    return tuple(k0 * x[i] + k3 * r2 * x[i] for i in range(3))


def force_coupled(m, state, x, v):
    """F = (k0 + k3*|x|^2)*x + F_f + f1 + f2 [N], a 3-vector."""
    k0, k3, limit, half_travel, k1, rate1, k2, rate2 = m
    elastic = elastic_force_coupled(k0, k3, x)
    friction = vector_friction_force(limit, half_travel, (state[0], state[1], state[2]), (state[3], state[4], state[5]))
    return tuple(elastic[i] + friction[i] + state[6 + i] + state[9 + i] for i in range(3))


def update_coupled(m, state, x, v):
    """At an event (d.v changed sign): the friction reverses where v shortens the travel."""
    k0, k3, limit, half_travel, k1, rate1, k2, rate2 = m
    travel, reversal = vector_friction_turn(limit, half_travel, (state[0], state[1], state[2]),
                                            (state[3], state[4], state[5]), v)
    return (travel[0], travel[1], travel[2], reversal[0], reversal[1], reversal[2],
            *tuple(state[6 + i] for i in range(6)))


def jump_coupled(m, state, jump):
    """A displacement jump (a 3-vector): a reversal first where it shortens the travel (and is more
    than rounding), then the friction travels it and the Maxwell springs take it."""
    k0, k3, limit, half_travel, k1, rate1, k2, rate2 = m
    travel, reversal = vector_friction_jump_turn(limit, half_travel, (state[0], state[1], state[2]),
                                                 (state[3], state[4], state[5]), jump)
    return (*tuple(travel[i] + jump[i] for i in range(3)), reversal[0], reversal[1], reversal[2],
            *tuple(state[6 + i] + k1 * jump[i] for i in range(3)),
            *tuple(state[9 + i] + k2 * jump[i] for i in range(3))), OK


def integrate_coupled(m, state, x, v, h, max_substeps):
    """Over the step x + v*t: a reversal at its start where v shortens the travel, then the travel
    grows by v*h and the Maxwell forces follow exactly; returns (state, 1, status)."""
    k0, k3, limit, half_travel, k1, rate1, k2, rate2 = m
    travel, reversal = vector_friction_turn(limit, half_travel, (state[0], state[1], state[2]),
                                            (state[3], state[4], state[5]), v)
    decay1, decay2 = maxwell_decay(rate1, h), maxwell_decay(rate2, h)
    new = (*tuple(travel[i] + v[i] * h for i in range(3)), reversal[0], reversal[1], reversal[2],
           *tuple(maxwell_step(state[6 + i], k1, decay1, v[i], h) for i in range(3)),
           *tuple(maxwell_step(state[9 + i], k2, decay2, v[i], h) for i in range(3)))
    if not math.isfinite(sum(new[i] for i in range(12))):
        return new, 1, NOT_FINITE
    return new, 1, OK


def derivatives_coupled(m, state, x, v):
    """(dd/dt, 0, df1/dt, df2/dt), 3-vectors each (model exchange): the reversal force changes only
    at events (``update_coupled``)."""
    k0, k3, limit, half_travel, k1, rate1, k2, rate2 = m
    return (v[0], v[1], v[2], 0.0, 0.0, 0.0, *tuple(k1 * v[i] - rate1 * state[6 + i] for i in range(3)),
            *tuple(k2 * v[i] - rate2 * state[9 + i] for i in range(3)))


def switches_coupled(m, state, x, v):
    """d.v [mm^2/s]: where it turns negative the friction reverses."""
    return (vector_dot((state[0], state[1], state[2]), v),)


COUPLED_STATES = (StateSpec("travel", 0, "m", "travel since the friction's last reversal, x - x_s"),
                  StateSpec("F_s", 1, "N", "friction force at the last reversal"))
"""The coupled friction's states (the first two vectors of the coupled state), which the
fractional model shares."""


SEARCH = SearchBox(
    (SearchCoordinate("k0", KIND.stiffness, -3.0, 1.0), SearchCoordinate("k3", KIND.cubic, 0.0, 2.0),
     SearchCoordinate("Ff_max", KIND.force, -3.0, 0.5), SearchCoordinate("x2", KIND.travel, -4.0, 0.5),
     SearchCoordinate("k1", KIND.stiffness, -4.0, 1.0), SearchCoordinate("c1", KIND.time_constant, -math.inf, 4.0,
                                                                       over=("k1",)),
     SearchCoordinate("k2", KIND.stiffness, -4.0, 1.0), SearchCoordinate("c2", KIND.slower, 0.0, 6.0, over=("k2",),
                                                                       partner="c1")),
    loop_start=SlowLoop(("k0", "k3"), "Ff_max", "x2", (("k1", 0.0), ("c1", 1.0), ("k2", 0.0), ("c2", 1.0))))
"""The fit's box: the friction's limit scaled by the peak force and its x2 by the largest
amplitude, the cubic term as k3*X^2/k_ref (0 to 2: up to twice k_ref's force added at the largest
amplitude X); the second Maxwell element is the slower one (its time constant c2/k2 is
10^(0..6) times c1/k1), so the two are never the same optimum twice. The spring and the friction
have starts from the data's slowest loop (identification/fitting/loop_start.py)."""


MODEL = BushingModel(
    "berg", "BergBushing", "Berg (1998): friction, Maxwell elements, progressive spring", PARAMETER_SPECS,
    (StateSpec("travel", 0, "m", "travel since the friction's last reversal, x - x_s"),
     StateSpec("F_s", 1, "N", "friction force at the last reversal"),
     StateSpec("direction", 2, "1", "direction of the motion since the last reversal (+1, -1; 0 at rest)"),
     StateSpec("f1", 3, "N", "force of the first Maxwell element"),
     StateSpec("f2", 4, "N", "force of the second Maxwell element")),
    "params_berg_filled_rubber.json", prepare, initial_state, jump, integrate, force,
    derivatives, switches, update=update,
    switch_specs=(StateSpec("v", 0, "m/s", "the velocity input: where it changes sign the friction reverses"),),
    search=SEARCH, plot_style=("C4", "-"), rank=30,
    coupled=CoupledKernels(
        COUPLED_STATES + (StateSpec("f1", 2, "N", "force of the first Maxwell element"),
                          StateSpec("f2", 3, "N", "force of the second Maxwell element")),
        initial_state_coupled, jump_coupled, integrate_coupled, force_coupled, derivatives_coupled, switches_coupled,
        (StateSpec("dv", 0, "m2/s", "d.v: where it turns negative the friction reverses"),), update=update_coupled),
    static_spring=("k0", "k3"))
