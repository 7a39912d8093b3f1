"""Elements the models share, written in the kernel language: no model's equations live here.

- ``softplus``: log(1 + exp(z)), the smooth corner every element below rounds with;
- ``dead_zone``: free play of +-gap around a centre, its corners rounded over a width (0: hard);
- ``ramp``, ``smooth_step``, ``limit_force``: a travel limit (a gap, then a stiffness with an
  exponent and a damping that ramps in over a depth), as the multibody tools' bushing limits;
- ``pchip_slope``, ``pchip_end_slope``, ``hermite``: the monotone cubic through a measured static
  curve's knots (scipy's PchipInterpolator), for a backbone;
- the fluid column of a hydraulic mount (its inertia track), which both hydraulic models take:
  its substeps over a step (``track_substeps``), its decoupler by law (``decoupler_travel``: a
  membrane or a free plate in a cage), the force and acceleration it gives (``track_force``,
  ``track_acceleration``) and its Runge-Kutta step (``track_step``);
- the rate-independent and viscoelastic elements of the filled-rubber models (``berg_model``,
  ``fractional_model``) and the hydraulic mounts: Berg's friction (``friction_force``,
  ``friction_turn``; ``vector_friction_*`` on a displacement vector), an algebraic law of the
  travel since the last reversal, so exact whatever the step; and the Maxwell element (a spring
  and a dashpot in series, ``maxwell_step``), linear and propagated exactly over a step with
  constant velocity.

Like ``integration``, this module is compiled by numba once for every model that imports it
(``fmu_src/kernels/numba_binding.py``), translated into C with the kernels that call it, and
differentiated with them (``fmu_src/kernels/tangents.py``); it takes the machinery's vector
algebra and decay factors from ``integration`` (its compiled copy where compiled). Units are the
caller's (mm, N).
"""
from __future__ import annotations

import math

from .integration import decay_factors, vector_axpy, vector_dot, vector_norm, vector_scale

SOFTPLUS_FLOOR = -37.0
"""Below it log(1 + exp(z)) < 8.6e-17, under half a unit of the last place of 1: :func:`softplus`
is 0 there, and a dead zone's far side costs no exp."""


def softplus(z):
    """log(1 + exp(z)), written so that exp never overflows (both branches are the same analytic
    function); 0 below SOFTPLUS_FLOOR."""
    if z > 0.0:
        return z + math.log(1.0 + math.exp(-z))
    if z < SOFTPLUS_FLOOR:
        return 0.0
    return math.log(1.0 + math.exp(z))


def dead_zone(e, gap, width):
    """Free play: 0 for |e| <= gap, e -+ gap beyond (``gap`` >= 0, same unit as e); with
    ``width`` > 0 the corners are rounded by a softplus over that width,
    width*(softplus((e - gap)/width) - softplus((-e - gap)/width)), odd in e and smooth; ``width``
    = 0 the hard corners."""
    if width <= 0.0:
        if e > gap:
            return e - gap
        if e < -gap:
            return e + gap
        return 0.0
    return width * (softplus((e - gap) / width) - softplus((-e - gap) / width))


def logistic(y):
    """1/(1 + exp(-y)), the softplus's slope, written so that exp never overflows."""
    if y >= 0.0:
        return 1.0 / (1.0 + math.exp(-y))
    e = math.exp(y)
    return e / (1.0 + e)


DEAD_ZONE_BISECTIONS = 60
"""Halvings of the bracket of :func:`inverse_dead_zone` (60: the bracket shrinks below rounding)."""


def inverse_dead_zone(d, gap, width):
    """The e whose ``dead_zone(e, gap, width)`` is d (same units): d + gap, d - gap or 0 with hard
    corners; with rounded ones, the root of the monotone softplus form, bracketed in
    [0, d + gap + width] (or its mirror: there D(e) > d), halved DEAD_ZONE_BISECTIONS times, then
    one Newton step, whose derivative with respect to d, gap and width is the root's own (what the
    fit's tangents of a bisection alone would not give)."""
    if width <= 0.0:
        if d > 0.0:
            return d + gap
        if d < 0.0:
            return d - gap
        return 0.0
    if d == 0.0:
        return 0.0
    low = 0.0
    high = d + gap + width
    if d < 0.0:
        low = d - gap - width
        high = 0.0
    for i in range(DEAD_ZONE_BISECTIONS):
        middle = 0.5 * (low + high)
        if dead_zone(middle, gap, width) < d:
            low = middle
        else:
            high = middle
    e = 0.5 * (low + high)
    slope = logistic((e - gap) / width) + logistic((-e - gap) / width)
    if slope > 0.0:
        e = e - (dead_zone(e, gap, width) - d) / slope
    return e


def ramp(d, width):
    """max(d, 0) with its corner rounded over ``width`` (width*softplus(d/width)); the hard corner
    where ``width`` = 0. Same unit as d."""
    if width <= 0.0:
        if d > 0.0:
            return d
        return 0.0
    return width * softplus(d / width)


def smooth_step(s):
    """0 for s <= 0, 1 for s >= 1 and 3s^2 - 2s^3 between: a step with no corner in its value or
    slope (MSC Adams' STEP, which its IMPACT function ramps a contact's damping in with)."""
    if s <= 0.0:
        return 0.0
    if s >= 1.0:
        return 1.0
    return s * s * (3.0 - 2.0 * s)


def limit_force(u, v, gap, stiffness, exponent, damping, depth, width):
    """The force [N] of a travel limit on the positive side at displacement u [mm] and velocity v
    [mm/s]: nothing within ``gap`` [mm]; beyond it, at penetration d = ramp(u - gap, width),
    stiffness*d^exponent [N/mm^exponent] and a damping [N.s/mm] that ramps in over ``depth`` [mm]
    (smooth_step(d/depth)*damping*v). The negative side is -limit_force(-u, -v, ...)."""
    d = ramp(u - gap, width)
    if d <= 0.0:
        return 0.0
    return stiffness * d ** exponent + damping * smooth_step(d / depth) * v


def pchip_slope(h0, h1, s0, s1):
    """The slope at an interior knot of the monotone cubic (Fritsch and Carlson; scipy's
    PchipInterpolator): 0 where the secants s0 (of the interval before, length h0) and s1 (after,
    h1) differ in sign or either is 0, else their weighted harmonic mean."""
    if s0 * s1 <= 0.0:
        return 0.0
    w1 = 2.0 * h1 + h0
    w2 = h1 + 2.0 * h0
    return (w1 + w2) / (w1 / s0 + w2 / s1)


def pchip_end_slope(h0, h1, s0, s1):
    """The slope at an end knot (scipy's PchipInterpolator: the three-point estimate from the end
    interval h0, s0 and the next h1, s1, set to 0 where its sign differs from s0's and limited to
    3*s0 where s0 and s1 differ in sign)."""
    d = ((2.0 * h0 + h1) * s0 - h0 * s1) / (h0 + h1)
    if d * s0 <= 0.0:
        return 0.0
    if s0 * s1 < 0.0 and abs(d) > abs(3.0 * s0):
        return 3.0 * s0
    return d


def hermite(u, xa, xb, fa, fb, da, db):
    """The cubic Hermite interpolant on [xa, xb] with values fa, fb and slopes da, db, at u."""
    h = xb - xa
    t = (u - xa) / h
    return (fa * (1.0 + 2.0 * t) * (1.0 - t) * (1.0 - t) + da * h * t * (1.0 - t) * (1.0 - t)
            + fb * t * t * (3.0 - 2.0 * t) - db * h * t * t * (1.0 - t))


THETA_TRACK = 0.25
"""A substep h_s of a fluid column's Runge-Kutta method keeps h_s*(sqrt((kb + kc)/mf) +
(cf + 2*ct*|w|)/mf) <= THETA_TRACK: the method's error on the column's free motion is then about
THETA_TRACK^5/120 = 8e-6 of it a substep."""


def track_substeps(kb, kc, mf, cf, ct, w, h):
    """The substeps over h [s] that keep each within THETA_TRACK of the fluid column's fastest
    rate: its natural frequency on the bulge and chamber stiffnesses kb, kc [N/mm] with its mass
    mf [N.s^2/mm], plus its damping rate (cf [N.s/mm] and the quadratic ct [N.s^2/mm^2] at its
    velocity w [mm/s]). A decoupler only softens what the column feels, so this bounds it too."""
    rate = math.sqrt((kb + kc) / mf) + (cf + 2.0 * ct * abs(w)) / mf
    count = h * rate / THETA_TRACK
    if not count < 1e9:         # inf or NaN (w not finite, mf vanishing): more than any budget
        return 1_000_000_000
    return max(1, int(math.ceil(count)))


MEMBRANE = 0.0
"""A decoupler law (:func:`decoupler_travel`): a membrane that engages its cage smoothly,
``(MEMBRANE, gap, stiffness, 0.0, 0.0)``."""
FREE_PLATE = 1.0
"""A decoupler law (:func:`decoupler_travel`): a plate free within +-gap, then held by its cage,
``(FREE_PLATE, K*gap, K*width, kcage/(K*(K + kcage)), 1/K)``."""


def decoupler_travel(decoupler, pressure):
    """u [mm], a hydraulic mount's decoupler travel under the chambers' pressure difference
    ``pressure`` [N], by its law (``decoupler[0]``; a law is a value, as the kernel language
    passes no functions):

    - MEMBRANE (law, gap [mm], stiffness K [N/mm], 0, 0): u = gap*tanh(P/(K*gap)), 0 where gap = 0;
      the tanh written with exp(-2|s|), which never overflows;
    - FREE_PLATE (law, K*gap [N], K*width [N], kcage/(K*(K + kcage)) [mm/N], 1/K [mm/N]) with K
      the plate's and the chambers' stiffness: u = P/K within the free travel, less what the
      cage takes beyond it (:func:`dead_zone` of P, rounded over the width)."""
    law, a, b, c, d = decoupler
    if law == MEMBRANE:
        if a <= 0.0:
            return 0.0
        s = pressure / (b * a)
        e = math.exp(-2.0 * abs(s))
        return math.copysign(a * (1.0 - e) / (1.0 + e), s)
    return pressure * d - c * dead_zone(pressure, a, b)


def track_force(kb, kc, decoupler, y, x):
    """(the force kb*(x - y - u) a hydraulic mount's fluid path puts on the mount [N], the pressure
    difference dp that drives its inertia track [N]) at mount displacement x and fluid displacement
    y [mm]: bulge stiffness kb and chamber stiffness kc [N/mm], u the ``decoupler``'s travel."""
    pressure = kb * (x - y) - kc * y
    u = decoupler_travel(decoupler, pressure)
    return kb * (x - y - u), pressure - (kb + kc) * u


def track_acceleration(kb, kc, mf, cf, ct, decoupler, y, w, x):
    """dw/dt [mm/s^2] of the fluid column (mass mf [N.s^2/mm], linear and turbulent damping cf
    [N.s/mm], ct [N.s^2/mm^2]) at fluid displacement y [mm], velocity w [mm/s] and mount
    displacement x [mm]."""
    bulge, drive = track_force(kb, kc, decoupler, y, x)
    return (drive - cf * w - ct * abs(w) * w) / mf


def track_step(kb, kc, mf, cf, ct, decoupler, y, w, x, v, h, n):
    """(y, w) of the fluid column after h [s] of mount travel x + v*t: the classical Runge-Kutta
    method on ``n`` equal substeps (:func:`track_substeps`), x + v*t exact within each."""
    s = h / n
    for i in range(n):
        x0 = x + v * (i * s)
        a1 = track_acceleration(kb, kc, mf, cf, ct, decoupler, y, w, x0)
        y2 = y + 0.5 * s * w
        w2 = w + 0.5 * s * a1
        a2 = track_acceleration(kb, kc, mf, cf, ct, decoupler, y2, w2, x0 + 0.5 * s * v)
        y3 = y + 0.5 * s * w2
        w3 = w + 0.5 * s * a2
        a3 = track_acceleration(kb, kc, mf, cf, ct, decoupler, y3, w3, x0 + 0.5 * s * v)
        y4 = y + s * w3
        w4 = w + s * a3
        a4 = track_acceleration(kb, kc, mf, cf, ct, decoupler, y4, w4, x0 + s * v)
        y = y + s / 6.0 * (w + 2.0 * w2 + 2.0 * w3 + w4)
        w = w + s / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return y, w


def friction_force(limit, half_travel, travel, reversal_force, direction):
    """Berg's smooth rate-independent friction force [N] (Berg, Vehicle System Dynamics 30, 1998).

    ``limit`` F_max [N] is the force it tends to far from a reversal, ``half_travel`` x2 [mm] the
    travel from rest at which it reaches F_max/2; the state is the ``travel`` x - x_s [mm] since
    the last reversal, the force F_s [N] there (``reversal_force``) and the ``direction`` of the
    motion since (+1 up, -1 down, 0 not yet moved). With beta = F_s/F_max, moving up

        F = F_s + (x - x_s)*(F_max - F_s)/(x2*(1 - beta) + (x - x_s)),

    moving down F = F_s + (x - x_s)*(F_max + F_s)/(x2*(1 + beta) - (x - x_s)); from rest (F_s = 0)
    both are F_max*x/(x2 + |x|). Every branch leaves its reversal with the slope F_max/x2 and tends
    to +-F_max. Written times F_max in numerator and denominator, so F_max = 0 gives 0."""
    if direction > 0.0 or (direction == 0.0 and travel >= 0.0):
        room = limit - reversal_force
        denominator = half_travel * room + travel * limit
    else:
        room = limit + reversal_force
        denominator = half_travel * room - travel * limit
    if denominator > 0.0:
        return reversal_force + travel * room * limit / denominator
    return reversal_force


ROUNDING_JUMP_MM = 1e-12
"""A displacement jump smaller than this [mm, or rad] is rounding, not motion, for the friction: a
master that passes v = (x_k+1 - x_k)/h gives x_k + v*h = x_k+1 only to rounding (1e-16 of x), and
a reversal there would restart the friction's branch at every step."""


def friction_jump_turn(limit, half_travel, travel, reversal_force, direction, jump_mm):
    """:func:`friction_turn` for a displacement jump: one of rounding size (ROUNDING_JUMP_MM) never
    reverses the friction (the travel still takes it)."""
    motion = jump_mm if abs(jump_mm) > ROUNDING_JUMP_MM else 0.0
    return friction_turn(limit, half_travel, travel, reversal_force, direction, motion)


def friction_turn(limit, half_travel, travel, reversal_force, direction, motion):
    """The friction state (travel, reversal force, direction) once the displacement moves the way
    of ``motion``'s sign (a velocity or a jump): where that is against ``direction``, a reversal
    here (travel 0, the reversal force the force here); the first motion from rest only sets the
    direction (the curve from rest is both branches at once); no motion changes nothing."""
    if motion > 0.0:
        heading = 1.0
    elif motion < 0.0:
        heading = -1.0
    else:
        return travel, reversal_force, direction
    if heading == direction:
        return travel, reversal_force, direction
    if direction == 0.0 and travel * heading >= 0.0:
        return travel, reversal_force, heading
    return 0.0, friction_force(limit, half_travel, travel, reversal_force, direction), heading


def vector_friction_force(limit, half_travel, travel, reversal_force):
    """Berg's friction on a displacement vector [N, a 3-vector]: from the last reversal, with the
    travel d = x - x_s (a 3-vector) and the force F_s there,

        F = F_s + R*|d|*F_max/(x2*|R| + |d|*F_max),   R = F_max*d/|d| - F_s,

    the force heads from F_s towards F_max in the direction of the travel, with Berg's law in the
    travel's length. Along a line it is Berg's law (R = +-F_max - F_s, |R| = F_max -+ F_s: the
    denominator x2*F_max*(1 -+ beta) + |d|*F_max of :func:`friction_force`); it depends on
    positions only (rate-independent) and turns with them (rotation invariant); F = F_s at d = 0,
    and F_max*x/(x2 + |x|) from rest (F_s = 0). Derivation: docs/models.md."""
    r = vector_norm(travel)
    if r == 0.0:
        return reversal_force
    room = vector_axpy(limit / r, travel, vector_scale(-1.0, reversal_force))
    denominator = half_travel * vector_norm(room) + r * limit
    if denominator > 0.0:
        return vector_axpy(r * limit / denominator, room, reversal_force)
    return reversal_force


def vector_friction_turn(limit, half_travel, travel, reversal_force, motion):
    """(travel, reversal force) once the displacement moves along ``motion`` (a velocity or a jump,
    3-vectors): a reversal (travel 0, the reversal force the force here) where the motion shortens
    the travel (d.motion < 0: the displacement turns back towards the last reversal), which along a
    line is a motion against the direction (:func:`friction_turn`); else as they are."""
    if vector_dot(travel, motion) < 0.0:
        return (0.0, 0.0, 0.0), vector_friction_force(limit, half_travel, travel, reversal_force)
    return travel, reversal_force


def vector_friction_jump_turn(limit, half_travel, travel, reversal_force, jump):
    """:func:`vector_friction_turn` for a displacement jump: one of rounding size
    (ROUNDING_JUMP_MM) never reverses the friction."""
    if vector_norm(jump) > ROUNDING_JUMP_MM:
        return vector_friction_turn(limit, half_travel, travel, reversal_force, jump)
    return travel, reversal_force


def maxwell_decay(rate, h):
    """(E, phi1) of a Maxwell element of ``rate`` = stiffness/damping [1/s] over h [s]:
    exp(-rate*h) and (1 - E)/(rate*h) (``decay_factors``), what :func:`maxwell_step` takes; a
    model may compute them once per step size (``prepare_step``)."""
    E, phi1, _ = decay_factors(rate * h)
    return E, phi1


def maxwell_step(force, stiffness, decay, v, h):
    """The force [N] of a Maxwell element (spring ``stiffness`` [N/mm] in series with a dashpot)
    after h [s] at velocity v [mm/s]: df/dt = k*v - rate*f, solved exactly,
    f(h) = f*E + k*v*h*phi1 with ``decay`` = (E, phi1) = :func:`maxwell_decay` (rate, h)."""
    return force * decay[0] + stiffness * v * h * decay[1]
