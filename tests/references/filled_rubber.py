"""The filled-rubber models' equations typed from the literature once more, independently of
``fmu_src`` (numpy and scipy only): the references of ``berg`` and ``fractional``.

A test's displacement is a path sampled uniformly, x_k at t_k = k*h [mm, s], straight between
samples (what a co-simulation master's x_k + v_k*(t - t_k) is, and what a fine enough grid makes
of a smooth input). On such a path every part of the force is computed exactly, each by its own
definition:

- the progressive spring k0*x + k3*x^3;
- Berg's friction (Berg, Vehicle System Dynamics 30, 1998): from rest F_f = Ff_max*x/(x2 + |x|);
  after a reversal at (x_s, F_s), with beta = F_s/Ff_max, moving up
  F_f = F_s + (x - x_s)*(Ff_max - F_s)/(x2*(1 - beta) + (x - x_s)), moving down
  F_f = F_s + (x - x_s)*(Ff_max + F_s)/(x2*(1 + beta) - (x - x_s)); a reversal is a sample where
  the path's direction changes (:func:`berg_friction`, a loop over the samples);
- a Maxwell element, spring k in series with dashpot c: the linear system k*s/(s + k/c) from x,
  by scipy.signal.lsim with linear interpolation between samples (exact on the path);
- the fractional derivative b*D^alpha x of the path (Caputo from the start, the bushing at rest
  before): on a straight piece of slope s_k, D^alpha x(t_n) collects
  s_k*((t_n - t_k)^(1-alpha) - (t_n - t_k+1)^(1-alpha))/Gamma(2 - alpha) (the L1 sum, exact for a
  path of straight pieces), summed by FFT convolution (:func:`fractional_derivative`).

The steady state of a sine x = X*sin(omega*t), for the data sheet (:func:`data_sheet`): the parts
are in parallel, so K* = F1/X is the sum of their first harmonics: k0 + 3/4*k3*X^2 (sin^3 = (3 sin -
sin 3)/4), b*(i*omega)^alpha, each Maxwell element's k*i*omega/(i*omega + k/c), and the
friction's, which does not depend on the frequency (its loop over one cycle after the first
reversal, sampled finely and integrated).

Units: mm, s, N; parameters in N-mm-s (k3 N/mm^3, b N.s^alpha/mm).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.signal import fftconvolve, lsim
from scipy.special import gamma as gamma_function


def _friction_law(limit, half_travel, x, x_s, F_s, direction):
    """Berg's friction at x on the branch leaving (x_s, F_s) in ``direction`` (0: from rest)."""
    if limit == 0.0:
        return 0.0
    if direction == 0:
        return limit * (x - x_s) / (half_travel + abs(x - x_s))
    beta = F_s / limit
    if direction > 0:
        return F_s + (x - x_s) * (limit - F_s) / (half_travel * (1.0 - beta) + (x - x_s))
    return F_s + (x - x_s) * (limit + F_s) / (half_travel * (1.0 + beta) - (x - x_s))


def berg_friction(x, limit, half_travel):
    """Berg's friction force [N] at every sample of the path ``x`` [mm], from rest at x[0]."""
    x = [float(value) for value in x]
    out = np.zeros(len(x))
    x_s, F_s, direction = x[0], 0.0, 0
    for k in range(1, len(x)):
        motion = x[k] - x[k - 1]
        heading = (motion > 0) - (motion < 0)
        if heading and heading != direction:
            if direction == 0 and (x[k - 1] - x_s) * heading >= 0:
                direction = heading          # the first motion from rest: the same curve
            else:
                F_s = _friction_law(limit, half_travel, x[k - 1], x_s, F_s, direction)
                x_s, direction = x[k - 1], heading
        out[k] = _friction_law(limit, half_travel, x[k], x_s, F_s, direction)
    return out


def maxwell_force(t, x, stiffness, damping):
    """The force [N] of a spring ``stiffness`` [N/mm] in series with a dashpot ``damping``
    [N.s/mm], relaxed at x[0], along the path (t, x)."""
    x = np.asarray(x, dtype=float)
    rate = stiffness / damping
    _, force, _ = lsim(([stiffness, 0.0], [1.0, rate]), U=x - x[0], T=np.asarray(t, dtype=float), interp=True)
    return np.asarray(force)


def fractional_derivative(t, x, alpha):
    """D^alpha of the path (t, x) [mm/s^alpha] at every sample, the path at rest before t[0]
    (Caputo from t[0]); t must be uniform."""
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    h = t[1] - t[0]
    if not np.allclose(np.diff(t), h, rtol=1e-9, atol=0.0):
        raise ValueError("fractional_derivative needs uniform samples")
    slopes = np.diff(x) / h
    m = np.arange(1, x.size, dtype=float)
    weights = h ** (1.0 - alpha) * (m ** (1.0 - alpha) - (m - 1.0) ** (1.0 - alpha))
    out = np.zeros(x.size)
    out[1:] = fftconvolve(slopes, weights)[: x.size - 1] / gamma_function(2.0 - alpha)
    return out


def spring_force(p, x):
    return p["k0"] * x + p["k3"] * x ** 3


def berg_force(p, t, x):
    """Berg's model: spring, friction and two Maxwell elements [N] along the path (t, x)."""
    return (spring_force(p, x) + berg_friction(x, p["Ff_max"], p["x2"])
            + maxwell_force(t, x, p["k1"], p["c1"]) + maxwell_force(t, x, p["k2"], p["c2"]))


def fractional_force(p, t, x):
    """The fractional model: spring, friction and b*D^alpha x [N] along the path (t, x)."""
    return (spring_force(p, x) + berg_friction(x, p["Ff_max"], p["x2"])
            + p["b"] * fractional_derivative(t, x, p["alpha"]))


FORCES = {"berg": berg_force, "fractional": fractional_force}


def friction_first_harmonic(limit, half_travel, amplitude_mm, samples=4000, cycles=40):
    """(in phase, quadrature) first harmonic [N] of Berg's friction on the steady loop of
    x = X*sin(phi): the last of ``cycles`` cycles from rest, ``samples`` a cycle. (The loop
    settles geometrically, by about a third per half cycle: after the first reversal at X the
    friction is its curve from rest there, and the branch down does not end at minus that.)"""
    phase = 2.0 * np.pi * np.arange(cycles * samples + 1) / samples
    x = amplitude_mm * np.sin(phase)
    force = berg_friction(x, limit, half_travel)[-(samples + 1):]
    phi = phase[-(samples + 1):]
    # trapezoids over one period (the loop's corners at the reversals are samples):
    # F1 = (1/pi) * integral of F*sin and F*cos over the period
    in_phase = np.trapezoid(force * np.sin(phi), phi) / np.pi
    quadrature = np.trapezoid(force * np.cos(phi), phi) / np.pi
    return in_phase, quadrature


def data_sheet(model, p, amplitudes_mm, frequencies_hz):
    """{(X, f): (|K*| [N/mm], loss angle [deg])} of the steady sines, the parts' first
    harmonics summed (module docstring)."""
    out = {}
    for X in amplitudes_mm:
        friction_in, friction_quadrature = friction_first_harmonic(p["Ff_max"], p["x2"], X)
        for f in frequencies_hz:
            s = 2j * math.pi * f
            stiffness = p["k0"] + 0.75 * p["k3"] * X ** 2 + (friction_in + 1j * friction_quadrature) / X
            if model == "fractional":
                stiffness += p["b"] * s ** p["alpha"]
            else:
                for k, c in ((p["k1"], p["c1"]), (p["k2"], p["c2"])):
                    stiffness += k * s / (s + k / c)
            out[X, f] = (abs(stiffness), math.degrees(np.angle(stiffness)))
    return out
