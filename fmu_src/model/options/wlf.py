"""``wlf``: a temperature law (time-temperature superposition with the Williams-Landel-Ferry
shift): at the rubber's temperature ``temperature`` T [K] every rate-dependent parameter of the
model (a dashpot [N.s/mm], a Maxwell element's dashpot, a limit's damping) is multiplied by the
shift a_T, every stiffness and static force by an elastic factor and every sliding level [N] by a
friction factor (``temperature_law``):

    log10 a_T = -wlf_c1 (T - T_ref) / (wlf_c2 + T - T_ref)

``temperature_ref`` T_ref [K] is the reference: at T = T_ref every factor is 1.0 exactly and the
model is its base bit for bit. Which parameter takes which factor its spec says
(``ParameterSpec.temperature_role``, by its unit unless its module says otherwise: N.s/mm viscous,
N/mm elastic, N friction; a displacement, an exponent or a Bouc-Wen shape none). A dashpot's time
constant c/k so shifts by a_T over the elastic factor; a Maxwell element's relaxation by the same.

The temperature is a condition, not a constant of the device: a test's own (a measurement's
``temperature_K``, its mean) sets it in fit, predict and compare, and an FMU takes it as a tunable
parameter (set at initialisation or between steps). Units: K, 1/K; C1 is a number of decades.
"""
from __future__ import annotations

from ..definition import SearchCoordinate
from ..parameter_specs import Constraint, ParameterSpec
from ..search_coordinates import KIND
from .element import OptionElement
from .temperature_law import (CONDITIONS, HELD, NEUTRAL, ROLES, coefficient_coordinates, coefficient_specs,
                              factor_lines, temperature_specs)

WLF = "wlf"
LN10 = 2.302585092994046
"""ln 10: a_T = exp(-ln10 C1 dT / (C2 + dT)), C1 in decades."""


def wlf_specs(count: int = 0) -> tuple[ParameterSpec, ...]:
    return (temperature_specs()
            + (ParameterSpec("wlf_c1", "1", "the WLF shift's C1 [decades]: log10 a_T = -C1 dT / (C2 + dT)",
                             minimum=0.0, why="a rate's time scale shortens as the rubber warms", temperature="none"),
               ParameterSpec("wlf_c2", "K", "the WLF shift's C2", minimum=0.0, exclusive=True,
                             why="the shift's singular point lies below the reference", temperature="none"))
            + coefficient_specs())


def wlf_constraints(count: int = 0) -> tuple[Constraint, ...]:
    return (Constraint((("wlf_c2", 1.0), ("temperature", 1.0), ("temperature_ref", -1.0)), 0.0, True, True, "K",
                       "the WLF shift is singular at C2 + T - T_ref = 0 and undefined below"),)


def wlf_coordinates(count: int) -> tuple[SearchCoordinate, ...]:
    return (SearchCoordinate("wlf_c1", KIND.value, 0.0, 30.0),
            SearchCoordinate("wlf_c2", KIND.value, 60.0, 600.0)) + coefficient_coordinates()


def wlf_law(p: tuple[str, ...]) -> tuple[tuple[str, ...], dict[str, str]]:
    """Source lines of the three factors from the law's parameters' texts ``p`` (specs' order)."""
    temperature, reference, c1, c2, elastic, friction = p
    return factor_lines("wlf", temperature, reference, f"math.exp(-{LN10!r} * {c1} * wlf_dT / ({c2} + wlf_dT))",
                        elastic, friction)


ELEMENT = OptionElement(
    token=WLF, word="a WLF temperature law", order=95, usage=WLF, specs=wlf_specs, coordinates=wlf_coordinates,
    constraints=wlf_constraints, law=wlf_law, conditions=CONDITIONS, prepare=lambda p: "()", held=HELD,
    law_roles=(("wlf_c1", "viscous"), ("wlf_c2", "viscous")) + ROLES,
    # the law off: every factor 1 at the reference (C2 any value the box holds)
    neutral=NEUTRAL + (("wlf_c1", 0.0), ("wlf_c2", 100.0)))
