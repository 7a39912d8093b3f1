"""Equations 1-5 of the proposed bushing model and their integrator. No FMI code here.

Units (the paper's): displacements x, y, w in mm, velocities in mm/s, hysteretic forces
z1, z2 and the bushing force F in N, time in s; parameters as in ``bushing_params``.
The state is the tuple ``(y, z1, w, z2)``.

Input convention: within a step of length h starting at displacement x0 the displacement is
``x0 + v*t`` and the velocity is ``v`` (constant). Where a step starts at a displacement other
than the one the state belongs to (the end of the previous step), the difference is applied
first as a displacement jump, the model's exact response to an impulse in dx/dt.

Integrator
----------
The equations are stiff (with the paper's Table 5 the y-z1 mode decays at ~5000 1/s, and
at ~5e5 1/s for c1 = 0.01, while w relaxes over ~50 s) and non-smooth (sgn() switches at
every reversal, |z|^n with n < 1 has an infinite derivative at z = 0). With v constant,
each Bouc-Wen block is an autonomous two-state system in its relative velocity u and its
hysteretic force z (g is the bracket of eqs. 1-2, which depends on u only through sgn u):

    block 1:  u1 = v - dy/dt,  du1/dt = k0*v/c1 - lam1*u1,  lam1 = (k0 + k1 + alpha1*g1)/c1
    block 2:  u2 = v - dw/dt,  du2/dt = -lam2*u2,           lam2 = (k2 + alpha2*g2)/(c0 + c2)
    both:     dz/dt = g(z, sgn u) * u

(differentiate eqs. 3-4 and substitute eqs. 1-2). All stiffness sits in the linear decay of
u, which is propagated exactly for a frozen lam (exponential integrator: stable for any
lam*h). Because z depends on time only through xi = integral of u, z follows the scalar
autonomous ODE dz/dxi = g(z, sgn u), which is advanced with classical RK4 in xi. lam is then
re-evaluated with the mean gain over the substep and the substep repeated once (second order
in the coupling), or, where that changes xi by under 1 %, z extended by one Taylor step. A substep is split where u crosses zero, so each part
stays on one branch of sgn(). Substeps are chosen a priori so that g and lam change by at
most a fraction ``THETA`` over each; there is no fixed time limit, since the linear part is
exact. y is recovered from the invariant c1*u1 = -(k1*(x - y) - k0*y + alpha1*z1), w by
integrating dw/dt = v - u2.
"""
from __future__ import annotations

import math
from typing import Mapping, NamedTuple

THETA = 0.35
"""Largest relative change of the Bouc-Wen gain g (and of lam) allowed within one substep.
Measured against Radau at 1 ms steps (tests/test_model_core.py): the force error stays below
5e-4 of its peak for the paper's tables, c1 = 0.01 and a 30 Hz, 3 mm sine; 0.5 would give 5e-3."""

THETA_JUMP = 0.1
"""The same bound for the RK4 pieces of a large displacement jump: jumps are rare (small ones
take a Heun step), so they can afford the tighter bound; a 2.5 mm jump is then exact to 1e-5."""

HEUN_JUMP_LIMIT = 0.05
"""A displacement jump over which g2 changes by less than this fraction takes one Heun step
(local error ~HEUN_JUMP_LIMIT^2/12 = 2e-4 of the jump's own, O(h^2) small, increment of z2)."""

DEFAULT_MAX_SUBSTEPS = 20000
"""Substeps allowed per call of :func:`advance` before it gives up (guards against hangs)."""


class StepError(ArithmeticError):
    """The step cannot be computed (overflow, non-finite result, too many substeps)."""


class BushingState(NamedTuple):
    y: float   # mm, displacement of the left plate
    z1: float  # N, hysteretic force of block 1
    w: float   # mm, displacement of the right plate
    z2: float  # N, hysteretic force of block 2


def hysteretic_gain(z: float, u: float, A: float, beta: float, gamma: float, n: float) -> float:
    """The bracket of eqs. 1-2: A - (gamma + beta*sgn(u)*sgn(z))*|z|^n  [N/mm]."""
    return A - (gamma + beta * _sign(u) * _sign(z)) * abs(z) ** n


def _sign(value: float) -> float:
    return 1.0 if value > 0.0 else (-1.0 if value < 0.0 else 0.0)


def plate_velocities(state, x: float, v: float, p: Mapping[str, float]) -> tuple[float, float]:
    """dy/dt and dw/dt from eqs. 3 and 4 [mm/s]."""
    y, z1, w, z2 = state
    dy = (p["c1"] * v + p["k1"] * (x - y) - p["k0"] * y + p["alpha1"] * z1) / p["c1"]
    return dy, _right_plate_velocity(w, z2, x, v, p)


def _right_plate_velocity(w, z2, x, v, p):
    """Eq. 4: dw/dt [mm/s]."""
    return (p["c2"] * v + p["k2"] * (x - w) + p["alpha2"] * z2) / (p["c0"] + p["c2"])


def rhs(t: float, state, x0: float, v: float, p: Mapping[str, float]) -> list[float]:
    """Eqs. 1-4 for the input x = x0 + v*t: returns [dy/dt, dz1/dt, dw/dt, dz2/dt].

    Written for ``scipy.integrate.solve_ivp`` references; the integrator below solves the
    same equations in the block form derived in the module docstring.
    """
    y, z1, w, z2 = state
    dy, dw = plate_velocities(state, x0 + v * t, v, p)
    dz1 = (v - dy) * hysteretic_gain(z1, v - dy, p["A1"], p["beta1"], p["gamma1"], p["n1"])
    dz2 = (v - dw) * hysteretic_gain(z2, v - dw, p["A2"], p["beta2"], p["gamma2"], p["n2"])
    return [dy, dz1, dw, dz2]


def force(state, x: float, v: float, p: Mapping[str, float]) -> float:
    """Eq. 5: F = k0*y + c0*dw/dt [N], positive for positive x (the force the bushing
    exerts on its base, i.e. the force needed to hold the upper plate at x)."""
    y, _, w, z2 = state
    return p["k0"] * y + p["c0"] * _right_plate_velocity(w, z2, x, v, p)


def initial_state(p: Mapping[str, float], x0: float = 0.0) -> BushingState:
    """Relaxed static equilibrium at displacement x0 [mm] with virgin hysteresis.

    z1 = z2 = 0, and y, w at rest for v = 0: k1*(x0 - y) = k0*y and w = x0. The force is then
    F0 = k0*k1/(k0 + k1) * x0, the static stiffness times x0, and it stays there while x0 is
    held. (With k0 = k1 = 0, y does not affect anything and is set to x0.)
    """
    stiffness = p["k0"] + p["k1"]
    y0 = p["k1"] * x0 / stiffness if stiffness > 0 else x0
    return BushingState(y0, 0.0, x0, 0.0)


class _Block(NamedTuple):
    """Constants of one Bouc-Wen block in the form du/dt = a - lam*u, lam = (K + alpha*g)/c."""
    K: float
    alpha: float
    c: float
    A: float
    beta: float
    gamma: float
    n: float


class CompiledModel(NamedTuple):
    """Parameters rearranged once for the integrator's hot loop."""
    k0: float
    k1: float
    k2: float
    c0: float
    c1: float
    C: float       # c0 + c2
    K1: float      # k0 + k1
    alpha1: float
    alpha2: float
    block1: _Block
    block2: _Block


def compile_model(p: Mapping[str, float]) -> CompiledModel:
    C = p["c0"] + p["c2"]
    K1 = p["k0"] + p["k1"]
    return CompiledModel(
        k0=p["k0"], k1=p["k1"], k2=p["k2"], c0=p["c0"], c1=p["c1"], C=C, K1=K1,
        alpha1=p["alpha1"], alpha2=p["alpha2"],
        block1=_Block(K1, p["alpha1"], p["c1"], p["A1"], p["beta1"], p["gamma1"], p["n1"]),
        block2=_Block(p["k2"], p["alpha2"], C, p["A2"], p["beta2"], p["gamma2"], p["n2"]),
    )


def _decay_factors(x: float) -> tuple[float, float, float]:
    """E = exp(-x), phi1 = (1 - E)/x, phi2 = (x - 1 + E)/x^2, accurate also near x = 0."""
    if -1e-3 < x < 1e-3:
        return 1.0 - x + 0.5 * x * x, 1.0 - 0.5 * x + x * x / 6.0, 0.5 - x / 6.0 + x * x / 24.0
    E = math.exp(-x)
    phi1 = (1.0 - E) / x
    return E, phi1, (1.0 - phi1) / x


def _rk4_in_xi(z: float, dxi: float, A: float, cpos: float, cneg: float, n: float) -> float:
    """Classical RK4 for dz/dxi = A - c*|z|^n with c = cpos for z > 0 and cneg for z < 0."""
    k1 = A - (cpos * z ** n if z > 0.0 else cneg * (-z) ** n)
    zt = z + 0.5 * dxi * k1
    k2 = A - (cpos * zt ** n if zt > 0.0 else cneg * (-zt) ** n)
    zt = z + 0.5 * dxi * k2
    k3 = A - (cpos * zt ** n if zt > 0.0 else cneg * (-zt) ** n)
    zt = z + dxi * k3
    k4 = A - (cpos * zt ** n if zt > 0.0 else cneg * (-zt) ** n)
    return z + dxi * (k1 + 2.0 * (k2 + k3) + k4) / 6.0


def _segment(u0, z0, h, a, blk, sigma):
    """Advance (u, z) of one block by h on the branch sgn(u) = sigma; returns (u, z, xi)."""
    K, alpha, c, A, beta, gamma, n = blk
    cpos = gamma + beta * sigma
    cneg = gamma - beta * sigma
    g0 = A - (cpos * z0 ** n if z0 > 0.0 else cneg * (-z0) ** n)
    lam = (K + alpha * g0) / c
    E, phi1, phi2 = _decay_factors(lam * h)
    xi = h * (u0 * phi1 + a * h * phi2)
    if xi == 0.0:
        return u0 * E + a * h * phi1, z0, 0.0
    z1 = _rk4_in_xi(z0, xi, A, cpos, cneg, n)
    # lam with the mean gain over the substep; xi changes by O(h^2), so one repeat suffices.
    lam = (K + alpha * (z1 - z0) / xi) / c
    E, phi1, phi2 = _decay_factors(lam * h)
    corrected = h * (u0 * phi1 + a * h * phi2)
    if abs(corrected - xi) <= 0.01 * abs(xi):
        # A small correction (always so when lam*h << 1): one Taylor step from the end of the
        # RK4 path; its error, (1/2)*THETA*(dxi/xi)^2 of the substep's dz, is below 2e-5.
        z1 = z1 + (A - (cpos * z1 ** n if z1 > 0.0 else cneg * (-z1) ** n)) * (corrected - xi)
    else:
        z1 = _rk4_in_xi(z0, corrected, A, cpos, cneg, n)
    return u0 * E + a * h * phi1, z1, corrected


def _block_step(u0, z0, h, a, blk):
    """Advance one block by h, splitting the substep where u changes sign."""
    if u0 == 0.0:
        if a == 0.0:
            return 0.0, z0, 0.0
        return _segment(u0, z0, h, a, blk, 1.0 if a > 0.0 else -1.0)
    sigma = 1.0 if u0 > 0.0 else -1.0
    if a * u0 < 0.0:
        K, alpha, c, A, beta, gamma, n = blk
        cz = (gamma + beta * sigma) if z0 > 0.0 else (gamma - beta * sigma)
        lam = (K + alpha * (A - cz * abs(z0) ** n)) / c
        if lam > 0.0:
            u_target = a / lam
            t_cross = -math.log(u_target / (u_target - u0)) / lam
            if t_cross < h:
                _, z_mid, xi_a = _segment(u0, z0, t_cross, a, blk, sigma)
                u1, z1, xi_b = _segment(0.0, z_mid, h - t_cross, a, blk, -sigma)
                return u1, z1, xi_a + xi_b
    return _segment(u0, z0, h, a, blk, sigma)


def _gain_variation(z0, g0, z_pred, A, cpos, cneg, n):
    """Gain at z_pred and how much g varies on the way from z0; returns (g_pred, dg, crosses).

    g has a cusp at z = 0 (g = A there): where z changes sign, the variation is measured
    through it, which the secant from g0 to g_pred can miss entirely.
    """
    g_pred = A - (cpos * z_pred ** n if z_pred > 0.0 else cneg * (-z_pred) ** n)
    crosses_zero = (z_pred > 0.0) != (z0 > 0.0)
    dg = abs(g0 - A) + abs(g_pred - A) if crosses_zero else abs(g_pred - g0)
    return g_pred, dg, crosses_zero


def _substeps_needed(u0, z0, T, a, blk):
    """Substeps so that g and lam change by at most THETA (relative) over each, predicted
    from the start of the remaining interval T."""
    K, alpha, c, A, beta, gamma, n = blk
    rate = u0
    if a * u0 <= 0.0 and a != 0.0:
        # u heads towards a/lam, possibly across zero: bound the travel by the larger speed.
        sigma = 1.0 if a > 0.0 else -1.0
    else:
        sigma = 1.0 if u0 >= 0.0 else -1.0
    cpos = gamma + beta * sigma
    cneg = gamma - beta * sigma
    g0 = A - (cpos * z0 ** n if z0 > 0.0 else cneg * (-z0) ** n)
    lam_c = K + alpha * g0
    if a != 0.0 and lam_c > 0.0:
        target = a * c / lam_c
        if abs(target) > abs(rate):
            rate = target
    _, dg, _ = _gain_variation(z0, g0, z0 + g0 * rate * T, A, cpos, cneg, n)
    if dg == 0.0:
        return 1
    rel = dg / abs(g0) if g0 != 0.0 else math.inf
    rel_lam = abs(alpha) * dg / (abs(lam_c) + c / T)
    worst = rel if rel > rel_lam else rel_lam
    if worst <= THETA:
        return 1
    if worst == math.inf or worst > 1e9:
        return 1_000_000_000
    return int(math.ceil(worst / THETA))


def apply_displacement_jump(model: CompiledModel, state, jump_mm: float) -> BushingState:
    """Exact response of eqs. 1-4 to an instantaneous displacement jump [mm] (an impulse in
    dx/dt): the dashpot c1 carries y along (y += jump, z1 unchanged); the dashpots c0, c2
    split it (w += c2/(c0 + c2)*jump) and block 2 sees the relative displacement
    xi = c0/(c0 + c2)*jump, along which z2 follows dz2/dxi = g2(z2, sgn xi).

    A master that sets x_{k+1} different from x_k + v_k*h (e.g. the instantaneous velocity
    instead of the mean over the step) makes such a jump at every step; treating it as a
    displacement of the whole model, not of the springs alone, keeps ẋ = v consistent.
    """
    y, z1, w, z2 = state
    if jump_mm == 0.0:
        return BushingState(y, z1, w, z2)
    y, z1, w, z2, status = _jump_kernel(model, y, z1, w, z2, jump_mm)
    if status != OK:
        raise StepError(f"a displacement jump of {jump_mm:g} mm needs too many substeps; "
                        "check the units of the inputs (the FMU takes metres)")
    return BushingState(y, z1, w, z2)


def advance(model: CompiledModel, state, state_x: float, x: float, v: float, h: float,
            max_substeps: int = DEFAULT_MAX_SUBSTEPS) -> tuple[BushingState, int]:
    """Integrate one step: displacement x + v*t [mm] for 0 <= t <= h [s], h > 0.

    ``state`` is valid at displacement ``state_x`` [mm] (the end of the previous step, or the
    initial displacement). If the step starts elsewhere (x != state_x) the difference is
    applied first as a displacement jump (:func:`apply_displacement_jump`). The new state is
    valid at x + v*h. Returns the new state and the number of substeps used. Raises
    StepError if the result would overflow or is not finite, or if more than
    ``max_substeps`` are needed; the state passed in is never modified (immutable tuple).
    """
    y, z1, w, z2 = state
    try:
        status = OK
        if x != state_x:
            y, z1, w, z2, status = _jump_kernel(model, y, z1, w, z2, x - state_x)
        if status == OK:
            y, z1, w, z2, used, status = _integrate(model, y, z1, w, z2, x, v, h, max_substeps)
    except (OverflowError, ZeroDivisionError, ValueError) as exc:
        raise StepError(f"the step overflowed ({exc}) at x = {x:g} mm, v = {v:g} mm/s, "
                        f"state = {tuple(state)}; check the units of the inputs "
                        "(the FMU takes metres and m/s) and the parameters") from None
    if status == TOO_MANY_SUBSTEPS:
        raise StepError(f"the step of {h:g} s would need more than {max_substeps} substeps "
                        f"(x = {x:g} mm, v = {v:g} mm/s); check the units of the inputs "
                        "(the FMU takes metres and m/s) or shorten the communication step")
    if status == NOT_FINITE:
        raise StepError(f"the step gave a non-finite state {(y, z1, w, z2)} at x = {x:g} mm, "
                        f"v = {v:g} mm/s; check the units of the inputs (the FMU takes metres "
                        "and m/s) and the parameters")
    return BushingState(y, z1, w, z2), used


# ---------------------------------------------------------------------------- kernels
# Plain float arithmetic, no exceptions raised, errors as status codes: the identification
# compiles these same functions with numba (identification/compiled_core.py).
OK, TOO_MANY_SUBSTEPS, NOT_FINITE = 0, 1, 2


def _jump_kernel(model, y, z1, w, z2, jump_mm):
    """apply_displacement_jump for a non-zero jump; returns (y, z1, w, z2, status)."""
    k0, k1, k2, c0, c1, C, K1, alpha1, alpha2, blk1, blk2 = model
    K, alpha, c, A, beta, gamma, n = blk2
    xi_total = c0 / C * jump_mm
    sigma = 1.0 if xi_total > 0.0 else -1.0
    cpos = gamma + beta * sigma
    cneg = gamma - beta * sigma
    remaining = xi_total
    for _ in range(DEFAULT_MAX_SUBSTEPS):
        # The a-priori rule of the time steps: bound the change of g2 per piece.
        g0 = A - (cpos * z2 ** n if z2 > 0.0 else cneg * (-z2) ** n)
        g_pred, dg, crosses_zero = _gain_variation(z2, g0, z2 + g0 * remaining, A, cpos, cneg, n)
        if not crosses_zero and dg <= HEUN_JUMP_LIMIT * abs(g0):
            # The usual case, a jump of O(h^2) from a master that passes the instantaneous
            # velocity: Heun's step from the two gains just computed.
            z2 = z2 + 0.5 * remaining * (g0 + g_pred)
            break
        allowed = THETA_JUMP * abs(g0)
        pieces = 1 if dg <= allowed else min(int(math.ceil(dg / (allowed + 1e-300))), 1000)
        piece = remaining / pieces
        z2 = _rk4_in_xi(z2, piece, A, cpos, cneg, n)
        remaining -= piece
        if pieces == 1:
            break
    else:
        return y, z1, w, z2, TOO_MANY_SUBSTEPS
    return y + jump_mm, z1, w + (C - c0) / C * jump_mm, z2, OK


def _integrate(model, y, z1, w, z2, x, v, h, max_substeps):
    """advance without the jump; returns (y, z1, w, z2, substeps used, status)."""
    k0, k1, k2, c0, c1, C, K1, alpha1, alpha2, blk1, blk2 = model
    a1 = k0 * v / c1
    elapsed = 0.0
    used = 0
    while True:
        remaining = h - elapsed
        x_now = x + v * elapsed
        u1 = -(k1 * (x_now - y) - k0 * y + alpha1 * z1) / c1
        u2 = (c0 * v - k2 * (x_now - w) - alpha2 * z2) / C
        count = max(_substeps_needed(u1, z1, remaining, a1, blk1),
                    _substeps_needed(u2, z2, remaining, 0.0, blk2))
        if used + 1 > max_substeps or count > max_substeps:
            return y, z1, w, z2, used, TOO_MANY_SUBSTEPS
        sub = remaining if count == 1 else remaining / count
        u1, z1, xi1 = _block_step(u1, z1, sub, a1, blk1)
        u2, z2, xi2 = _block_step(u2, z2, sub, 0.0, blk2)
        elapsed = h if count == 1 else elapsed + sub
        x_now = x + v * elapsed
        # The invariant keeps y consistent with u1; the stiff k/c1 coupling would amplify
        # any quadrature error of y into u1.
        y = (k1 * x_now + alpha1 * z1 + c1 * u1) / K1 if K1 > 0.0 else y + v * sub - xi1
        w = w + v * sub - xi2
        used += 1
        if count == 1:
            break
    if not (math.isfinite(y) and math.isfinite(z1) and math.isfinite(w) and math.isfinite(z2)):
        return y, z1, w, z2, used, NOT_FINITE
    return y, z1, w, z2, used, OK
