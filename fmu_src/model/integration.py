"""Integration machinery shared by the bushing models: no model's equations live here.

A model (``proposed_model``, ``spencer_model``, ``single_bouc_wen_model``, ``kelvin_voigt_model``)
writes its equations as five kernels and uses the pieces below to step them:

- a Bouc-Wen block in the form the models share. Where a Bouc-Wen element (eq. 1 or 2 of the
  paper) sits in series with a dashpot c and a spring K, and the displacement's velocity v is
  constant over a step, the block is an autonomous two-state system in the element's relative
  velocity u and its hysteretic force z:

      du/dt = a - lam*u,   lam = (K + alpha*g)/c,   dz/dt = g(z, sgn u)*u,
      g = A - (gamma + beta*sgn(u)*sgn(z))*|z|^n     (the bracket of eqs. 1-2, N/mm)

  (``a`` is the drive of the linear part, constant over the step). All stiffness sits in the
  linear decay of u, which is propagated exactly for a frozen lam (an exponential integrator:
  stable for any lam*h). Because z depends on time only through xi = integral of u, z follows
  the scalar autonomous ODE dz/dxi = g(z, sgn u), advanced with classical RK4 in xi. lam is
  then re-evaluated with the mean gain over the substep and the substep repeated once (second
  order in the coupling), or, where that changes xi by under 1 %, z extended by one Taylor
  step. A substep is split where u crosses zero, so each part stays on one branch of sgn().
  ``block_step`` advances a block; ``substeps_needed`` chooses substeps a priori so that g and
  lam change by at most ``THETA`` over each (there is no fixed time limit: the linear part is
  exact).
- a walk of z along a given relative displacement xi (``walk_along_xi``): a displacement jump
  (an impulse in dx/dt) moves z that way, and so does a step of a Bouc-Wen element driven
  directly by the displacement.
- the driver ``advance``: a model's jump and integration kernels for one communication step,
  their status codes turned into ``StepError`` with a message naming the inputs (the FMU's
  error policy lives in ``pythonfmu_slave``; this is where the step's failures are worded).

Kernels are plain float arithmetic that raise nothing and report errors as status codes (OK,
TOO_MANY_SUBSTEPS, NOT_FINITE), so that the identification compiles these same functions with
numba (``identification/forward/population.py``) and the native FMU translates them into C.

Units (the paper's): displacements in mm, velocities in mm/s, hysteretic forces in N, time in s.
"""
from __future__ import annotations

import math

THETA = 0.35
"""Largest relative change of the Bouc-Wen gain g (and of lam) allowed within one substep.
Measured against Radau at 1 ms steps (tests/fmu_src/model/test_model_core.py): the force error stays below
5e-4 of its peak for the paper's tables, c1 = 0.01 and a 30 Hz, 3 mm sine; 0.5 would give 5e-3."""

THETA_JUMP = 0.1
"""The same bound for the RK4 pieces of a walk along xi: jumps are rare (small ones take a Heun
step), so they can afford the tighter bound; a 2.5 mm jump is then exact to 1e-5."""

HEUN_JUMP_LIMIT = 0.05
"""A walk over which g changes by less than this fraction takes one Heun step (local error
~HEUN_JUMP_LIMIT^2/12 = 2e-4 of the walk's own, O(h^2) small, increment of z)."""

DEFAULT_MAX_SUBSTEPS = 20000
"""Substeps allowed per call of :func:`advance` before it gives up (guards against hangs)."""

OK, TOO_MANY_SUBSTEPS, NOT_FINITE = 0, 1, 2
"""Status codes of the kernels."""

JUMP_RELATIVE, JUMP_FLOOR, JUMP_WINDOW, JUMP_COUNT = 0.1, 1e-6, 50, 30
"""Jumping inputs, which the FMUs warn about (logging only; the force is the same). An FMU takes
x + v*(t - t_k) over a step; where the x set at a step's start differs from where the state is
(x_(k-1) + v_(k-1)*h), it takes the difference as a displacement jump, which the dashpots carry.
A step "jumps" where |x - x_state| > JUMP_RELATIVE*|v|*h + JUMP_FLOOR (kernel units: mm or rad);
more than JUMP_COUNT jumping steps among an axis's last JUMP_WINDOW (<= 62: the history is the
bits of one integer) is a v that is not the derivative of the sampled x (a measured velocity fed
beside a measured displacement). A smooth x(t_k) with v = dx/dt(t_k) jumps by x''*h^2/2 only:
near reversals, at most 9 of 50 steps of a 10 Hz sine at 1 ms (24 at 30 Hz), none with v the
secant. The test is :func:`displacement_jumped`, one kernel that the pythonfmu slave calls, the
compiled batched step (``numba_binding._step_axes``) calls compiled, and the native C calls
translated (``BW_DISPLACEMENT_JUMPED``); the window's count (BW_JUMP_WINDOW, BW_JUMP_COUNT in C)
is each host's bookkeeping."""


def displacement_jumped(x, state_x, v, h):
    """Whether a step that sets the displacement x [mm or rad] where the state is at state_x starts
    with a jump: |x - state_x| > JUMP_RELATIVE*|v|*h + JUMP_FLOOR, v [mm/s or rad/s] the step's
    velocity and h [s] its size (the constants' docstring says why)."""
    return abs(x - state_x) > JUMP_RELATIVE * (abs(v) * h) + JUMP_FLOOR


class StepError(ArithmeticError):
    """The step cannot be computed (overflow, non-finite result, too many substeps)."""


def block_gain(z, u, blk):
    """The bracket of eqs. 1-2 of a block ``blk`` (module docstring) at hysteretic force z and
    relative velocity u: A - (gamma + beta*sgn(u)*sgn(z))*|z|^n  [N/mm]."""
    K, alpha, c, A, beta, gamma, n = blk
    sigma = 1.0 if u > 0.0 else (-1.0 if u < 0.0 else 0.0)
    if z > 0.0:
        return A - (gamma + beta * sigma) * z ** n
    if z < 0.0:
        return A - (gamma - beta * sigma) * (-z) ** n
    return A


def decay_factors(x: float) -> tuple[float, float, float]:
    """E = exp(-x), phi1 = (1 - E)/x, phi2 = (x - 1 + E)/x^2, to rounding also near x = 0: there
    (|x| < 1e-3) their Taylor series to x^4, whose remainder is below 1e-17; a shorter series
    would change E by 1.7e-10 where the two forms meet, which a Maxwell element of rate 1/h
    accumulates over a run."""
    if -1e-3 < x < 1e-3:
        return (1.0 - x * (1.0 - x * (0.5 - x * (1.0 / 6.0 - x / 24.0))),
                1.0 - x * (0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0))),
                0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x * (1.0 / 120.0 - x / 720.0))))
    E = math.exp(-x)
    phi1 = (1.0 - E) / x
    return E, phi1, (1.0 - phi1) / x


def rk4_in_xi(z: float, dxi: float, A: float, cpos: float, cneg: float, n: float, k1: float) -> float:
    """Classical RK4 for dz/dxi = A - c*|z|^n with c = cpos for z > 0 and cneg for z < 0; ``k1``
    is the slope at z, which every caller has at hand (a power fewer per step)."""
    zt = z + 0.5 * dxi * k1
    k2 = A - (cpos * zt ** n if zt > 0.0 else cneg * (-zt) ** n)
    zt = z + 0.5 * dxi * k2
    k3 = A - (cpos * zt ** n if zt > 0.0 else cneg * (-zt) ** n)
    zt = z + dxi * k3
    k4 = A - (cpos * zt ** n if zt > 0.0 else cneg * (-zt) ** n)
    return z + dxi * (k1 + 2.0 * (k2 + k3) + k4) / 6.0


def block_power(z, blk):
    """|z|^n of a block: its callers share it (the power is most of a step's cost)."""
    return abs(z) ** blk[6]


def block_segment(u0, z0, zn, h, a, blk, sigma):
    """Advance (u, z) of a block by h on the branch sgn(u) = sigma; returns (u, z, xi).

    ``blk`` = (K, alpha, c, A, beta, gamma, n): the block's constants (module docstring); ``zn``
    = |z0|^n (``block_power``)."""
    K, alpha, c, A, beta, gamma, n = blk
    cpos = gamma + beta * sigma
    cneg = gamma - beta * sigma
    g0 = A - (cpos * zn if z0 > 0.0 else cneg * zn)
    lam = (K + alpha * g0) / c
    E, phi1, phi2 = decay_factors(lam * h)
    xi = h * (u0 * phi1 + a * h * phi2)
    if xi == 0.0:
        return u0 * E + a * h * phi1, z0, 0.0
    z1 = rk4_in_xi(z0, xi, A, cpos, cneg, n, g0)
    # lam with the mean gain over the substep; xi changes by O(h^2), so one repeat suffices.
    lam = (K + alpha * (z1 - z0) / xi) / c
    E, phi1, phi2 = decay_factors(lam * h)
    corrected = h * (u0 * phi1 + a * h * phi2)
    if abs(corrected - xi) <= 0.01 * abs(xi):
        # A small correction (always so when lam*h << 1): one Taylor step from the end of the
        # RK4 path; its error, (1/2)*THETA*(dxi/xi)^2 of the substep's dz, is below 2e-5.
        z1 = z1 + (A - (cpos * z1 ** n if z1 > 0.0 else cneg * (-z1) ** n)) * (corrected - xi)
    else:
        z1 = rk4_in_xi(z0, corrected, A, cpos, cneg, n, g0)
    return u0 * E + a * h * phi1, z1, corrected


def block_step(u0, z0, zn, h, a, blk):
    """Advance a block by h, splitting the substep where u changes sign; returns (u, z, xi).
    ``zn`` = |z0|^n (``block_power``)."""
    if u0 == 0.0:
        if a == 0.0:
            return 0.0, z0, 0.0
        return block_segment(u0, z0, zn, h, a, blk, 1.0 if a > 0.0 else -1.0)
    sigma = 1.0 if u0 > 0.0 else -1.0
    if a * u0 < 0.0:
        K, alpha, c, A, beta, gamma, n = blk
        cz = (gamma + beta * sigma) if z0 > 0.0 else (gamma - beta * sigma)
        lam = (K + alpha * (A - cz * zn)) / c
        if lam > 0.0:
            u_target = a / lam
            t_cross = -math.log(u_target / (u_target - u0)) / lam
            if t_cross < h:
                _, z_mid, xi_a = block_segment(u0, z0, zn, t_cross, a, blk, sigma)
                u1, z1, xi_b = block_segment(0.0, z_mid, block_power(z_mid, blk), h - t_cross, a, blk, -sigma)
                return u1, z1, xi_a + xi_b
    return block_segment(u0, z0, zn, h, a, blk, sigma)


def gain_variation(z0, g0, z_pred, A, cpos, cneg, n):
    """Gain at z_pred and how much g varies on the way from z0; returns (g_pred, dg, crosses).

    g has a cusp at z = 0 (g = A there): where z changes sign, the variation is measured
    through it, which the secant from g0 to g_pred can miss entirely.
    """
    g_pred = A - (cpos * z_pred ** n if z_pred > 0.0 else cneg * (-z_pred) ** n)
    crosses_zero = (z_pred > 0.0) != (z0 > 0.0)
    dg = abs(g0 - A) + abs(g_pred - A) if crosses_zero else abs(g_pred - g0)
    return g_pred, dg, crosses_zero


def substeps_needed(u0, z0, zn, T, a, blk):
    """Substeps so that g and lam of a block change by at most THETA (relative) over each,
    predicted from the start of the remaining interval T; ``zn`` = |z0|^n (``block_power``)."""
    K, alpha, c, A, beta, gamma, n = blk
    rate = u0
    if a * u0 <= 0.0 and a != 0.0:
        # u heads towards a/lam, possibly across zero: bound the travel by the larger speed.
        sigma = 1.0 if a > 0.0 else -1.0
    else:
        sigma = 1.0 if u0 >= 0.0 else -1.0
    cpos = gamma + beta * sigma
    cneg = gamma - beta * sigma
    g0 = A - (cpos * zn if z0 > 0.0 else cneg * zn)
    lam_c = K + alpha * g0
    if a != 0.0 and lam_c > 0.0:
        target = a * c / lam_c
        if abs(target) > abs(rate):
            rate = target
    _, dg, _ = gain_variation(z0, g0, z0 + g0 * rate * T, A, cpos, cneg, n)
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


def walk_along_xi(z, xi_total, A, beta, gamma, n, heun_limit, theta, max_pieces):
    """z after the relative displacement ``xi_total`` [mm] of a Bouc-Wen element (dz/dxi =
    g(z, sgn xi), the branch fixed by the sign of xi); returns (z, status).

    Pieces are chosen so that g changes by at most ``theta`` over each (RK4 on each); a walk
    over which g changes by less than ``heun_limit`` takes one Heun step instead. At most
    ``max_pieces`` solves (TOO_MANY_SUBSTEPS beyond)."""
    sigma = 1.0 if xi_total > 0.0 else -1.0
    cpos = gamma + beta * sigma
    cneg = gamma - beta * sigma
    remaining = xi_total
    for _ in range(max_pieces):
        # The a-priori rule of the time steps: bound the change of g per piece.
        g0 = A - (cpos * z ** n if z > 0.0 else cneg * (-z) ** n)
        g_pred, dg, crosses_zero = gain_variation(z, g0, z + g0 * remaining, A, cpos, cneg, n)
        if not crosses_zero and dg <= heun_limit * abs(g0):
            # The usual case of a jump, O(h^2) from a master that passes the instantaneous
            # velocity: Heun's step from the two gains just computed.
            z = z + 0.5 * remaining * (g0 + g_pred)
            break
        allowed = theta * abs(g0)
        pieces = 1 if dg <= allowed else min(int(math.ceil(dg / (allowed + 1e-300))), 1000)
        piece = remaining / pieces
        z = rk4_in_xi(z, piece, A, cpos, cneg, n, g0)
        remaining -= piece
        if pieces == 1:
            break
    else:
        return z, TOO_MANY_SUBSTEPS
    return z, OK


# ---------------------------------------------------------------------------- coupled (vector) Bouc-Wen blocks
# A Bouc-Wen element acting on a displacement vector (the plane, or 3-space; the kernels take
# 3-vectors, a plane path has a zero third component) has the isotropic evolution
#
#     dz/dt = A*u - |z|^(n-2)*(gamma*(z.u) + beta*|z.u|)*z
#
# which is eq. 1 along any line (z parallel to u). Its linearisation in u is
# M = A*I - (gamma + beta*sgn(z.u))*|z|^(n-2)*z z^T: the scalar bracket g = A - (...)*|z|^n along z,
# A across it. A step works in the frame of z: the component along its direction e (signed s) is
# the scalar block of the section above, whose every decision (branch, split where its velocity
# changes sign, substeps) it reuses, so a path along a line steps as the one-axis model does; the
# part across e is linear (rate (K + alpha*A)/c for a block, exact exponentials) and feeds z across
# at A*u, while the nonlinear term shrinks (or, unloading, grows) that part at the rate
# psi = (gamma + beta*sgn)*|z|^(n-2)*(z.u), whose integral over the step the parallel solve gives:
# integral(psi*s dt) = A*xi_parallel - (s1 - s0). The frame is that of the mean of z and its linear
# prediction at the step's end (the midpoint rule: second order in the frame's turn). Substeps
# also bound that turn, weighted by the nonlinear share of the gain (THETA_ROTATION). Measured against scipy's Radau on circles, ellipses and random plane paths:
# tests/fmu_src/model/test_coupled_models.py.

THETA_ROTATION = 0.1
"""Largest turn of z's direction [rad] per substep, weighted by the nonlinear share
|A - g|/|A| of the gain (the turn matters only through the nonlinear term)."""


def vector_dot(a, b):
    """a.b of two 3-vectors."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def vector_axpy(s, a, b):
    """s*a + b (3-vectors)."""
    return (s * a[0] + b[0], s * a[1] + b[1], s * a[2] + b[2])


def vector_scale(s, a):
    """s*a (a 3-vector)."""
    return (s * a[0], s * a[1], s * a[2])


def vector_norm(a):
    """|a| of a 3-vector."""
    return math.sqrt(vector_dot(a, a))


def vector_direction(a, fallback):
    """a/|a|, or ``fallback`` where a = 0."""
    r = vector_norm(a)
    if r > 0.0:
        return (a[0] / r, a[1] / r, a[2] / r)
    return fallback


def block_frame(z, u, a):
    """The frame's direction of a coupled block: along z; where z = 0, along its relative velocity
    u; where that is 0 too, along the drive a; else x."""
    return vector_direction(z, vector_direction(u, vector_direction(a, (1.0, 0.0, 0.0))))


def vector_gain(z, u, A, beta, gamma, n):
    """The coupled block's rate dz/dt = A*u - |z|^(n-2)*(gamma*(z.u) + beta*|z.u|)*z [N/s] at
    hysteretic force z [N] and relative velocity u [mm/s] (3-vectors); finite at z = 0 for n > 0."""
    zu = vector_dot(z, u)
    r2 = vector_dot(z, z)
    if r2 > 0.0:
        f = r2 ** (0.5 * n - 1.0) * (gamma * zu + beta * abs(zu))
        return (A * u[0] - f * z[0], A * u[1] - f * z[1], A * u[2] - f * z[2])
    return (A * u[0], A * u[1], A * u[2])


def across_decay(s0, s1, xi_parallel, A):
    """The integral of psi over a step, from its parallel solve: (A*xi - (s1 - s0))/mean(s); 0 where s
    passes through 0 (the part across is then of rounding size, and psi's mean is not defined)."""
    if s0 * s1 > 0.0:
        return (A * xi_parallel - (s1 - s0)) / (0.5 * (s0 + s1))
    return 0.0


def rotation_pieces(s0, zn, s_end, across, A, beta, gamma, n, sigma, limit):
    """Pieces so that z's direction turns by at most THETA_ROTATION per piece, weighted by the
    nonlinear share of the gain: from the parallel force s0 [N] (``zn`` = |s0|^n) towards about
    s_end, with ``across`` the norm of A times the travel across z [N]; at most ``limit`` + 1 (the
    caller's limit of substeps, so that more is refused, not computed)."""
    if across == 0.0 or A == 0.0:
        return 1
    reference = max(abs(s0), abs(s_end))
    if reference == 0.0:
        return 1
    power = zn if reference == abs(s0) else reference ** n
    share = abs(gamma + beta * sigma) * power / abs(A)
    turn = across / reference * share
    if turn <= THETA_ROTATION:
        return 1
    if turn > THETA_ROTATION * limit:
        return limit + 1
    return int(math.ceil(turn / THETA_ROTATION))


def vector_walk_frame(z, travel, e, A, beta, gamma, n, heun_limit, theta, max_pieces):
    """z after the straight relative displacement ``travel`` of a coupled element, stepped in the
    frame ``e`` (see the section's comment); returns (z, status)."""
    s0 = vector_dot(z, e)
    across0 = vector_axpy(-s0, e, z)
    along = vector_dot(travel, e)
    across = vector_axpy(-along, e, travel)
    s1, status = walk_along_xi(s0, along, A, beta, gamma, n, heun_limit, theta, max_pieces)
    E, phi1, _ = decay_factors(across_decay(s0, s1, along, A))
    return vector_axpy(s1, e, vector_axpy(E, across0, vector_scale(A * phi1, across))), status


def vector_walk(z, travel, A, beta, gamma, n, heun_limit, theta, max_pieces):
    """z (a 3-vector, N) after the straight relative displacement ``travel`` [mm] of a coupled
    Bouc-Wen element (``walk_along_xi`` across space: a displacement jump, or a step of an element
    driven by the displacement itself); returns (z, status). Pieces bound the turn of z's
    direction (THETA_ROTATION), each stepped in the frame of the mean of z and its linear
    prediction at the piece's end."""
    remaining = travel
    used = 0
    while True:
        e = block_frame(z, remaining, (0.0, 0.0, 0.0))
        s0 = vector_dot(z, e)
        zn = abs(s0) ** n
        along = vector_dot(remaining, e)
        sigma = 1.0 if along * s0 >= 0.0 else -1.0
        g0 = A - (gamma + beta * sigma) * zn
        across = A * vector_norm(vector_axpy(-along, e, remaining))
        count = rotation_pieces(s0, zn, s0 + g0 * along, across, A, beta, gamma, n, sigma, max_pieces)
        if used + 1 > max_pieces or count > max_pieces:
            return z, TOO_MANY_SUBSTEPS
        if count == 1:
            piece = remaining
        else:
            piece = vector_scale(1.0 / count, remaining)
        # the frame of the mean of z and its linear prediction at the piece's end, z + g0*along*e + A*across
        along_piece = vector_dot(piece, e)
        predicted = vector_axpy(g0 * along_piece, e, vector_axpy(A, vector_axpy(-along_piece, e, piece), z))
        middle = vector_direction(vector_axpy(1.0, z, predicted), e)
        predicted, status = vector_walk_frame(z, piece, middle, A, beta, gamma, n, heun_limit, theta, max_pieces)
        if status != OK:
            return z, status
        z = predicted
        used += 1
        if count == 1:
            return z, OK
        remaining = vector_axpy(-1.0, piece, remaining)


def vector_block_frame(u, z, h, a, blk, e):
    """A coupled block (``blk`` as the scalar block's) advanced by h in the frame ``e``; returns
    (u, z, xi) as 3-vectors. Along e the scalar :func:`block_step`; across it u decays at
    (K + alpha*A)/c and drives z at A, which the nonlinear term decays at psi (see the comment)."""
    K, alpha, c, A, beta, gamma, n = blk
    s0 = vector_dot(z, e)
    z_across = vector_axpy(-s0, e, z)
    u_along = vector_dot(u, e)
    u_across = vector_axpy(-u_along, e, u)
    a_along = vector_dot(a, e)
    a_across = vector_axpy(-a_along, e, a)
    u1, s1, xi_along = block_step(u_along, s0, abs(s0) ** n, h, a_along, blk)
    lam = (K + alpha * A) / c
    E, phi1, phi2 = decay_factors(lam * h)
    decay = across_decay(s0, s1, xi_along, A)
    Em, phim1, phim2 = decay_factors(decay)
    # integrals over the step of exp(-psi*(h - t)) times exp(-lam*t) and times t*phi1(lam*t):
    # the drive of z across by u_across(t) = u_across*exp(-lam*t) + a_across*t*phi1(lam*t)
    # written so that phi1's argument is >= 0 (no overflow): h*exp(-y)*phi1(x - y), y the smaller of
    # lam*h and psi*h
    if decay < lam * h:
        from_u = h * Em * decay_factors(lam * h - decay)[1]
    else:
        from_u = h * E * decay_factors(decay - lam * h)[1]
    if abs(lam * h) > 1e-5:   # the difference loses about 1e-16/(lam*h) of its value
        from_a = (h * phim1 - from_u) / lam
    else:   # the limit lam -> 0, h^2*phi2(psi*h), to a relative O(lam*h)
        from_a = h * h * phim2
    z_across = vector_axpy(Em, z_across, vector_axpy(A * from_u, u_across, vector_scale(A * from_a, a_across)))
    return (vector_axpy(u1, e, vector_axpy(E, u_across, vector_scale(h * phi1, a_across))),
            vector_axpy(s1, e, z_across),
            vector_axpy(xi_along, e, vector_axpy(h * phi1, u_across, vector_scale(h * h * phi2, a_across))))


def vector_block_view(u, z, a, n):
    """(e, s0, |s0|^n): a coupled block's frame (:func:`block_frame`), its force along it, and that
    force's power n, which the substeps (:func:`vector_substeps_needed`) and the step
    (:func:`vector_block_step`) share (a power is most of a step's cost)."""
    e = block_frame(z, u, a)
    s0 = vector_dot(z, e)
    return e, s0, abs(s0) ** n


def vector_block_step(u, z, h, a, blk, view):
    """A coupled block (3-vectors u [mm/s], z [N], drive a [mm/s^2]; ``view`` its
    :func:`vector_block_view`) advanced by h [s] in the frame of the mean of z's start and its
    linear prediction at the end, z + g*xi_along*e + A*xi_across (the travels at the frozen rates:
    the midpoint rule in the frame's turn, at the cost of two exponentials); returns (u, z, xi), xi
    the relative displacement over the step."""
    K, alpha, c, A, beta, gamma, n = blk
    e, s0, zn = view
    u_along = vector_dot(u, e)
    a_along = vector_dot(a, e)
    moving = u_along if u_along != 0.0 else a_along
    sigma = 1.0 if moving * s0 >= 0.0 else -1.0
    g0 = A - (gamma + beta * sigma) * zn
    E, phi1, phi2 = decay_factors((K + alpha * g0) / c * h)
    xi_along = h * (u_along * phi1 + a_along * h * phi2)
    E, phi1, phi2 = decay_factors((K + alpha * A) / c * h)
    xi_across = vector_axpy(h * phi1, vector_axpy(-u_along, e, u),
                            vector_scale(h * h * phi2, vector_axpy(-a_along, e, a)))
    predicted = vector_axpy(g0 * xi_along, e, vector_axpy(A, xi_across, z))
    return vector_block_frame(u, z, h, a, blk, vector_direction(vector_axpy(1.0, z, predicted), e))


def vector_substeps_needed(u, z, T, a, blk, limit, view):
    """Substeps of a coupled block over the remaining interval T [s] (``view`` its
    :func:`vector_block_view`): those of its part along z (:func:`substeps_needed`) and those that
    bound the turn of z's direction (:func:`rotation_pieces`, at most ``limit`` + 1)."""
    K, alpha, c, A, beta, gamma, n = blk
    e, s0, zn = view
    u_along = vector_dot(u, e)
    a_along = vector_dot(a, e)
    count = substeps_needed(u_along, s0, zn, T, a_along, blk)
    u_across = vector_axpy(-u_along, e, u)
    a_across = vector_axpy(-a_along, e, a)
    E, phi1, phi2 = decay_factors((K + alpha * A) / c * T)
    across = A * vector_norm(vector_axpy(T * phi1, u_across, vector_scale(T * T * phi2, a_across)))
    if across == 0.0:
        return count
    moving = u_along if u_along != 0.0 else a_along
    sigma = 1.0 if moving * s0 >= 0.0 else -1.0
    g0 = A - (gamma + beta * sigma) * zn
    E, phi1, phi2 = decay_factors((K + alpha * g0) / c * T)
    s_end = s0 + g0 * (T * (u_along * phi1 + a_along * T * phi2))
    turn = rotation_pieces(s0, zn, s_end, across, A, beta, gamma, n, sigma, limit)
    return turn if turn > count else count


# ---------------------------------------------------------------------------- the start
def start_state(m, x0, rest_force):
    """The state a run starts from at displacement ``x0`` [mm]: at rest holding ``rest_force``
    [N] (the model's ``resting_state``: a friction element stuck with its slider deflected, the
    force a test before left in the device) where that is a number, else relaxed
    (``initial_state``; NaN asks for it). Bound to each model's kernels as :func:`step` is, for
    a model with a ``resting_state``; never called in this module."""
    if rest_force == rest_force:
        return resting_state(m, x0, rest_force)  # noqa: F821 (the model's, where bound)
    return initial_state(m, x0)  # noqa: F821


def start_relaxed(m, x0, rest_force):
    """:func:`start_state` of a model that holds no force at rest (it has no ``resting_state``):
    relaxed at ``x0`` whatever ``rest_force`` is."""
    return initial_state(m, x0)  # noqa: F821


# ---------------------------------------------------------------------------- the step
def unprepared_step(m, h):
    """``prepare_step`` of a model without constants of its own per step size: its constants."""
    return m


def step(m, state, state_x, x, v, h, max_substeps):
    """One communication step of a model, the protocol every path runs: the displacement is
    x + v*t [mm] for 0 <= t <= h [s]; ``state`` is valid at displacement ``state_x``, so where
    x differs from it the difference is first a displacement jump (``jump``), then the model
    integrates over the step (``integrate``, given the step's constants ``prepare_step(m, h)``:
    what depends on h alone, such as a relaxation mode's decay; ``m`` itself for most models).
    Returns (state at x + v*h, substeps, status).

    Written once here and bound to each model's own kernels: in plain Python as
    ``BushingModel.step`` (a copy of this function whose globals are the model module's),
    compiled into each model's generated module (``numba_binding.model_source``), and in the
    generated C of the native FMU. It is never called in this module."""
    return step_prepared(m, prepare_step(m, h), state, state_x, x, v, h, max_substeps)  # noqa: F821


def step_prepared(m, ms, state, state_x, x, v, h, max_substeps):
    """:func:`step` with the step's constants ``ms`` = ``prepare_step(m, h)`` at hand: a caller that
    steps many times with the same h (the fit's population loop) prepares them once per h."""
    status = OK
    used = 0
    if x != state_x:
        state, status = jump(m, state, x - state_x)  # noqa: F821 (the model's, where bound)
    if status == OK:
        state, used, status = integrate(ms, state, x, v, h, max_substeps)  # noqa: F821
    return state, used, status


def step_coupled(m, state, state_x, x, v, h, max_substeps):
    """:func:`step` of a model's coupled form (``definition.CoupledKernels``): x, v and
    state_x are 3-vectors [mm, mm/s], and where x differs from state_x the difference is first a
    displacement jump. Bound to the coupled kernels ``jump_coupled`` and ``integrate_coupled``;
    never called in this module."""
    status = OK
    used = 0
    if x[0] != state_x[0] or x[1] != state_x[1] or x[2] != state_x[2]:
        state, status = jump_coupled(m, state, (x[0] - state_x[0], x[1] - state_x[1],  # noqa: F821
                                                x[2] - state_x[2]))
    if status == OK:
        state, used, status = integrate_coupled(prepare_step(m, h), state, x, v, h, max_substeps)  # noqa: F821
    return state, used, status


# ---------------------------------------------------------------------------- the driver
def advance(model, constants, state, state_x: float, x: float, v: float, h: float,
            max_substeps: int = DEFAULT_MAX_SUBSTEPS) -> tuple[tuple, int]:
    """One step of ``model`` (a ``definition.BushingModel``): displacement x + v*t [mm]
    for 0 <= t <= h [s], h > 0, from ``state`` (valid at displacement ``state_x`` [mm]; where
    the step starts elsewhere, the difference is applied first as a displacement jump).
    ``constants``: ``model.prepare`` of its parameters. Returns the state valid at x + v*h and
    the substeps used. Raises StepError if the result would overflow or is not finite, or if
    more than ``max_substeps`` are needed; ``state`` (a tuple) is never modified."""
    try:
        new, used, status = model.step(constants, state, state_x, x, v, h, max_substeps)
    except (OverflowError, ZeroDivisionError, ValueError) as exc:
        raise StepError(f"the step overflowed ({exc}) at x = {x:g} mm, v = {v:g} mm/s, "
                        f"state = {tuple(state)}: are x [mm], v [mm/s] and the parameters in their units?") from None
    if status == TOO_MANY_SUBSTEPS:
        raise StepError(f"more than {max_substeps} substeps needed for a step of {h:g} s at x = {x:g} mm, "
                        f"v = {v:g} mm/s: are x and v in mm and mm/s, or is the step too long?")
    if status == NOT_FINITE:
        raise StepError(f"the state {tuple(new)} at x = {x:g} mm, v = {v:g} mm/s is not finite: are x [mm], "
                        "v [mm/s] and the parameters in their units?")
    return new, used


def apply_displacement_jump(model, constants, state, jump_mm: float) -> tuple:
    """``model``'s response to an instantaneous displacement jump [mm] (an impulse in dx/dt).

    A master that sets x_{k+1} different from x_k + v_k*h (e.g. the instantaneous velocity
    instead of the mean over the step) makes such a jump at every step; treating it as a
    displacement of the whole model, not of its springs alone, keeps dx/dt = v consistent."""
    if jump_mm == 0.0:
        return tuple(state)
    new, status = model.jump(constants, state, jump_mm)
    if status != OK:
        raise StepError(f"a displacement jump of {jump_mm:g} mm needs too many substeps: is it in mm?")
    return new
