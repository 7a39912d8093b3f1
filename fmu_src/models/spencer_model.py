"""Spencer's phenomenological MR-damper model (Spencer et al., 1997), Fig. 7 of the paper.

    F = c1*dy/dt + k1*(x - x0)
    dy/dt = [alpha*z + c0*dx/dt + k0*(x - y)] / (c0 + c1)
    dz/dt = -gamma*|u|*z*|z|^(n-1) - beta*u*|z|^n + A*u,   u = dx/dt - dy/dt

Spencer puts gamma on the |u| term where the paper's eqs. 1-2 put beta; the parameters keep
Spencer's names and meaning (in the shared block form, the paper's beta is Spencer's gamma).
Units N-mm-s as for the proposed model: z is a force in N, so alpha is dimensionless and A in
N/mm (Spencer writes z in m and alpha in N/m; the force is the same with z_here =
alpha_Spencer*z_Spencer). The state is ``(y, z)``, y in mm.

Stepped as one block of ``integration`` (differentiate the y equation and substitute dz/dt):
u = (c1*v - k0*(x - y) - alpha*z)/(c0 + c1), du/dt = -lam*u, lam = (k0 + alpha*g)/(c0 + c1);
y follows dy/dt = v - u.
"""
from __future__ import annotations

import math

from ..model.parameter_specs import DAMPING, EXPONENT, GAIN, SPRING, WEIGHT, Constraint, ParameterSpec
from ..model.integration import (DEFAULT_MAX_SUBSTEPS, HEUN_JUMP_LIMIT, NOT_FINITE, OK, THETA_JUMP, TOO_MANY_SUBSTEPS,
                                 block_gain, block_power, block_step, substeps_needed, vector_block_step, vector_block_view,
                                 vector_dot, vector_gain, vector_substeps_needed, vector_walk, walk_along_xi)
from ..model.definition import BushingModel, CoupledKernels, SearchBox, SearchCoordinate, StateSpec
from ..model.search_coordinates import KIND

PARAMETER_SPECS = (
    ParameterSpec("c0", "N.s/mm", "viscous damping in parallel with the Bouc-Wen element (large velocities)",
                  **DAMPING),
    ParameterSpec("k0", "N/mm", "stiffness in parallel with the Bouc-Wen element (large velocities)", **SPRING),
    ParameterSpec("c1", "N.s/mm", "dashpot from the internal displacement y to ground (roll-off at low velocity)",
                  minimum=0.0, exclusive=True, why="it divides dy/dt"),
    ParameterSpec("k1", "N/mm", "accumulator spring from x to ground", **SPRING),
    ParameterSpec("x0", "mm", "initial displacement of the accumulator spring k1 (preload -k1*x0)"),
    ParameterSpec("alpha", "1", "weight of the hysteretic force z", **WEIGHT),
    ParameterSpec("A", "N/mm", "Bouc-Wen initial stiffness", **GAIN),
    ParameterSpec("beta", "N^(1-n)/mm", "Spencer's beta: on u*|z|^n (the paper's gamma)"),
    ParameterSpec("gamma", "N^(1-n)/mm", "Spencer's gamma: on |u|*z*|z|^(n-1) (the paper's beta)"),
    ParameterSpec("n", "1", "Bouc-Wen exponent", **EXPONENT),
)

SINGLE_BLOCK_CONSTRAINTS = (
    # beta and gamma as the single Bouc-Wen element names them too
    Constraint((("beta", 1.0), ("gamma", 1.0)), 0.0, True, False, "", "the bounded hysteresis loop's condition"),
)


# ---------------------------------------------------------------------------- kernels
def prepare(p):
    """(c0, k0, c1, k1, x0, alpha, C = c0 + c1, block (K, alpha, c, A, beta, gamma, n) in the
    paper's beta/gamma) from the 10 values in ``PARAMETER_SPECS`` order."""
    c0, k0, c1, k1, x0, alpha, A, beta, gamma, n = p
    C = c0 + c1
    return (c0, k0, c1, k1, x0, alpha, C, (k0, alpha, C, A, gamma, beta, n))


def initial_state(m, x0):
    """At rest at displacement x0 [mm]: y = x0, z = 0 (F = k1*(x0 - x0_spring))."""
    return (x0, 0.0)


def force(m, state, x, v):
    """F = c1*dy/dt + k1*(x - x0) [N]."""
    c0, k0, c1, k1, x0, alpha, C, blk = m
    y, z = state
    return c1 * ((alpha * z + c0 * v + k0 * (x - y)) / C) + k1 * (x - x0)


def jump(m, state, jump_mm):
    """An impulse in dx/dt: the dashpots c0 (across the element) and c1 (to ground) split it,
    y += c0/(c0 + c1)*jump, and z walks along the element's share c1/(c0 + c1)*jump."""
    c0, k0, c1, k1, x0, alpha, C, blk = m
    y, z = state
    z, status = walk_along_xi(z, c1 / C * jump_mm, blk[3], blk[4], blk[5], blk[6],
                              HEUN_JUMP_LIMIT, THETA_JUMP, DEFAULT_MAX_SUBSTEPS)
    if status != OK:
        return (y, z), status
    return (y + c0 / C * jump_mm, z), OK


def integrate(m, state, x, v, h, max_substeps):
    """The block over the step; returns (state, substeps used, status)."""
    c0, k0, c1, k1, x0, alpha, C, blk = m
    y, z = state
    elapsed = 0.0
    used = 0
    while True:
        remaining = h - elapsed
        u = (c1 * v - k0 * (x + v * elapsed - y) - alpha * z) / C
        zn = block_power(z, blk)
        count = substeps_needed(u, z, zn, remaining, 0.0, blk)
        if used + 1 > max_substeps or count > max_substeps:
            return (y, z), used, TOO_MANY_SUBSTEPS
        sub = remaining if count == 1 else remaining / count
        u, z, xi = block_step(u, z, zn, sub, 0.0, blk)
        elapsed = h if count == 1 else elapsed + sub
        y = y + v * sub - xi
        used += 1
        if count == 1:
            break
    if not (math.isfinite(y) and math.isfinite(z)):
        return (y, z), used, NOT_FINITE
    return (y, z), used, OK


def derivatives(m, state, x, v):
    """(dy/dt, dz/dt) [mm/s, N/s] at displacement x [mm] and velocity v [mm/s] (model exchange)."""
    c0, k0, c1, k1, x0, alpha, C, blk = m
    y, z = state
    u = (c1 * v - k0 * (x - y) - alpha * z) / C
    return (v - u, u * block_gain(z, u, blk))


def switches(m, state, x, v):
    """The element's relative velocity u [mm/s] and z [N]: where the right-hand side switches."""
    c0, k0, c1, k1, x0, alpha, C, blk = m
    y, z = state
    return ((c1 * v - k0 * (x - y) - alpha * z) / C, z)


# ---------------------------------------------------------------------------- coupled kernels
# On a displacement vector (3-vectors; integration's coupled blocks): y is a vector, each linear
# element acts on each component and the Bouc-Wen element is the isotropic vector block. The
# accumulator's offset x0 has no direction in the plane: the coupled model takes k1*x (a group
# refuses x0 != 0; an axis offset and preload do that job). The state is (y, z), 6 floats.
def initial_state_coupled(m, x0):
    """At rest at the displacement x0 (a 3-vector): y = x0, z = 0."""
    return (x0[0], x0[1], x0[2], 0.0, 0.0, 0.0)


def _relative_velocity_coupled(m, y, z, x, v):
    """The element's relative velocity u = (c1*v - k0*(x - y) - alpha*z)/(c0 + c1) [mm/s]."""
    c0, k0, c1, k1, x0, alpha, C, blk = m
    return tuple((c1 * v[i] - k0 * (x[i] - y[i]) - alpha * z[i]) / C for i in range(3))


def force_coupled(m, state, x, v):
    """F = c1*dy/dt + k1*x [N], a 3-vector."""
    c0, k0, c1, k1, x0, alpha, C, blk = m
    return tuple(c1 * ((alpha * state[3 + i] + c0 * v[i] + k0 * (x[i] - state[i])) / C) + k1 * x[i]
                 for i in range(3))


def jump_coupled(m, state, jump):
    """The dashpots split the jump: y += c0/(c0 + c1)*jump, z walks along c1/(c0 + c1)*jump."""
    c0, k0, c1, k1, x0, alpha, C, blk = m
    z, status = vector_walk((state[3], state[4], state[5]), tuple(c1 / C * jump[i] for i in range(3)), blk[3], blk[4],
                            blk[5], blk[6], HEUN_JUMP_LIMIT, THETA_JUMP, DEFAULT_MAX_SUBSTEPS)
    if status != OK:
        return state, status
    return (*tuple(state[i] + c0 / C * jump[i] for i in range(3)), z[0], z[1], z[2]), OK


def integrate_coupled(m, state, x, v, h, max_substeps):
    """The vector block over the step; returns (state, substeps used, status)."""
    c0, k0, c1, k1, x0, alpha, C, blk = m
    y = (state[0], state[1], state[2])
    z = (state[3], state[4], state[5])
    elapsed = 0.0
    used = 0
    while True:
        remaining = h - elapsed
        u = _relative_velocity_coupled(m, y, z, tuple(x[i] + v[i] * elapsed for i in range(3)), v)
        view = vector_block_view(u, z, (0.0, 0.0, 0.0), blk[6])
        count = vector_substeps_needed(u, z, remaining, (0.0, 0.0, 0.0), blk, max_substeps, view)
        if used + 1 > max_substeps or count > max_substeps:
            return (y[0], y[1], y[2], z[0], z[1], z[2]), used, TOO_MANY_SUBSTEPS
        sub = remaining if count == 1 else remaining / count
        u, z, xi = vector_block_step(u, z, sub, (0.0, 0.0, 0.0), blk, view)
        elapsed = h if count == 1 else elapsed + sub
        y = tuple(y[i] + v[i] * sub - xi[i] for i in range(3))
        used += 1
        if count == 1:
            break
    if not math.isfinite(y[0] + y[1] + y[2] + z[0] + z[1] + z[2]):
        return (y[0], y[1], y[2], z[0], z[1], z[2]), used, NOT_FINITE
    return (y[0], y[1], y[2], z[0], z[1], z[2]), used, OK


def derivatives_coupled(m, state, x, v):
    """(dy/dt, dz/dt) [mm/s, N/s] (model exchange)."""
    c0, k0, c1, k1, x0, alpha, C, blk = m
    z = (state[3], state[4], state[5])
    u = _relative_velocity_coupled(m, (state[0], state[1], state[2]), z, x, v)
    dz = vector_gain(z, u, blk[3], blk[4], blk[5], blk[6])
    return (v[0] - u[0], v[1] - u[1], v[2] - u[2], dz[0], dz[1], dz[2])


def switches_coupled(m, state, x, v):
    """z.u [N.mm/s]: where it changes sign the element's law switches branch."""
    z = (state[3], state[4], state[5])
    return (vector_dot(z, _relative_velocity_coupled(m, (state[0], state[1], state[2]), z, x, v)),)


SEARCH = SearchBox(
    (SearchCoordinate("k0", KIND.stiffness, -5.0, 1.0), SearchCoordinate("k1", KIND.stiffness, -3.0, 1.0),
     SearchCoordinate("c0", KIND.damping, -4.0, 2.0),
     SearchCoordinate("c1", KIND.time_constant, -math.inf, 6.0, over=("k0", "A")),
     SearchCoordinate("A", KIND.gain, -4.0, 1.0), SearchCoordinate("gamma", KIND.shape, 0.0, 20.0, "n"),
     SearchCoordinate("beta", KIND.shape_sum, 0.0, 40.0, "n", partner="gamma", sign=1.0),
     SearchCoordinate("n", KIND.exponent, 0.1, 1.5)),
    unit_weights=("alpha",), zeros=("x0",))
"""The fit's box. Spencer's gamma sits where eq. 1 has beta: gamma >= 0, gamma + beta > 0; its
dashpot to ground c1 works against k0 and the Bouc-Wen element; x0 (a constant force) is held at 0."""


MODEL = BushingModel(
    "spencer", "SpencerBushing", "Spencer (1997)", PARAMETER_SPECS,
    (StateSpec("z", 1, "N", "hysteretic force"),
     StateSpec("y", 0, "m", "internal displacement (between the Bouc-Wen element and c1)")),
    "params_spencer_fit_synthetic_table5.json", prepare, initial_state, jump, integrate, force,
    derivatives, switches,
    switch_specs=(StateSpec("u", 0, "m/s", "relative velocity of the Bouc-Wen element, v - dy/dt"),
                  StateSpec("z", 1, "N", "hysteretic force")),
    constraints=SINGLE_BLOCK_CONSTRAINTS, search=SEARCH, plot_style=("C2", "-."), rank=10,
    coupled=CoupledKernels(
        (StateSpec("y", 0, "m", "internal displacement (between the Bouc-Wen element and c1)"),
         StateSpec("z", 1, "N", "hysteretic force")),
        initial_state_coupled, jump_coupled, integrate_coupled, force_coupled, derivatives_coupled, switches_coupled,
        (StateSpec("zu", 0, "N.m/s", "z.u: the element's branch"),), zero_parameters=("x0",)),
    static_spring=("k1", "x0"))
