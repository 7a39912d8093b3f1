"""A voided, asymmetric bushing, typed here from its equations (numpy and scipy only; nothing of the
project): the truth of data/generate_voided_bushing.py and of the tests that fit it.

    F = S(x) + z + f1 + b                                          the force a rig measures [N]
    S(x) = ks*x - (kr - ks)*w*softplus((xv - x)/w) + k3*x^3 + kb*(w*softplus((x - xb)/w))^2
    dz/dt = dx/dt*(A - (gamma + beta*sgn(dx/dt*z))*|z|)            a Bouc-Wen element, n = 1 [N]
    df1/dt = k1*dx/dt - (k1/c1)*f1                                  a Maxwell element [N]

S is the static curve: soft (ks) until the void closes at x = xv < 0, then the rubber's kr; a
progressive k3*x^3 both ways; a bump stop kb*d^2 beyond xb > 0; the corners rounded over w. z is
the filled rubber's friction-like hysteresis (its level A/(beta + gamma)), f1 its rate dependence
(time constant c1/k1), b the load cell's zero, which every test of the rig carries.

Units mm, N, s. ``force(t, x_of_t)`` solves the states by scipy's Radau in continuous time along
the displacement function x_of_t (returning x and dx/dt at t), from rest at x(0).
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

PARAMETERS = {
    "ks": 150.0,       # N/mm: the void side's soft rubber
    "kr": 900.0,       # N/mm: the rubber once the void has closed
    "xv": -1.5,        # mm: where the void closes
    "k3": 12.0,        # N/mm^3: progressive rubber
    "kb": 2500.0,      # N/mm^2: the bump stop, quadratic in its penetration
    "xb": 2.5,         # mm: where the bump stop engages
    "w": 0.15,         # mm: the corners' width
    "A": 600.0,        # N/mm: the hysteresis's initial stiffness
    "beta": 3.75,      # 1/mm: (beta + gamma)*|z| = A at z = 80 N, its level
    "gamma": 3.75,
    "k1": 300.0,       # N/mm: the Maxwell element's spring
    "c1": 3.0,         # N.s/mm: its dashpot, time constant 10 ms
    "b": 40.0,         # N: the load cell's zero
}
RTOL, ATOL_N = 1e-10, 1e-8


def softplus(z):
    return np.logaddexp(0.0, z)


def static_force(p: dict, x):
    """S(x) [N]: the bushing's static curve (module docstring)."""
    w = p["w"]
    return (p["ks"] * x - (p["kr"] - p["ks"]) * w * softplus((p["xv"] - x) / w) + p["k3"] * x ** 3
            + p["kb"] * (w * softplus((x - p["xb"]) / w)) ** 2)


def rhs(t, state, p, path):
    z, f1 = state
    _, xd = path(t)
    zd = xd * (p["A"] - (p["gamma"] + p["beta"] * np.sign(xd * z)) * abs(z))
    return [zd, p["k1"] * xd - p["k1"] / p["c1"] * f1]


def force(p: dict, t: np.ndarray, path, max_step: float = 1e-3) -> np.ndarray:
    """The measured force [N] at the times ``t`` along ``path`` (t -> (x [mm], dx/dt [mm/s])),
    from rest: z = f1 = 0 at t[0]."""
    solution = solve_ivp(rhs, (t[0], t[-1]), [0.0, 0.0], method="Radau", t_eval=t, args=(p, path), rtol=RTOL,
                         atol=ATOL_N, max_step=max_step)
    if not solution.success:
        raise RuntimeError(solution.message)
    x, _ = path(t)
    z, f1 = solution.y
    return static_force(p, x) + z + f1 + p["b"]
