"""A band brake with backlash, typed here from its laws (numpy and scipy only; nothing of the
project): the truth of data/generate_band_brake.py and of the benchmark that fits it.

    F = k0*x + c*dx/dt + b + C(e)                          the force a rig measures [N]
    C(e) = sgn(e)*G(|e| - gap),  G(a) = 0 (a <= 0), kc*a^2/(2*d) (a < d), kc*(a - d/2)
    |C(e)| <= L(s),  L(s) = f * r^(min(s, S)/S)            r = r_pos or r_neg by the side

k0 and c are the device's rubber path, b the load cell's zero. The band's contact C works on the
engagement e (the drum's displacement less where the band's play is centred): nothing within
the play (±gap), then a stiffness rising linearly from 0 to kc over a depth d. The band slides
on the drum where the contact force would pass its level L: the level grows with the travel s
into the engaged side (the capstan effect: the band wraps as the drum drags it, to r times f
after a travel S, a different r each way) and restarts once the contact unloads into the play.

Units mm, N, s. ``force(p, t, path)`` walks the displacement function ``path`` (t -> (x [mm],
dx/dt [mm/s])) from rest, the play centred at x(t[0]), on ``substeps`` equal pieces between the
samples; at each piece it finds where the contact meets the level with scipy's brentq.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

PARAMETERS = {
    "k0": 20.0,        # N/mm: the rubber path
    "c": 0.4,          # N.s/mm: its damping
    "b": 60.0,         # N: the load cell's zero
    "gap": 0.8,        # mm: half the band's play
    "kc": 900.0,       # N/mm: the contact's stiffness once engaged
    "d": 0.3,          # mm: the depth over which the contact's stiffness rises
    "f": 150.0,        # N: the band's level as a side engages
    "r_pos": 2.5,      # 1: the level's growth the energized way (positive)
    "r_neg": 1.3,      # 1: ... and the other way
    "S": 1.5,          # mm: the travel over which the level grows
}


def contact(p: dict, e: float) -> float:
    """C(e) [N]."""
    a = abs(e) - p["gap"]
    if a <= 0.0:
        return 0.0
    g = p["kc"] * a * a / (2.0 * p["d"]) if a < p["d"] else p["kc"] * (a - p["d"] / 2.0)
    return math.copysign(g, e)


def level(p: dict, s: float, side: float) -> float:
    """L(s) [N] on the side of side's sign."""
    r = p["r_pos"] if side > 0 else p["r_neg"]
    return p["f"] * r ** (min(s, p["S"]) / p["S"])


def band_force(p: dict, x: np.ndarray) -> np.ndarray:
    """The band's force C(e) [N] along the finely sampled displacement x [mm]."""
    gap = p["gap"]
    e, s = 0.0, 0.0
    out = np.zeros(x.size)
    for i in range(1, x.size):
        trial = e + (x[i] - x[i - 1])
        side = math.copysign(1.0, trial)
        if abs(trial) <= gap:
            s = 0.0
        elif abs(e) > gap and math.copysign(1.0, e) == side:
            s += max(side * (trial - e), 0.0)
        else:
            s = abs(trial) - gap
        e = trial
        limit = level(p, s, side)
        if abs(e) > gap and abs(contact(p, e)) > limit:
            e = side * brentq(lambda a: contact(p, a) - limit, gap, gap + 10.0 * (limit / p["kc"] + p["d"] + 1.0),
                              xtol=1e-14, rtol=1e-14)
        out[i] = contact(p, e)
    return out


def force(p: dict, t: np.ndarray, path, substeps: int = 10) -> np.ndarray:
    """The measured force [N] at the times t along path, walked on ``substeps`` pieces a sample."""
    fine = np.concatenate([np.linspace(t[i], t[i + 1], substeps, endpoint=False) for i in range(t.size - 1)]
                          + [t[-1:]])
    x_fine, _ = path(fine)
    band = band_force(p, np.asarray(x_fine, dtype=float))[::substeps]
    x, v = path(t)
    return p["k0"] * x + p["c"] * v + p["b"] + band
