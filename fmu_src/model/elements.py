"""Elements the models share, written in the kernel language: no model's equations live here.

- ``softplus``: log(1 + exp(z)), the smooth corner every element below rounds with;
- ``dead_zone``: free play of +-gap around a centre, its corners rounded over a width (0: hard);
- ``ramp``, ``smooth_step``, ``limit_force``: a travel limit (a gap, then a stiffness with an
  exponent and a damping that ramps in over a depth), as the multibody tools' bushing limits;
- ``pchip_slope``, ``pchip_end_slope``, ``hermite``: the monotone cubic through a measured static
  curve's knots (scipy's PchipInterpolator), for a backbone;
- ``track_substeps``: the substeps of a hydraulic mount's fluid column (its inertia track) over a
  step, which both hydraulic models take;

Like ``integration``, this module is compiled by numba once for every model that imports it
(``fmu_src/kernels/numba_binding.py``), translated into C with the kernels that call it, and
differentiated with them (``fmu_src/kernels/tangents.py``). Units are the caller's (mm, N).
"""
from __future__ import annotations

import math

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
