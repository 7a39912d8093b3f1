"""A fractional-derivative bushing model (Sjöberg and Kari, Vehicle System Dynamics 37, 2002;
García Tárrago et al., Polymer Testing 26, 2007): a progressive elastic spring, Berg's friction
and a fractional-derivative viscoelastic element in parallel.

    F = k0*x + k3*x^3 + F_f + b*D^alpha x,   0 < alpha < 1

with F_f Berg's friction as in ``berg_model``. The fractional element's dynamic stiffness
b*(i*omega)^alpha has the loss angle alpha*90 degrees at every frequency and a magnitude that
grows like omega^alpha: two numbers for the broad relaxation spectrum that gives filled rubber
its nearly constant loss angle over 1-100 Hz.

Realisation with a bounded state. D^alpha is the relaxation spectrum

    s^alpha = sin(alpha*pi)/pi * integral over r > 0 of r^(alpha-1) * s/(s + r) dr,

a continuum of Maxwell elements s/(s + r) of rate r. On a fixed logarithmic grid of MODES rates
r_j = 10^-4 ... 10^5 1/s, two per decade (spacing d = ln(10)/2), each is a Maxwell element of
stiffness b*sin(alpha*pi)/pi*r_j^alpha*d (the midpoint rule in ln r); below the grid, the rates
under r_a = r_0*exp(-d/2) are one Maxwell element with their whole stiffness
b*sin(alpha*pi)/pi*r_a^alpha/alpha and the rate r_a*(1 - alpha)/alpha, which keeps both their
stiffness at frequencies above r_a and their viscosity below it; above the grid, the rates over
r_b = r_(MODES-1)*exp(d/2) act as one dashpot b*sin(alpha*pi)/pi*r_b^(alpha-1)/(1 - alpha).
The state and the cost of a step are fixed (MODES + 1 Maxwell forces); the realisation's error
against b*(i*omega)^alpha is measured in ``benchmarks/bench_fractional_realisation.py`` and
stated on the Models page of the docs.

Units N-mm-s: x in mm, forces in N, k0 in N/mm, k3 in N/mm^3, x2 in mm, b in N.s^alpha/mm,
alpha dimensionless. The state is ``(travel, F_s, direction, f_0, ..., f_MODES)``: the
friction's (``berg_model``) and the forces of the MODES + 1 Maxwell elements [N], the lower
tail's last. Exact over a step with constant velocity, as Berg's model.
"""
from __future__ import annotations

import math

from .berg_model import COUPLED_STATES, CUBIC, FRICTION_LIMIT, HALF_TRAVEL
from ..model.parameter_specs import SPRING, ParameterSpec
from ..model.elements import (friction_force, friction_jump_turn, friction_turn, maxwell_decay, maxwell_step,
                              vector_friction_force, vector_friction_jump_turn, vector_friction_turn)
from ..model.integration import NOT_FINITE, OK, vector_dot
from ..model.definition import BushingModel, CoupledKernels, SearchBox, SearchCoordinate, SlowLoop, StateSpec
from ..model.search_coordinates import KIND

MODES = 19
"""Maxwell elements on the grid of rates, 10^-4 ... 10^5 1/s, two per decade."""
ELEMENTS = MODES + 1
"""The grid's elements and the one of the rates below it."""
LOG_LOWEST_RATE = math.log(1e-4)
LOG_RATE_STEP = math.log(10.0) / 2.0
LOG_TAIL_RATE = LOG_LOWEST_RATE - 0.5 * LOG_RATE_STEP
"""ln r_a: the rates below the grid (the lower tail, one Maxwell element)."""
LOG_TOP_RATE = LOG_LOWEST_RATE + (MODES - 0.5) * LOG_RATE_STEP
"""ln r_b: the rates above the grid (the upper tail, one dashpot)."""

PARAMETER_SPECS = (
    ParameterSpec("k0", "N/mm", "linear elastic stiffness", **SPRING),
    ParameterSpec("k3", "N/mm^3", "cubic elastic stiffness: the progressive spring k0*x + k3*x^3", **CUBIC),
    ParameterSpec("Ff_max", "N", "friction force limit: Berg's friction tends to +-Ff_max far from a reversal",
                  **FRICTION_LIMIT),
    ParameterSpec("x2", "mm", "friction travel from rest to half the limit (stiffness Ff_max/x2 at a reversal)",
                  **HALF_TRAVEL),
    ParameterSpec("b", "N.s^alpha/mm", "coefficient of the fractional derivative: |K*| of the element is "
                  "b*omega^alpha", minimum=0.0, why="a negative viscoelastic element adds energy",
                  bound_powers=(0, 1)),
    ParameterSpec("alpha", "1", "order of the fractional derivative: the element's loss angle is alpha*90 degrees",
                  minimum=0.0, maximum=1.0, exclusive=True,
                  why="between a spring (0) and a dashpot (1), the spectrum's integral exists"),
)


# ---------------------------------------------------------------------------- kernels
def prepare(p):
    """(k0, k3, Ff_max, x2, the ELEMENTS Maxwell stiffnesses [N/mm], their rates [1/s], the upper
    tail's dashpot [N.s/mm]) from the 6 values in ``PARAMETER_SPECS`` order."""
    k0, k3, limit, half_travel, b, alpha = p
    scale = b * math.sin(alpha * math.pi) / math.pi
    stiffness = (*tuple(scale * LOG_RATE_STEP * math.exp(alpha * (LOG_LOWEST_RATE + i * LOG_RATE_STEP))
                        for i in range(MODES)),
                 scale * math.exp(alpha * LOG_TAIL_RATE) / alpha)
    rates = (*tuple(math.exp(LOG_LOWEST_RATE + i * LOG_RATE_STEP) for i in range(MODES)),
             math.exp(LOG_TAIL_RATE) * (1.0 - alpha) / alpha)
    dashpot = scale * math.exp((alpha - 1.0) * LOG_TOP_RATE) / (1.0 - alpha)
    return (k0, k3, limit, half_travel, stiffness, rates, dashpot)


def initial_state(m, x0):
    """At rest at x0 [mm]: no travel since a reversal, no friction or relaxation force."""
    return (0.0, 0.0, 0.0, *tuple(0.0 for i in range(ELEMENTS)))


def force(m, state, x, v):
    """F = k0*x + k3*x^3 + F_f + (the Maxwell forces) + (upper tail)*v [N]."""
    k0, k3, limit, half_travel, stiffness, rates, dashpot = m
    return (k0 * x + k3 * x * x * x + friction_force(limit, half_travel, state[0], state[1], state[2])
            + sum(state[3 + i] for i in range(ELEMENTS)) + dashpot * v)


def update(m, state, x, v):
    """At an event (v changed sign): the friction reverses if v runs against its direction."""
    k0, k3, limit, half_travel, stiffness, rates, dashpot = m
    travel, reversal, direction = friction_turn(limit, half_travel, state[0], state[1], state[2], v)
    return (travel, reversal, direction, *tuple(state[3 + i] for i in range(ELEMENTS)))


def jump(m, state, jump_mm):
    """An instantaneous displacement jump: a reversal first if it runs against the motion (and is
    more than rounding, ``elements.ROUNDING_JUMP_MM``), then
    the friction travels it and the Maxwell springs take it."""
    k0, k3, limit, half_travel, stiffness, rates, dashpot = m
    travel, reversal, direction = friction_jump_turn(limit, half_travel, state[0], state[1], state[2], jump_mm)
    return (travel + jump_mm, reversal, direction,
            *tuple(state[3 + i] + stiffness[i] * jump_mm for i in range(ELEMENTS))), OK


def prepare_step(m, h):
    """The step's constants: the model's constants and every Maxwell element's decay over h
    (``elements.maxwell_decay``), which depend on h alone: a caller that steps many times with
    the same h computes them once (the fit's population loop), instead of ELEMENTS exponentials
    a step."""
    rates = m[5]
    return (m, tuple(maxwell_decay(rates[i], h) for i in range(ELEMENTS)))


def integrate(ms, state, x, v, h, max_substeps):
    """Over the step x + v*t (``ms`` = ``prepare_step(m, h)``): a reversal at its start if v runs
    against the motion, the travel grows by v*h and every Maxwell force follows exactly; returns
    (state, 1, status)."""
    m, decays = ms
    k0, k3, limit, half_travel, stiffness, rates, dashpot = m
    travel, reversal, direction = friction_turn(limit, half_travel, state[0], state[1], state[2], v)
    new = (travel + v * h, reversal, direction,
           *tuple(maxwell_step(state[3 + i], stiffness[i], decays[i], v, h) for i in range(ELEMENTS)))
    if not math.isfinite(new[0] + sum(new[3 + i] for i in range(ELEMENTS))):
        return new, 1, NOT_FINITE
    return new, 1, OK


def derivatives(m, state, x, v):
    """(d travel/dt, 0, 0, df_j/dt ...) [mm/s, N/s, 1/s, N/s ...] (model exchange)."""
    k0, k3, limit, half_travel, stiffness, rates, dashpot = m
    return (v, 0.0, 0.0, *tuple(stiffness[i] * v - rates[i] * state[3 + i] for i in range(ELEMENTS)))


def switches(m, state, x, v):
    """v [mm/s]: where it changes sign the friction reverses."""
    return (v,)


# ---------------------------------------------------------------------------- coupled kernels
# On a displacement vector (3-vectors), as Berg's coupled model (berg_model): the radial progressive
# spring, the vector friction, and each Maxwell element of the spectrum and the upper tail's dashpot
# on each component. The state is (travel d, F_s, f_0, ..., f_MODES), 3-vectors: element j's
# component c at 6 + 3*j + c.
COUPLED_SIZE = 6 + 3 * ELEMENTS


def initial_state_coupled(m, x0):
    """At rest at x0: no travel since a reversal, no friction or relaxation force."""
    return tuple(0.0 for i in range(COUPLED_SIZE))


def force_coupled(m, state, x, v):
    """F = (k0 + k3*|x|^2)*x + F_f + (the Maxwell forces) + (upper tail)*v [N], a 3-vector."""
    k0, k3, limit, half_travel, stiffness, rates, dashpot = m
    r2 = vector_dot(x, x)
    friction = vector_friction_force(limit, half_travel, (state[0], state[1], state[2]), (state[3], state[4], state[5]))
    return tuple(k0 * x[c] + k3 * r2 * x[c] + friction[c] + sum(state[6 + 3 * i + c] for i in range(ELEMENTS))
                 + dashpot * v[c] for c in range(3))


def update_coupled(m, state, x, v):
    """At an event (d.v changed sign): the friction reverses where v shortens the travel."""
    k0, k3, limit, half_travel, stiffness, rates, dashpot = m
    travel, reversal = vector_friction_turn(limit, half_travel, (state[0], state[1], state[2]),
                                            (state[3], state[4], state[5]), v)
    return (travel[0], travel[1], travel[2], reversal[0], reversal[1], reversal[2],
            *tuple(state[i] for i in range(6, COUPLED_SIZE)))


def jump_coupled(m, state, jump):
    """A displacement jump (a 3-vector): a reversal first where it shortens the travel (and is more
    than rounding), then the friction travels it and the Maxwell springs take it."""
    k0, k3, limit, half_travel, stiffness, rates, dashpot = m
    travel, reversal = vector_friction_jump_turn(limit, half_travel, (state[0], state[1], state[2]),
                                                 (state[3], state[4], state[5]), jump)
    return (*tuple(travel[c] + jump[c] for c in range(3)), reversal[0], reversal[1], reversal[2],
            *tuple(state[i] + stiffness[(i - 6) // 3] * jump[(i - 6) % 3] for i in range(6, COUPLED_SIZE))), OK


def integrate_coupled(ms, state, x, v, h, max_substeps):
    """Over the step x + v*t (``ms`` = ``prepare_step(m, h)``): a reversal at its start where v
    shortens the travel, the travel grows by v*h and every Maxwell force follows exactly; returns
    (state, 1, status)."""
    m, decays = ms
    k0, k3, limit, half_travel, stiffness, rates, dashpot = m
    travel, reversal = vector_friction_turn(limit, half_travel, (state[0], state[1], state[2]),
                                            (state[3], state[4], state[5]), v)
    new = (*tuple(travel[c] + v[c] * h for c in range(3)), reversal[0], reversal[1], reversal[2],
           *tuple(maxwell_step(state[i], stiffness[(i - 6) // 3], decays[(i - 6) // 3], v[(i - 6) % 3], h)
                  for i in range(6, COUPLED_SIZE)))
    if not math.isfinite(sum(new[i] for i in range(COUPLED_SIZE))):
        return new, 1, NOT_FINITE
    return new, 1, OK


def derivatives_coupled(m, state, x, v):
    """(dd/dt, 0, df_j/dt ...), 3-vectors each (model exchange)."""
    k0, k3, limit, half_travel, stiffness, rates, dashpot = m
    return (v[0], v[1], v[2], 0.0, 0.0, 0.0,
            *tuple(stiffness[(i - 6) // 3] * v[(i - 6) % 3] - rates[(i - 6) // 3] * state[i]
                   for i in range(6, COUPLED_SIZE)))


def switches_coupled(m, state, x, v):
    """d.v [mm^2/s]: where it turns negative the friction reverses."""
    return (vector_dot((state[0], state[1], state[2]), v),)


SEARCH = SearchBox(
    (SearchCoordinate("k0", KIND.stiffness, -3.0, 1.0), SearchCoordinate("k3", KIND.cubic, 0.0, 2.0),
     SearchCoordinate("Ff_max", KIND.force, -3.0, 0.5), SearchCoordinate("x2", KIND.travel, -4.0, 0.5),
     SearchCoordinate("alpha", KIND.exponent, 0.02, 0.98), SearchCoordinate("b", KIND.power_law, -4.0, 3.0,
                                                                         exponent="alpha")),
    loop_start=SlowLoop(("k0", "k3"), "Ff_max", "x2", (("b", 0.0), ("alpha", 0.5))))
"""The fit's box: as Berg's for the spring and the friction; alpha within (0.02, 0.98) and b as
log10(b/(k_ref*tau_ref^alpha)), the element's |K*| at the data's own time scale in units of k_ref;
the spring and the friction have starts from the data's slowest loop (identification/fitting/loop_start.py)."""


def _mode_states():
    rates = [math.exp(LOG_LOWEST_RATE + i * LOG_RATE_STEP) for i in range(MODES)]
    return tuple(StateSpec(f"f{i}", 3 + i, "N", f"force of the relaxation mode of rate {rate:.3g} 1/s")
                 for i, rate in enumerate(rates)) + \
        (StateSpec(f"f{MODES}", 3 + MODES, "N", "force of the relaxation modes below 1e-4 1/s (one element)"),)


MODEL = BushingModel(
    "fractional", "FractionalBushing", "fractional derivative with friction (Sjoberg-Kari)", PARAMETER_SPECS,
    (StateSpec("travel", 0, "m", "travel since the friction's last reversal, x - x_s"),
     StateSpec("F_s", 1, "N", "friction force at the last reversal"),
     StateSpec("direction", 2, "1", "direction of the motion since the last reversal (+1, -1; 0 at rest)"))
    + _mode_states(),
    "params_fractional_filled_rubber.json", prepare, initial_state, jump, integrate, force,
    derivatives, switches, update=update,
    switch_specs=(StateSpec("v", 0, "m/s", "the velocity input: where it changes sign the friction reverses"),),
    search=SEARCH, plot_style=("C5", "-"), rank=40,
    coupled=CoupledKernels(
        COUPLED_STATES + tuple(StateSpec(spec.name, 2 + i, "N", spec.meaning) for i, spec in enumerate(_mode_states())),
        initial_state_coupled, jump_coupled, integrate_coupled, force_coupled, derivatives_coupled, switches_coupled,
        (StateSpec("dv", 0, "m2/s", "d.v: where it turns negative the friction reverses"),), update=update_coupled),
    static_spring=("k0", "k3"))
