"""The classic single Bouc-Wen element (Ok et al., 2005), Fig. 6 of the paper.

    F = c0*dx/dt + k0*x + alpha*z,   dz/dt = g(z, sgn dx/dt)*dx/dt   (eq. 1's bracket g, the
    paper's beta and gamma)

Units N-mm-s: z is a force in N, alpha dimensionless, A in N/mm. The state is ``(z,)``.

The element is driven by the displacement itself, so within a step (dx/dt = v constant) z
depends on time only through x: a step is the walk of z along v*h (``integration``), in RK4
pieces over each of which g changes by at most ``integration.THETA``; no time stiffness.
"""
from __future__ import annotations

import math

from ..model.parameter_specs import DAMPING, EXPONENT, GAIN, SPRING, WEIGHT, ParameterSpec
from ..model.integration import (DEFAULT_MAX_SUBSTEPS, HEUN_JUMP_LIMIT, NOT_FINITE, OK, THETA, THETA_JUMP, block_gain,
                                 vector_dot, vector_gain, vector_walk, walk_along_xi)
from ..model.definition import BushingModel, CoupledKernels, SearchBox, SearchCoordinate, StateSpec
from ..model.search_coordinates import KIND
from .spencer_model import SINGLE_BLOCK_CONSTRAINTS

PARAMETER_SPECS = (
    ParameterSpec("c0", "N.s/mm", "viscous damping in parallel", **DAMPING),
    ParameterSpec("k0", "N/mm", "linear stiffness in parallel", **SPRING),
    ParameterSpec("alpha", "1", "weight of the hysteretic force z", **WEIGHT),
    ParameterSpec("A", "N/mm", "Bouc-Wen initial stiffness", **GAIN),
    ParameterSpec("beta", "N^(1-n)/mm", "Bouc-Wen shape parameter on |u|*z*|z|^(n-1) (as in eq. 1)"),
    ParameterSpec("gamma", "N^(1-n)/mm", "Bouc-Wen shape parameter on u*|z|^n (as in eq. 1)"),
    ParameterSpec("n", "1", "Bouc-Wen exponent", **EXPONENT),
)


# ---------------------------------------------------------------------------- kernels
def prepare(p):
    """The 7 values in ``PARAMETER_SPECS`` order, as they are."""
    c0, k0, alpha, A, beta, gamma, n = p
    return (c0, k0, alpha, A, beta, gamma, n)


def initial_state(m, x0):
    """Virgin hysteresis: z = 0 (F = k0*x0 at rest)."""
    return (0.0,)


def resting_state(m, x0, force):
    """At rest at x0 [mm] holding ``force`` [N]: z = (force - k0*x0)/alpha, the nearest the
    element holds to it (within its ultimate force (A/(beta + gamma))^(1/n) where beta + gamma > 0;
    z = 0 where alpha = 0)."""
    c0, k0, alpha, A, beta, gamma, n = m
    if alpha == 0.0:
        return (0.0,)
    z = (force - k0 * x0) / alpha
    if beta + gamma > 0.0:
        ultimate = (A / (beta + gamma)) ** (1.0 / n)
        if z > ultimate:
            z = ultimate
        if z < -ultimate:
            z = -ultimate
    return (z,)


def force(m, state, x, v):
    """F = c0*v + k0*x + alpha*z [N]."""
    c0, k0, alpha, A, beta, gamma, n = m
    return c0 * v + k0 * x + alpha * state[0]


def jump(m, state, jump_mm):
    """z walks along the jump."""
    c0, k0, alpha, A, beta, gamma, n = m
    z, status = walk_along_xi(state[0], jump_mm, A, beta, gamma, n, HEUN_JUMP_LIMIT, THETA_JUMP,
                              DEFAULT_MAX_SUBSTEPS)
    return (z,), status


def integrate(m, state, x, v, h, max_substeps):
    """z walks along v*h; returns (state, 1, status)."""
    c0, k0, alpha, A, beta, gamma, n = m
    z, status = walk_along_xi(state[0], v * h, A, beta, gamma, n, 0.0, THETA, max_substeps)
    if status == OK and not math.isfinite(z):
        status = NOT_FINITE
    return (z,), 1, status


def derivatives(m, state, x, v):
    """(dz/dt,) [N/s]: the element driven by the displacement itself (model exchange)."""
    c0, k0, alpha, A, beta, gamma, n = m
    return (v * block_gain(state[0], v, (0.0, alpha, 1.0, A, beta, gamma, n)),)


def switches(m, state, x, v):
    """v [mm/s] and z [N]: where the right-hand side switches."""
    return (v, state[0])


# ---------------------------------------------------------------------------- coupled kernels
# The element on a displacement vector (3-vectors x, v [mm, mm/s], z [N]; a plane path has a zero
# third component): F = c0*v + k0*x + alpha*z, dz = A*dx - |z|^(n-2)*(gamma*(z.dx) + beta*|z.dx|)*z,
# the isotropic law that is eq. 1 along any line (integration.vector_gain). The state is z.
def initial_state_coupled(m, x0):
    """Virgin hysteresis: z = 0."""
    return (0.0, 0.0, 0.0)


def force_coupled(m, state, x, v):
    """F = c0*v + k0*x + alpha*z [N], a 3-vector."""
    c0, k0, alpha, A, beta, gamma, n = m
    return tuple(c0 * v[i] + k0 * x[i] + alpha * state[i] for i in range(3))


def jump_coupled(m, state, jump):
    """z walks along the jump (a 3-vector, mm)."""
    c0, k0, alpha, A, beta, gamma, n = m
    return vector_walk(state, jump, A, beta, gamma, n, HEUN_JUMP_LIMIT, THETA_JUMP, DEFAULT_MAX_SUBSTEPS)


def integrate_coupled(m, state, x, v, h, max_substeps):
    """z walks along v*h; returns (state, 1, status)."""
    c0, k0, alpha, A, beta, gamma, n = m
    z, status = vector_walk(state, tuple(v[i] * h for i in range(3)), A, beta, gamma, n, 0.0, THETA, max_substeps)
    if status == OK and not math.isfinite(z[0] + z[1] + z[2]):
        status = NOT_FINITE
    return z, 1, status


def derivatives_coupled(m, state, x, v):
    """dz/dt [N/s] (model exchange)."""
    c0, k0, alpha, A, beta, gamma, n = m
    return vector_gain(state, v, A, beta, gamma, n)


def switches_coupled(m, state, x, v):
    """z.v [N.mm/s]: where it changes sign the element's law switches branch."""
    return (vector_dot(state, v),)


SEARCH = SearchBox(
    (SearchCoordinate("k0", KIND.stiffness, -3.0, 1.0), SearchCoordinate("c0", KIND.damping, -4.0, 2.0),
     SearchCoordinate("A", KIND.gain, -4.0, 1.0), SearchCoordinate("beta", KIND.shape, 0.0, 20.0, "n"),
     SearchCoordinate("gamma", KIND.shape_sum, 0.0, 40.0, "n", partner="beta", sign=1.0),
     SearchCoordinate("n", KIND.exponent, 0.1, 1.5)),
    unit_weights=("alpha",))
"""The fit's box (alpha held at 1)."""


MODEL = BushingModel(
    "single_bouc_wen", "SingleBoucWenBushing", "single Bouc-Wen", PARAMETER_SPECS,
    (StateSpec("z", 0, "N", "hysteretic force"),), "params_single_bouc_wen_fit_synthetic_table5.json",
    prepare, initial_state, jump, integrate, force,
    derivatives, switches, constraints=SINGLE_BLOCK_CONSTRAINTS,
    switch_specs=(StateSpec("v", 0, "m/s", "the velocity input, which drives the element"),
                  StateSpec("z", 1, "N", "hysteretic force")),
    search=SEARCH, plot_style=("C1", ":"), rank=20, resting_state=resting_state,
    coupled=CoupledKernels((StateSpec("z", 0, "N", "hysteretic force"),), initial_state_coupled,
                           jump_coupled, integrate_coupled, force_coupled, derivatives_coupled, switches_coupled,
                           (StateSpec("zv", 0, "N.m/s", "z.v: the element's branch"),)),
    static_spring=("k0",))
