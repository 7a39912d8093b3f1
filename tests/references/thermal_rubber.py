"""A SYNTHETIC filled-rubber bushing that knows its temperature, typed from textbook equations
independently of the project's models: a spring and a dashpot in parallel with a Maxwell element
and a Jenkins element (a spring and a Coulomb slider in series), every rate under the
Williams-Landel-Ferry time-temperature shift and every stiffness and the slider's level scaled
exponentially with the temperature.

    log10 a_T = -C1 (T - T_ref) / (C2 + T - T_ref)          (WLF, T in K)
    k(T) = k exp(e (T - T_ref)),   c(T) = c a_T,   f_slip(T) = f_slip exp(g (T - T_ref))
    F = k(T) x + c(T) dx/dt + f_M + f_J
    df_M/dt = k_M(T) dx/dt - (k_M(T) / c_M(T)) f_M          (Maxwell: exact over straight pieces)
    f_J <- clip(f_J + k_J(T) dx, -f_slip(T), f_slip(T))      (Jenkins: elastic-perfectly plastic)

Units: x mm, t s, F N, T K, stiffness N/mm, dashpot N.s/mm. The path is taken as straight pieces
between its points; the dashpot's force at a point uses the path's velocity given there.
"""
from __future__ import annotations

import math

import numpy as np

TRUTH = dict(k=150.0, c=0.4, maxwell_k=250.0, maxwell_c=2.5, jenkins_k=400.0, jenkins_f=150.0,
             temperature_ref=296.15, wlf_c1=4.0, wlf_c2=200.0, elastic_per_K=-0.004, friction_per_K=-0.006)
"""The truth at 23 degC: a Maxwell relaxation of 10 ms there (125 ms at -20 degC, 1.3 ms at 80 degC)."""


def shift(p: dict, temperature_K: float) -> float:
    """a_T of the WLF law (its C1 in decades)."""
    d = temperature_K - p["temperature_ref"]
    if p["wlf_c2"] + d <= 0.0:
        raise ValueError(f"C2 + T - T_ref = {p['wlf_c2'] + d} K: the WLF shift is singular")
    return 10.0 ** (-p["wlf_c1"] * d / (p["wlf_c2"] + d))


def at_temperature(p: dict, temperature_K: float) -> dict:
    """The truth's constants at ``temperature_K`` [K]."""
    d = temperature_K - p["temperature_ref"]
    a, e, g = shift(p, temperature_K), math.exp(p["elastic_per_K"] * d), math.exp(p["friction_per_K"] * d)
    return dict(k=p["k"] * e, c=p["c"] * a, maxwell_k=p["maxwell_k"] * e, maxwell_c=p["maxwell_c"] * a,
                jenkins_k=p["jenkins_k"] * e, jenkins_f=p["jenkins_f"] * g)


def force(p: dict, temperature_K, t: np.ndarray, x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """F [N] at the points t [s] of the path x [mm] (straight between points; v [mm/s] the velocity
    the dashpot reads at each point), starting virgin at rest. ``temperature_K`` [K]: a number, or
    one a point, the straight piece that ends at point i (and the force there) at temperature_K[i]:
    the states carry over a change, the slider's level clipping its force from the next piece on."""
    temperature = np.broadcast_to(np.asarray(temperature_K, dtype=float), np.shape(t))
    out = np.empty(t.size)
    f_m = f_j = 0.0
    q = at_temperature(p, float(temperature[0]))
    out[0] = q["k"] * x[0] + q["c"] * v[0]
    for i in range(1, t.size):
        q = at_temperature(p, float(temperature[i]))
        rate = q["maxwell_k"] / q["maxwell_c"]
        h, dx = t[i] - t[i - 1], x[i] - x[i - 1]
        slope = dx / h
        decay = math.exp(-rate * h)
        # d f/dt = k_M s - rate f over a straight piece: f -> f e^(-rate h) + c_M s (1 - e^(-rate h))
        f_m = f_m * decay + q["maxwell_c"] * slope * (1.0 - decay)
        f_j = min(max(f_j + q["jenkins_k"] * dx, -q["jenkins_f"]), q["jenkins_f"])
        out[i] = q["k"] * x[i] + q["c"] * v[i] + f_m + f_j
    return out


def project_parameters(p: dict = TRUTH, temperature_K: float | None = None) -> dict:
    """The truth as the project's ``kelvin_voigt+maxwell+iwan1+wlf`` names it (its own equations
    are the project's; this is only the names)."""
    return dict(k=p["k"], c=p["c"], preload=0.0, maxwell_k=p["maxwell_k"], maxwell_c=p["maxwell_c"],
                iwan_k=p["jenkins_k"], iwan_f=p["jenkins_f"],
                temperature=p["temperature_ref"] if temperature_K is None else temperature_K,
                temperature_ref=p["temperature_ref"], wlf_c1=p["wlf_c1"], wlf_c2=p["wlf_c2"],
                elastic_per_K=p["elastic_per_K"], friction_per_K=p["friction_per_K"])


def heated_force(p: dict, capacity_J_K: float, resistance_K_W: float, ambient_K: float, t: np.ndarray,
                 x: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(F [N], the rubber's temperature [K]) at the points of the path x [mm] (straight between
    them; v [mm/s] the velocity the dashpot reads at each point) of the bushing heated by its own
    dissipation and cooled to ``ambient_K``: C dT/dt = D - (T - T_amb)/R, D the heat its elements
    make (the dashpot's c s^2, the Maxwell dashpot's f_M^2/c_M at the piece's middle, the slider's
    level times its slip), each piece at the temperature it starts at (the law of
    :func:`at_temperature`), the cooling over the piece exact for its mean heat."""
    out, temperature = np.empty(t.size), np.empty(t.size)
    f_m = f_j = 0.0
    T = ambient_K
    q = at_temperature(p, T)
    out[0], temperature[0] = q["k"] * x[0] + q["c"] * v[0], T
    tau = capacity_J_K * resistance_K_W
    for i in range(1, t.size):
        q = at_temperature(p, T)
        rate = q["maxwell_k"] / q["maxwell_c"]
        h, dx = t[i] - t[i - 1], x[i] - x[i - 1]
        slope = dx / h
        decay = math.exp(-rate * h)
        f_m_end = f_m * decay + q["maxwell_c"] * slope * (1.0 - decay)
        f_mid = f_m * math.exp(-rate * h / 2) + q["maxwell_c"] * slope * (1.0 - math.exp(-rate * h / 2))
        trial = f_j + q["jenkins_k"] * dx
        f_j_end = min(max(trial, -q["jenkins_f"]), q["jenkins_f"])
        slip = abs(trial - f_j_end) / q["jenkins_k"]          # [mm]
        heat_mJ = q["c"] * slope ** 2 * h + f_mid ** 2 / q["maxwell_c"] * h + q["jenkins_f"] * slip
        power = 1e-3 * heat_mJ / h
        cooling = math.exp(-h / tau)
        T = ambient_K + (T - ambient_K) * cooling + power * resistance_K_W * (1.0 - cooling)
        f_m, f_j = f_m_end, f_j_end
        q = at_temperature(p, T)
        out[i], temperature[i] = q["k"] * x[i] + q["c"] * v[i] + f_m + f_j, T
    return out, temperature
