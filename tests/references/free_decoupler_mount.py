"""A hydraulic mount with a free decoupler plate, typed from its equations and solved by scipy
(numpy and scipy only; nothing of ``fmu_src`` or ``identification``): the independent reference
for ``fmu_src/models/hydraulic_free_decoupler_model.py`` and the truth of the synthetic free-play
mount in ``data/generate_hydraulic_free_decoupler.py``.

The mount (units N-mm-s; parameters as in the model's parameter file):

    F = k0*x + k3*x^3 + c0*dx/dt + f1 + kb*(x - y - u)
    df1/dt = k1*dx/dt - (k1/c1)*f1
    dy/dt = w,   mf*dw/dt = P - (kb + kc)*u - cf*w - ct*|w|*w,   P = kb*(x - y) - kc*y

and the plate, massless, where the pressure across it balances its centring spring and its cage:

    P - (kb + kc)*u = kd*u + cage(u)

- width = 0, the hard cage: cage(u) = kcage*(|u| - gap)*sign(u) beyond the free travel, 0 inside.
  Solved here for u by scipy's brentq on the balance itself (not by the model's closed form).
- width > 0, the cage's corner rounded: u = P/K - kcage/(K*(K + kcage))*D(P), K = kb + kc + kd,
  D(P) = W*(softplus((P - K*gap)/W) - softplus((-P - K*gap)/W)), W = K*width, softplus written
  with numpy's logaddexp. As width -> 0 this is the hard cage's solution (the tests check it).

The state (y, w, f1) starts relaxed (P = 0, the plate centred, the fluid still) and scipy's Radau
integrates the continuous-time input.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

RTOL = 1e-10
ATOL = (1e-12, 1e-10, 1e-9)        # y [mm], w [mm/s], f1 [N]


def plate_travel(p, pressure):
    """u [mm] of the plate under the pressure difference ``pressure`` [N] (module docstring)."""
    kb, kc, kd, kcage, gap, width = p["kb"], p["kc"], p["kd"], p["kcage"], p["gap"], p["width"]
    stiffness = kb + kc + kd
    if width > 0.0:
        free, rounding = stiffness * gap, stiffness * width
        dead = rounding * (np.logaddexp(0.0, (pressure - free) / rounding)
                           - np.logaddexp(0.0, (-pressure - free) / rounding))
        return pressure / stiffness - kcage / (stiffness * (stiffness + kcage)) * dead

    def balance(u):
        beyond = max(abs(u) - gap, 0.0) * np.sign(u)
        return pressure - (kb + kc) * u - kd * u - kcage * beyond
    if pressure == 0.0:
        return 0.0
    bound = 2.0 * abs(pressure) / stiffness    # |u| <= |P|/K (the cage only pushes back), bracketed with room
    return brentq(balance, -bound, bound, xtol=1e-15, rtol=1e-15)


def fluid_path(p, x, y):
    """(the fluid path's force kb*(x - y - u) [N], the pressure that drives the track [N])."""
    pressure = p["kb"] * (x - y) - p["kc"] * y
    u = plate_travel(p, pressure)
    return p["kb"] * (x - y - u), pressure - (p["kb"] + p["kc"]) * u


def rhs(t, state, p, signal):
    """d/dt (y, w, f1) under the input ``signal(t)`` -> (x [mm], dx/dt [mm/s])."""
    y, w, f1 = state
    x, xd = signal(t)
    _, drive = fluid_path(p, x, y)
    return [w, (drive - p["cf"] * w - p["ct"] * abs(w) * w) / p["mf"], p["k1"] * xd - p["k1"] / p["c1"] * f1]


def force(p, states, x, xd):
    """F [N] at the states (columns (y, w, f1)), displacements x [mm] and velocities xd [mm/s]."""
    y, _, f1 = states
    bulge = np.array([fluid_path(p, xi, yi)[0] for xi, yi in zip(np.atleast_1d(x), np.atleast_1d(y))])
    return p["k0"] * x + p["k3"] * x ** 3 + p["c0"] * xd + f1 + bulge


def start(p, x0):
    """Relaxed at x0: P = 0 (y = kb*x0/(kb + kc)), the plate centred, the fluid still."""
    return [p["kb"] * x0 / (p["kb"] + p["kc"]), 0.0, 0.0]


def steady_stiffness(p, amplitude_mm, frequency_hz, settle_s=4.0, points=1024):
    """K* = F1/X1 [N/mm] on x = amplitude*sin(2*pi*f*t) from rest: the first Fourier coefficient
    of the force over the first whole cycle after ``settle_s`` [s], by the rectangle rule on
    ``points`` samples of Radau's solution (exact for a trigonometric polynomial of degree below
    ``points``), over that of x."""
    omega = 2.0 * np.pi * frequency_hz
    period = 1.0 / frequency_hz
    begin = np.ceil(settle_s / period) * period

    def signal(t):
        return amplitude_mm * np.sin(omega * t), amplitude_mm * omega * np.cos(omega * t)
    t = begin + period * np.arange(points) / points
    solution = solve_ivp(rhs, (0.0, begin + period), start(p, 0.0), method="Radau", t_eval=t, args=(p, signal),
                         rtol=RTOL, atol=np.array(ATOL), max_step=period / 16)
    if not solution.success:
        raise RuntimeError(f"{amplitude_mm} mm, {frequency_hz} Hz: {solution.message}")
    x, xd = signal(t)
    f = force(p, solution.y, x, xd)
    kernel = np.exp(-1j * omega * t)
    return np.sum(f * kernel) / np.sum(x * kernel)
