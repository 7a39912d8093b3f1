"""The hydraulic mount's complex stiffness in its linear case (no decoupler, gap = 0; no turbulent
damping, ct = 0), typed from the equations (numpy only; nothing of ``fmu_src`` or
``identification``).

With gap = 0 the decoupler's travel u is 0, so the track is driven by dp = P = kb*(x - y) - kc*y,
and with ct = 0 the equations are linear:

    F      = k0*x + c0*dx/dt + f1 + kb*(x - y)
    df1/dt = k1*dx/dt - (k1/c1)*f1
    mf*d2y/dt2 = kb*x - (kb + kc)*y - cf*dy/dt

In the periodic steady state at x = Re(X*exp(i*omega*t)) every quantity is Re(Q*exp(i*omega*t)),
d/dt is a factor i*omega, and K* = F/X:

- the Maxwell element: (i*omega + k1/c1)*F1 = i*omega*k1*X, so F1/X = k1*i*omega*c1/(k1 + i*omega*c1);
- the fluid column: (kb + kc - mf*omega^2 + i*omega*cf)*Y = kb*X, so with D = kb + kc - mf*omega^2
  + i*omega*cf the fluid path gives kb*(X - Y)/X = kb*(D - kb)/D
  = kb*(kc - mf*omega^2 + i*omega*cf)/D;
- the rubber's spring and dashpot: k0 + i*omega*c0.

    K*(omega) = k0 + i*omega*c0 + k1*i*omega*c1/(k1 + i*omega*c1)
                + kb*(kc - mf*omega^2 + i*omega*cf)/(kb + kc - mf*omega^2 + i*omega*cf)

which is the form fmu_src/models/hydraulic_model.py's docstring states. Limits: at omega -> 0 it is
k0 + kb*kc/(kb + kc) (the static stiffness, the bulge in series with the bellows), at
omega -> oo k0 + k1 + kb + i*omega*c0 (the fluid cannot move, the Maxwell spring is rigid).
tests/fmu_src/model/test_hydraulic_model.py checks this algebra against a direct solve of the 3x3 system.

Units: parameters in N-mm-s (k in N/mm, c in N.s/mm, mf in N.s^2/mm), K* in N/mm.
"""
from __future__ import annotations

import numpy as np


def complex_stiffness(p, frequency_hz):
    """K* [N/mm] (complex, the shape of ``frequency_hz`` [Hz]) of the linear hydraulic mount with
    the parameters ``p`` (a mapping with k0, c0, k1, c1, kb, kc, mf, cf; a gap or ct in it is not
    read: this is the mount with gap = 0 and ct = 0)."""
    omega = 2.0 * np.pi * np.asarray(frequency_hz, dtype=float)
    k0, c0, k1, c1 = p["k0"], p["c0"], p["k1"], p["c1"]
    kb, kc, mf, cf = p["kb"], p["kc"], p["mf"], p["cf"]
    maxwell = k1 * 1j * omega * c1 / (k1 + 1j * omega * c1)
    track = kc - mf * omega ** 2 + 1j * omega * cf
    return k0 + 1j * omega * c0 + maxwell + kb * track / (kb + track)


def free_decoupler_complex_stiffness(p, frequency_hz):
    """K* [N/mm] of the free-plate mount (fmu_src/models/hydraulic_free_decoupler_model.py) in its
    linear case: no free travel (gap = 0), no turbulent damping (ct = 0), no cubic spring (k3 = 0).

    With gap = 0 the plate is a membrane held by its centring spring and its cage together:
    P - (kb + kc)*u = (kd + kcage)*u, so u = P/Kt with Kt = kb + kc + kd + kcage, and the track is
    driven by dp = a*P with a = (kd + kcage)/Kt. With P = kb*X - (kb + kc)*Y:

    - the fluid column: (a*(kb + kc) - mf*omega^2 + i*omega*cf)*Y = a*kb*X;
    - the fluid path: kb*(X - Y - U) = kb*((1 - kb/Kt)*X - a*Y) (as U = (kb*X - (kb + kc)*Y)/Kt);
    - the rubber: k0 + i*omega*c0 and the Maxwell element, as in :func:`complex_stiffness`.

    As kcage grows (a -> 1, kb/Kt -> 0) this is :func:`complex_stiffness`."""
    omega = 2.0 * np.pi * np.asarray(frequency_hz, dtype=float)
    k0, c0, k1, c1 = p["k0"], p["c0"], p["k1"], p["c1"]
    kb, kc, mf, cf, kd, kcage = p["kb"], p["kc"], p["mf"], p["cf"], p["kd"], p["kcage"]
    total = kb + kc + kd + kcage
    a = (kd + kcage) / total
    maxwell = k1 * 1j * omega * c1 / (k1 + 1j * omega * c1)
    fluid = a * kb / (a * (kb + kc) - mf * omega ** 2 + 1j * omega * cf)
    return k0 + 1j * omega * c0 + maxwell + kb * ((1.0 - kb / total) - a * fluid)
