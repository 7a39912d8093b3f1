"""The linear bushing of ADAMS/RecurDyn, one axis: F = k*x + c*dx/dt + preload.

Algebraic: no state, nothing to integrate. Units: k in N/mm, c in N.s/mm, preload in N.
"""
from __future__ import annotations

from ..model.parameter_specs import DAMPING, SPRING, ParameterSpec
from ..model.integration import OK
from ..model.definition import BushingModel, LinearForce

PARAMETER_SPECS = (
    ParameterSpec("k", "N/mm", "stiffness", **SPRING),
    ParameterSpec("c", "N.s/mm", "viscous damping", **DAMPING),
    ParameterSpec("preload", "N", "force at x = 0", temperature="none"),
)


def prepare(p):
    """(k, c, preload) in ``PARAMETER_SPECS`` order."""
    k, c, preload = p
    return (k, c, preload)


def initial_state(m, x0):
    return ()


def force(m, state, x, v):
    """F = k*x + c*v + preload [N]."""
    k, c, preload = m
    return k * x + c * v + preload


def jump(m, state, jump_mm):
    return state, OK


def integrate(m, state, x, v, h, max_substeps):
    return state, 0, OK


def derivatives(m, state, x, v):
    """No state: nothing to integrate."""
    return ()


def switches(m, state, x, v):
    return ()


MODEL = BushingModel(
    "kelvin_voigt", "KelvinVoigtBushing", "Kelvin-Voigt (linear)", PARAMETER_SPECS, (),
    "params_kelvin_voigt_fit_synthetic_table5.json", prepare, initial_state, jump, integrate, force,
    derivatives, switches, plot_style=("C3", "--"), rank=90,
    linear=LinearForce((("k", "displacement"), ("c", "velocity")), held=(("preload", 0.0),)),
    static_spring=("k",))
