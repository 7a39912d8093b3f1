"""A Bouc-Wen element whose yield differs by direction, with free play and breakaway: a spring with
free play in series with a slider that slides at one force one way and another the other way.

    F   = c0*dx/dt + k0*x + z,            z = A*D(e)                  the force [N]
    de/dt = dx/dt * (1 - H(z*dx/dt) * (|z|/Z)^n)                      the element's deflection [mm]
    Z   = (zp if z > 0 else zn) * (1 + eps*q)                          its yield, per direction [N]
    dq/dt = ((1 - q)*(1 - s) - q*s) * |dx/dt| / delta,  s = H(z*dx/dt)*(|z|/Z)^n     breakaway memory

D is free play of +-``gap`` (``elements.dead_zone``: no force inside it, its corners rounded over
``width``; 0: hard corners). Without play and breakaway (gap = eps = 0) z is the Bouc-Wen
element of eq. 1 with beta = gamma = A/(2*Z^n) (unloading elastic, dz/dx = A) whose ultimate
force is zp one way and zn the other: the per-direction levels of a friction device (the banded
rotary friction damper of ``data/brfd/``, +13 and -10 kN) or a bushing whose hysteresis is not
symmetric (Song and Der Kiureghian 2006 generalise Bouc-Wen the same way, by terms in sgn(z)).
The play is a band's backlash or a bushing's clearance to its sleeve: on reversal the force
falls to 0 and stays there for 2*gap of travel. The breakaway: q tends to 1 while the element
sticks (s = 0: unloading, in the play) and to 0 while it slides (s = 1), each over ``delta`` of
travel, and raises the yield by the factor 1 + eps*q, so that the force overshoots by eps where
sliding starts after a stick and settles to the sliding level over ``delta``.

Rate-independent but for c0: the state (e, q) depends on time only through x, so a step is a walk
along the travel v*h. Where the element sticks (s = 0) e moves with x exactly and q relaxes
exactly (q = 1 - (1 - q0)*exp(-travel/delta)); only where it loads (z*v > 0) does the walk take
classical RK4 substeps, each short enough (``THETA`` of the shortest of Z/(max(n, 1)*A), delta and
the play's width) that s changes little over it: the substeps go where the force turns, none
elsewhere.

Units N-mm-s: z, zp, zn in N, A and k0 in N/mm, c0 in N.s/mm, gap, width and delta in mm, n, eps
and q dimensionless. The state is ``(e, q)``: the element's deflection [mm] and the breakaway
memory [1]; at rest e = 0 (the play's centre) and q = 1, or, holding a force at rest (a friction
force the test before left in the device: ``resting_state``), stuck at the e that gives it.
"""
from __future__ import annotations

import math

from ..model.parameter_specs import DAMPING, SPRING, ParameterSpec
from ..model.elements import dead_zone, inverse_dead_zone
from ..model.integration import DEFAULT_MAX_SUBSTEPS, NOT_FINITE, OK, THETA, TOO_MANY_SUBSTEPS
from ..model.definition import BushingModel, SearchBox, SearchCoordinate, StateSpec
from ..model.search_coordinates import KIND

LEVEL = dict(minimum=0.0, exclusive=True, why="a yield force is a positive magnitude", bound_powers=(0, 0))
PARAMETER_SPECS = (
    ParameterSpec("c0", "N.s/mm", "viscous damping in parallel", **DAMPING),
    ParameterSpec("k0", "N/mm", "static stiffness in parallel", **SPRING),
    ParameterSpec("A", "N/mm", "the element's elastic stiffness (its spring in series with the slider)",
                  minimum=0.0, exclusive=True, why="the element needs a spring"),
    ParameterSpec("zp", "N", "the element's yield (sliding) force in the positive direction", **LEVEL),
    ParameterSpec("zn", "N", "the element's yield (sliding) force in the negative direction, a magnitude", **LEVEL),
    ParameterSpec("n", "1", "sharpness of the yield: where the element loads, the share (|z|/Z)^n of the travel "
                  "slides", minimum=0.0, exclusive=True, why="an exponent of a share is positive"),
    ParameterSpec("gap", "mm", "the element's free play each way from its centre (0: none)", minimum=0.0,
                  why="a travel is a magnitude"),
    ParameterSpec("width", "mm", "the width of travel over which the play's corners engage (0: hard corners)",
                  minimum=0.0, why="a width is a magnitude"),
    ParameterSpec("eps", "1", "breakaway: the yield's overshoot, as a fraction, where sliding starts after a stick "
                  "(0: none)", minimum=0.0, why="a breakaway raises the yield"),
    ParameterSpec("delta", "mm", "breakaway: the travel over which the overshoot decays while sliding and "
                  "recovers while sticking", minimum=0.0, exclusive=True, why="a decay needs a length"),
)


# ---------------------------------------------------------------------------- kernels
def prepare(p):
    """(c0, k0, A, zp, zn, n, gap, width, eps, 1/delta, the walk's longest substep [mm]) from the 10
    values in ``PARAMETER_SPECS`` order."""
    c0, k0, A, zp, zn, n, gap, width, eps, delta = p
    level = zp
    if zn < level:
        level = zn
    longest = level / A
    if n > 1.0:
        longest = longest / n
    if delta < longest:
        longest = delta
    if 0.0 < width < longest:
        longest = width
    return (c0, k0, A, zp, zn, n, gap, width, eps, 1.0 / delta, THETA * longest)


def sliding(m, e, q, direction):
    """(z [N], s): the element's force at deflection e and the share of the travel that slides
    when x moves in ``direction`` (+1 or -1) with breakaway memory q."""
    c0, k0, A, zp, zn, n, gap, width, eps, rate, longest = m
    z = A * dead_zone(e, gap, width)
    if z * direction > 0.0:
        level = zn
        if z > 0.0:
            level = zp
        return z, (abs(z) / (level * (1.0 + eps * q))) ** n
    return z, 0.0


def walk_rates(m, e, q, direction):
    """(de/dx, dq/d|x|) of the walk in ``direction``."""
    z, s = sliding(m, e, q, direction)
    return 1.0 - s, ((1.0 - q) * (1.0 - s) - q * s) * m[9]


def walk(m, state, travel, max_substeps):
    """(state, substeps, status) after x moves by ``travel`` [mm] (module docstring): exact while
    the element sticks, RK4 substeps of at most the longest step while it loads."""
    c0, k0, A, zp, zn, n, gap, width, eps, rate, longest = m
    e, q = state
    if travel == 0.0:
        return state, 0, OK
    direction = 1.0 if travel > 0.0 else -1.0
    # it sticks until e passes the point where z starts to load in this direction
    start = 0.0
    if width <= 0.0:
        start = direction * gap
    stick = (start - e) * direction
    if stick > 0.0:
        free = stick
        if abs(travel) < stick:
            free = abs(travel)
        e = e + direction * free
        q = 1.0 - (1.0 - q) * math.exp(-free * rate)
        travel = travel - direction * free
    substeps = 0
    if travel != 0.0:
        if abs(travel) < longest * 1e9:
            substeps = int(math.ceil(abs(travel) / longest))
        else:                   # inf or NaN (a travel not finite, a longest step vanishing): over any budget
            substeps = max_substeps + 1
        if substeps > max_substeps:
            return (e, q), substeps, TOO_MANY_SUBSTEPS
        h = travel / substeps
        a = abs(h)
        for i in range(substeps):
            de1, dq1 = walk_rates(m, e, q, direction)
            de2, dq2 = walk_rates(m, e + 0.5 * h * de1, q + 0.5 * a * dq1, direction)
            de3, dq3 = walk_rates(m, e + 0.5 * h * de2, q + 0.5 * a * dq2, direction)
            de4, dq4 = walk_rates(m, e + h * de3, q + a * dq3, direction)
            e = e + h * (de1 + 2.0 * (de2 + de3) + de4) / 6.0
            q = q + a * (dq1 + 2.0 * (dq2 + dq3) + dq4) / 6.0
    if not (math.isfinite(e) and math.isfinite(q)):
        return (e, q), substeps, NOT_FINITE
    return (e, q), substeps, OK


def initial_state(m, x0):
    """At rest: the element at its play's centre (e = 0, z = 0), stuck (q = 1)."""
    return (0.0, 1.0)


def resting_state(m, x0, force):
    """At rest at x0 [mm] holding ``force`` [N]: the element stuck (q = 1) at the deflection whose
    force A*D(e) is force - k0*x0, the nearest its yield allows each way ((1 + eps) times zp or
    zn, where it starts to slide)."""
    c0, k0, A, zp, zn, n, gap, width, eps, rate, longest = m
    z = force - k0 * x0
    if z > zp * (1.0 + eps):
        z = zp * (1.0 + eps)
    if z < -zn * (1.0 + eps):
        z = -zn * (1.0 + eps)
    return (inverse_dead_zone(z / A, gap, width), 1.0)


def force(m, state, x, v):
    """F = c0*v + k0*x + A*D(e) [N]."""
    c0, k0, A, zp, zn, n, gap, width, eps, rate, longest = m
    return c0 * v + k0 * x + A * dead_zone(state[0], gap, width)


def jump(m, state, jump_mm):
    """The element walks along the jump."""
    new, substeps, status = walk(m, state, jump_mm, DEFAULT_MAX_SUBSTEPS)
    return new, status


def integrate(m, state, x, v, h, max_substeps):
    """The element walks along v*h; returns (state, substeps, status)."""
    return walk(m, state, v * h, max_substeps)


def derivatives(m, state, x, v):
    """(de/dt [mm/s], dq/dt [1/s]) (model exchange)."""
    direction = 1.0 if v > 0.0 else -1.0
    de, dq = walk_rates(m, state[0], state[1], direction)
    return (v * de, abs(v) * dq)


def switches(m, state, x, v):
    """v [mm/s], z [N] and the play's corners e - gap and e + gap [mm]: where they change sign the
    element's law switches branch (the corners matter where width = 0)."""
    c0, k0, A, zp, zn, n, gap, width, eps, rate, longest = m
    e = state[0]
    return (v, A * dead_zone(e, gap, width), e - gap, e + gap)


SEARCH = SearchBox(
    (SearchCoordinate("k0", KIND.stiffness, -5.0, 1.0), SearchCoordinate("c0", KIND.damping, -5.0, 1.0),
     SearchCoordinate("A", KIND.stiffness, -1.0, 3.0),
     SearchCoordinate("zp", KIND.force, -1.5, 0.5), SearchCoordinate("zn", KIND.force, -1.5, 0.5),
     SearchCoordinate("n", KIND.exponent, 0.5, 8.0),
     SearchCoordinate("gap", KIND.travel, -4.0, -0.3), SearchCoordinate("width", KIND.travel, -4.0, -1.0),
     SearchCoordinate("eps", KIND.exponent, 0.0, 2.0), SearchCoordinate("delta", KIND.travel, -3.0, 0.0)))
"""The fit's box: the springs against k_ref, the levels against the data's force F_ref, the play,
its engagement width and the breakaway's travel against the largest amplitude x_ref, log10 all;
n and eps as they are."""


MODEL = BushingModel(
    "asymmetric_bouc_wen", "AsymmetricBoucWenBushing", "asymmetric Bouc-Wen with play", PARAMETER_SPECS,
    (StateSpec("e", 0, "m", "the element's deflection, play included"),
     StateSpec("q", 1, "1", "breakaway memory: 1 stuck, 0 sliding")),
    "params_asymmetric_bouc_wen_illustrative.json", prepare, initial_state, jump, integrate, force,
    derivatives, switches,
    switch_specs=(StateSpec("v", 0, "m/s", "the velocity input, which drives the element"),
                  StateSpec("z", 1, "N", "the element's force"),
                  StateSpec("play_upper", 2, "m", "e - gap: the play's upper corner"),
                  StateSpec("play_lower", 3, "m", "e + gap: the play's lower corner")),
    search=SEARCH, plot_style=("C8", "-"), rank=25, resting_state=resting_state,
    description="A Bouc-Wen element whose yield differs by direction, with free play and breakaway, in "
                "parallel with a spring and a dashpot (inputs x [m], v [m/s]; output F [N]).",
    static_spring=("k0",))
