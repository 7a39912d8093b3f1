"""The proposed bushing model of the paper: eqs. 1-5, 16 parameters. No FMI code here.

    dz1/dt = g1*(dx/dt - dy/dt),  dz2/dt = g2*(dx/dt - dw/dt)                       (eqs. 1-2)
    g_i = A_i - (gamma_i + beta_i*sgn(u_i)*sgn(z_i))*|z_i|^n_i
    c1*(dx/dt - dy/dt) + k1*(x - y) - k0*y + alpha1*z1 = 0                          (eq. 3)
    (c0 + c2)*dw/dt = c2*dx/dt + k2*(x - w) + alpha2*z2                              (eq. 4)
    F = k0*y + c0*dw/dt                                                              (eq. 5)

Units (the paper's): displacements x, y, w in mm, velocities in mm/s, hysteretic forces
z1, z2 and the bushing force F in N, time in s; parameters in N-mm-s units (below), so that
the paper's tables can be typed in verbatim. The state is ``(y, z1, w, z2)``.

How it is stepped (``integration``). With dx/dt = v constant over a step, each Bouc-Wen block
is the shared block form in its relative velocity u and hysteretic force z
(differentiate eqs. 3-4 and substitute eqs. 1-2):

    block 1:  u1 = v - dy/dt,  du1/dt = k0*v/c1 - lam1*u1,  lam1 = (k0 + k1 + alpha1*g1)/c1
    block 2:  u2 = v - dw/dt,  du2/dt = -lam2*u2,           lam2 = (k2 + alpha2*g2)/(c0 + c2)

The equations are stiff (with Table 5 the y-z1 mode decays at ~5000 1/s, and at ~5e5 1/s for
c1 = 0.01, while w relaxes over ~50 s) and non-smooth; the shared exponential step is stable
for any stiffness. y is recovered from the invariant c1*u1 = -(k1*(x - y) - k0*y + alpha1*z1),
w by integrating dw/dt = v - u2.
"""
from __future__ import annotations

import math

from ..model.parameter_specs import DAMPING, EXPONENT, GAIN, SPRING, WEIGHT, Constraint, ParameterSpec
from ..model.integration import (DEFAULT_MAX_SUBSTEPS, HEUN_JUMP_LIMIT, NOT_FINITE, OK, THETA_JUMP, TOO_MANY_SUBSTEPS,
                                 block_gain, block_power, block_step, substeps_needed, vector_block_step, vector_block_view,
                                 vector_dot, vector_gain, vector_substeps_needed, vector_walk, walk_along_xi)
from ..model.definition import BushingModel, CoupledKernels, SearchBox, SearchCoordinate, StateSpec
from ..model.search_coordinates import KIND

IDENTIFIER = "BoucWenBushing"

PARAMETER_SPECS: tuple[ParameterSpec, ...] = (
    ParameterSpec("c0", "N.s/mm", "dashpot in series with the right block; roll-off at low velocity", **DAMPING),
    ParameterSpec("k0", "N/mm", "spring from the left plate y to ground; main static stiffness", **SPRING),
    ParameterSpec("c1", "N.s/mm", "dashpot between x and y; relaxation of the impact force",
                  minimum=0.0, exclusive=True, why="it divides eq. 3"),
    ParameterSpec("k1", "N/mm", "spring between x and y (standard solid)", **SPRING),
    ParameterSpec("c2", "N.s/mm", "dashpot between x and w; viscous damping at large velocity", **DAMPING),
    ParameterSpec("k2", "N/mm", "spring between x and w; stiffness at large velocity", **SPRING),
    ParameterSpec("alpha1", "1", "weight of the hysteretic force z1 on the left plate", **WEIGHT),
    ParameterSpec("alpha2", "1", "weight of the hysteretic force z2 on the right plate", **WEIGHT),
    ParameterSpec("beta1", "N^(1-n1)/mm", "Bouc-Wen shape parameter of z1 (eq. 1)"),
    ParameterSpec("beta2", "N^(1-n2)/mm", "Bouc-Wen shape parameter of z2 (eq. 2)"),
    ParameterSpec("gamma1", "N^(1-n1)/mm", "Bouc-Wen shape parameter of z1 (eq. 1)"),
    ParameterSpec("gamma2", "N^(1-n2)/mm", "Bouc-Wen shape parameter of z2 (eq. 2)"),
    ParameterSpec("n1", "1", "Bouc-Wen exponent of z1 (smoothness of the transition)", **EXPONENT),
    ParameterSpec("n2", "1", "Bouc-Wen exponent of z2", **EXPONENT),
    ParameterSpec("A1", "N/mm", "Bouc-Wen initial stiffness of z1", **GAIN),
    ParameterSpec("A2", "N/mm", "Bouc-Wen initial stiffness of z2", **GAIN),
)
PARAMETER_NAMES: tuple[str, ...] = tuple(spec.name for spec in PARAMETER_SPECS)
PARAMETER_UNITS: dict[str, str] = {spec.name: spec.unit for spec in PARAMETER_SPECS}

CONSTRAINTS = (
    Constraint((("c0", 1.0), ("c2", 1.0)), 0.0, True, True, "N.s/mm", "it divides eq. 4"),
    # the paper's identification constraints, which the equations do not need but a fitted
    # bushing should satisfy
    Constraint((("A1", 1.0),), 1.0, False, False, "N/mm", "the paper's constraint"),
    Constraint((("A2", 1.0),), 1.0, False, False, "N/mm", "the paper's constraint"),
    Constraint((("beta1", 1.0),), 0.0, False, False, "", "the paper's constraint"),
    Constraint((("beta2", 1.0),), 0.0, False, False, "", "the paper's constraint"),
    Constraint((("beta1", 1.0), ("gamma1", 1.0)), 0.0, True, False, "", "the paper's constraint"),
    Constraint((("beta2", 1.0), ("gamma2", -1.0)), 0.0, True, False, "", "the paper's constraint"),
)


# ---------------------------------------------------------------------------- kernels
def prepare(p):
    """Constants of the hot loop from the 16 values in ``PARAMETER_SPECS`` order: (k0, k1, k2,
    c0, c1, c2, C = c0 + c2, K1 = k0 + k1, alpha1, alpha2, block 1, block 2), each block
    (K, alpha, c, A, beta, gamma, n) as ``integration`` takes it."""
    c0, k0, c1, k1, c2, k2, alpha1, alpha2, beta1, beta2, gamma1, gamma2, n1, n2, A1, A2 = p
    C = c0 + c2
    K1 = k0 + k1
    return (k0, k1, k2, c0, c1, c2, C, K1, alpha1, alpha2,
            (K1, alpha1, c1, A1, beta1, gamma1, n1),
            (k2, alpha2, C, A2, beta2, gamma2, n2))


def initial_state(m, x0):
    """Relaxed static equilibrium at displacement x0 [mm] with virgin hysteresis: z1 = z2 = 0,
    k1*(x0 - y) = k0*y and w = x0, so F = k0*k1/(k0 + k1)*x0, the static stiffness times x0,
    held while x0 is. (With k0 = k1 = 0, y affects nothing and is set to x0.)"""
    k1, K1 = m[1], m[7]
    y0 = k1 * x0 / K1 if K1 > 0.0 else x0
    return (y0, 0.0, x0, 0.0)


def force(m, state, x, v):
    """Eq. 5 with eq. 4: F = k0*y + c0*dw/dt [N], positive for positive x (the force the
    bushing exerts on its base, i.e. the force needed to hold the upper plate at x)."""
    k0, k1, k2, c0, c1, c2, C, K1, alpha1, alpha2, blk1, blk2 = m
    y, z1, w, z2 = state
    return k0 * y + c0 * ((c2 * v + k2 * (x - w) + alpha2 * z2) / C)


def jump(m, state, jump_mm):
    """Exact response to a displacement jump (an impulse in dx/dt): the dashpot c1 carries y
    along (y += jump, z1 unchanged); the dashpots c0, c2 split it (w += c2/(c0 + c2)*jump) and
    block 2 sees the relative displacement xi = c0/(c0 + c2)*jump, along which z2 walks."""
    k0, k1, k2, c0, c1, c2, C, K1, alpha1, alpha2, blk1, blk2 = m
    y, z1, w, z2 = state
    z2, status = walk_along_xi(z2, c0 / C * jump_mm, blk2[3], blk2[4], blk2[5], blk2[6],
                               HEUN_JUMP_LIMIT, THETA_JUMP, DEFAULT_MAX_SUBSTEPS)
    if status != OK:
        return (y, z1, w, z2), status
    return (y + jump_mm, z1, w + (C - c0) / C * jump_mm, z2), OK


def integrate(m, state, x, v, h, max_substeps):
    """Both blocks over the step; returns (state, substeps used, status)."""
    k0, k1, k2, c0, c1, c2, C, K1, alpha1, alpha2, blk1, blk2 = m
    y, z1, w, z2 = state
    a1 = k0 * v / c1
    elapsed = 0.0
    used = 0
    while True:
        remaining = h - elapsed
        x_now = x + v * elapsed
        u1 = -(k1 * (x_now - y) - k0 * y + alpha1 * z1) / c1
        u2 = (c0 * v - k2 * (x_now - w) - alpha2 * z2) / C
        zn1, zn2 = block_power(z1, blk1), block_power(z2, blk2)
        count = max(substeps_needed(u1, z1, zn1, remaining, a1, blk1),
                    substeps_needed(u2, z2, zn2, remaining, 0.0, blk2))
        if used + 1 > max_substeps or count > max_substeps:
            return (y, z1, w, z2), used, TOO_MANY_SUBSTEPS
        sub = remaining if count == 1 else remaining / count
        u1, z1, xi1 = block_step(u1, z1, zn1, sub, a1, blk1)
        u2, z2, xi2 = block_step(u2, z2, zn2, sub, 0.0, blk2)
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
        return (y, z1, w, z2), used, NOT_FINITE
    return (y, z1, w, z2), used, OK


def derivatives(m, state, x, v):
    """Eqs. 1-4 at displacement x [mm] and velocity v [mm/s]: the state's rates (dy/dt, dz1/dt,
    dw/dt, dz2/dt) [mm/s, N/s], for a host that integrates the state itself (model exchange)."""
    k0, k1, k2, c0, c1, c2, C, K1, alpha1, alpha2, blk1, blk2 = m
    y, z1, w, z2 = state
    dy = (c1 * v + k1 * (x - y) - k0 * y + alpha1 * z1) / c1
    dw = (c2 * v + k2 * (x - w) + alpha2 * z2) / C
    u1 = v - dy
    u2 = v - dw
    return (dy, u1 * block_gain(z1, u1, blk1), dw, u2 * block_gain(z2, u2, blk2))


def switches(m, state, x, v):
    """Where the right-hand side of eqs. 1-2 switches branch: the blocks' relative velocities
    u1 = v - dy/dt, u2 = v - dw/dt [mm/s] and their hysteretic forces z1, z2 [N] changing sign
    (event indicators for a host's integrator)."""
    dy, dz1, dw, dz2 = derivatives(m, state, x, v)
    return (v - dy, state[1], v - dw, state[3])


# ---------------------------------------------------------------------------- coupled kernels
# Eqs. 1-5 on a displacement vector (3-vectors x, v, y, w, z1, z2; a plane path has a zero third
# component): the plates y and w are vectors, every spring and dashpot acts on each component, and
# each Bouc-Wen block is the isotropic vector block (integration's coupled blocks), eq. 1 along any
# line. The state is (y, z1, w, z2), 12 floats.
def initial_state_coupled(m, x0):
    """Relaxed static equilibrium at the displacement x0 (a 3-vector) with virgin hysteresis."""
    k1, K1 = m[1], m[7]
    if K1 > 0.0:
        return (k1 * x0[0] / K1, k1 * x0[1] / K1, k1 * x0[2] / K1, 0.0, 0.0, 0.0, x0[0], x0[1], x0[2], 0.0, 0.0, 0.0)
    return (x0[0], x0[1], x0[2], 0.0, 0.0, 0.0, x0[0], x0[1], x0[2], 0.0, 0.0, 0.0)


def force_coupled(m, state, x, v):
    """Eq. 5 with eq. 4 on each component: F = k0*y + c0*dw/dt [N], a 3-vector."""
    k0, k1, k2, c0, c1, c2, C, K1, alpha1, alpha2, blk1, blk2 = m
    return tuple(k0 * state[i] + c0 * ((c2 * v[i] + k2 * (x[i] - state[6 + i]) + alpha2 * state[9 + i]) / C)
                 for i in range(3))


def jump_coupled(m, state, jump):
    """A displacement jump (a 3-vector): y takes it, w its share c2/(c0 + c2), and z2 walks along
    the rest, c0/(c0 + c2)*jump."""
    k0, k1, k2, c0, c1, c2, C, K1, alpha1, alpha2, blk1, blk2 = m
    z2, status = vector_walk((state[9], state[10], state[11]), tuple(c0 / C * jump[i] for i in range(3)), blk2[3],
                             blk2[4], blk2[5], blk2[6], HEUN_JUMP_LIMIT, THETA_JUMP, DEFAULT_MAX_SUBSTEPS)
    if status != OK:
        return state, status
    return (state[0] + jump[0], state[1] + jump[1], state[2] + jump[2], state[3], state[4], state[5],
            *tuple(state[6 + i] + (C - c0) / C * jump[i] for i in range(3)), z2[0], z2[1], z2[2]), OK


def integrate_coupled(m, state, x, v, h, max_substeps):
    """Both vector blocks over the step; returns (state, substeps used, status)."""
    k0, k1, k2, c0, c1, c2, C, K1, alpha1, alpha2, blk1, blk2 = m
    y = (state[0], state[1], state[2])
    z1 = (state[3], state[4], state[5])
    w = (state[6], state[7], state[8])
    z2 = (state[9], state[10], state[11])
    a1 = tuple(k0 * v[i] / c1 for i in range(3))
    elapsed = 0.0
    used = 0
    while True:
        remaining = h - elapsed
        x_now = tuple(x[i] + v[i] * elapsed for i in range(3))
        u1 = tuple(-(k1 * (x_now[i] - y[i]) - k0 * y[i] + alpha1 * z1[i]) / c1 for i in range(3))
        u2 = tuple((c0 * v[i] - k2 * (x_now[i] - w[i]) - alpha2 * z2[i]) / C for i in range(3))
        view1 = vector_block_view(u1, z1, a1, blk1[6])
        view2 = vector_block_view(u2, z2, (0.0, 0.0, 0.0), blk2[6])
        count = max(vector_substeps_needed(u1, z1, remaining, a1, blk1, max_substeps, view1),
                    vector_substeps_needed(u2, z2, remaining, (0.0, 0.0, 0.0), blk2, max_substeps, view2))
        if used + 1 > max_substeps or count > max_substeps:
            return (y[0], y[1], y[2], z1[0], z1[1], z1[2], w[0], w[1], w[2], z2[0], z2[1], z2[2]), used, \
                TOO_MANY_SUBSTEPS
        sub = remaining if count == 1 else remaining / count
        u1, z1, xi1 = vector_block_step(u1, z1, sub, a1, blk1, view1)
        u2, z2, xi2 = vector_block_step(u2, z2, sub, (0.0, 0.0, 0.0), blk2, view2)
        elapsed = h if count == 1 else elapsed + sub
        x_now = tuple(x[i] + v[i] * elapsed for i in range(3))
        # as the one-axis step: the invariant keeps y consistent with u1
        if K1 > 0.0:
            y = tuple((k1 * x_now[i] + alpha1 * z1[i] + c1 * u1[i]) / K1 for i in range(3))
        else:
            y = tuple(y[i] + v[i] * sub - xi1[i] for i in range(3))
        w = tuple(w[i] + v[i] * sub - xi2[i] for i in range(3))
        used += 1
        if count == 1:
            break
    new = (y[0], y[1], y[2], z1[0], z1[1], z1[2], w[0], w[1], w[2], z2[0], z2[1], z2[2])
    if not math.isfinite(sum(new[i] for i in range(12))):
        return new, used, NOT_FINITE
    return new, used, OK


def derivatives_coupled(m, state, x, v):
    """Eqs. 1-4 on each component: (dy/dt, dz1/dt, dw/dt, dz2/dt), 3-vectors each [mm/s, N/s]."""
    k0, k1, k2, c0, c1, c2, C, K1, alpha1, alpha2, blk1, blk2 = m
    dy = tuple((c1 * v[i] + k1 * (x[i] - state[i]) - k0 * state[i] + alpha1 * state[3 + i]) / c1 for i in range(3))
    dw = tuple((c2 * v[i] + k2 * (x[i] - state[6 + i]) + alpha2 * state[9 + i]) / C for i in range(3))
    dz1 = vector_gain((state[3], state[4], state[5]), tuple(v[i] - dy[i] for i in range(3)), blk1[3], blk1[4],
                      blk1[5], blk1[6])
    dz2 = vector_gain((state[9], state[10], state[11]), tuple(v[i] - dw[i] for i in range(3)), blk2[3], blk2[4],
                      blk2[5], blk2[6])
    return (dy[0], dy[1], dy[2], dz1[0], dz1[1], dz1[2], dw[0], dw[1], dw[2], dz2[0], dz2[1], dz2[2])


def switches_coupled(m, state, x, v):
    """z1.u1 and z2.u2 [N.mm/s]: where either changes sign its block's law switches branch."""
    rates = derivatives_coupled(m, state, x, v)
    return (vector_dot((state[3], state[4], state[5]), tuple(v[i] - rates[i] for i in range(3))),
            vector_dot((state[9], state[10], state[11]), tuple(v[i] - rates[6 + i] for i in range(3))))


SEARCH = SearchBox(
    (SearchCoordinate("k0", KIND.stiffness, -3.0, 1.0), SearchCoordinate("k1", KIND.stiffness, -3.0, 1.0),
     SearchCoordinate("k2", KIND.stiffness, -5.0, 0.0),
     SearchCoordinate("c0", KIND.time_constant, -math.inf, 6.0, over=("k2", "A2")),
     SearchCoordinate("c1", KIND.time_constant, -math.inf, 4.0, over=("k0", "k1", "A1")),
     SearchCoordinate("c2", KIND.damping, -4.0, 2.0),
     SearchCoordinate("A1", KIND.gain, -4.0, 1.0), SearchCoordinate("A2", KIND.gain, -4.0, 1.0),
     SearchCoordinate("beta1", KIND.shape, 0.0, 20.0, "n1"), SearchCoordinate("beta2", KIND.shape, 0.0, 20.0, "n2"),
     SearchCoordinate("gamma1", KIND.shape_sum, 0.0, 40.0, "n1", partner="beta1", sign=1.0),
     SearchCoordinate("gamma2", KIND.shape_sum, 0.0, 40.0, "n2", partner="beta2", sign=-1.0),
     SearchCoordinate("n1", KIND.exponent, 0.1, 1.5), SearchCoordinate("n2", KIND.exponent, 0.1, 1.5)),
    unit_weights=("alpha1", "alpha2"))
"""The fit's box: the paper's constraints A >= 1 N/mm, beta >= 0, beta1 + gamma1 > 0 and
beta2 - gamma2 > 0 are bounds of its coordinates; each block's alpha is held at 1."""


MODEL = BushingModel(
    "proposed", IDENTIFIER, "proposed (paper eqs. 1-5)", PARAMETER_SPECS,
    (StateSpec("z1", 1, "N", "hysteretic force of the left block (eq. 1)"),
     StateSpec("z2", 3, "N", "hysteretic force of the right block (eq. 2)"),
     StateSpec("y", 0, "m", "displacement of the left plate (eq. 3)"),
     StateSpec("w", 2, "m", "displacement of the right plate (eq. 4)")),
    "params_table5_combined.json", prepare, initial_state, jump, integrate, force,
    derivatives, switches,
    switch_specs=(StateSpec("u1", 0, "m/s", "relative velocity of block 1, v - dy/dt"),
                  StateSpec("z1", 1, "N", "hysteretic force of block 1"),
                  StateSpec("u2", 2, "m/s", "relative velocity of block 2, v - dw/dt"),
                  StateSpec("z2", 3, "N", "hysteretic force of block 2")),
    constraints=CONSTRAINTS, search=SEARCH, plot_style=("C0", "-"), rank=0,
    description=("Nonlinear rubber bushing, one axis: the modified Spencer/Bouc-Wen model of 'New nonlinear bushing "
                 "model for general excitations using Bouc-Wen hysteretic model' (eqs. 1-5). Ports in SI, "
                 "parameters in the paper's N-mm-s units."),
    coupled=CoupledKernels(
        (StateSpec("y", 0, "m", "displacement of the left plate (eq. 3)"),
         StateSpec("z1", 1, "N", "hysteretic force of the left block (eq. 1)"),
         StateSpec("w", 2, "m", "displacement of the right plate (eq. 4)"),
         StateSpec("z2", 3, "N", "hysteretic force of the right block (eq. 2)")),
        initial_state_coupled, jump_coupled, integrate_coupled, force_coupled, derivatives_coupled, switches_coupled,
        (StateSpec("z1u1", 0, "N.m/s", "z1.u1: block 1's branch"),
         StateSpec("z2u2", 1, "N.m/s", "z2.u2: block 2's branch"))))
