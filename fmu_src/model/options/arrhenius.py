"""``arrhenius``: a temperature law with the Arrhenius shift, the law of a thermally activated
process (a rubber's relaxation well above its glass transition, a fluid's viscosity): at the
rubber's temperature T [K] every rate-dependent parameter of the model is multiplied by

    a_T = exp(arrhenius_K (1/T - 1/T_ref)),    arrhenius_K = E_a / R [K]

(E_a the activation energy [J/mol], R = 8.314 J/(mol K): 100 kJ/mol is 12 000 K), every stiffness
and static force by the elastic factor and every sliding level by the friction factor
(``temperature_law``), as ``wlf`` does with its shift. At T = T_ref every factor is 1.0 exactly.
The temperature is a test's own, as with ``wlf``; a model takes one law (the two share their
parameters' names)."""
from __future__ import annotations

from ..definition import SearchCoordinate
from ..parameter_specs import ParameterSpec
from ..search_coordinates import KIND
from .element import OptionElement
from .temperature_law import (CONDITIONS, HELD, NEUTRAL, ROLES, coefficient_coordinates, coefficient_specs,
                              factor_lines, temperature_specs)

ARRHENIUS = "arrhenius"


def arrhenius_specs(count: int = 0) -> tuple[ParameterSpec, ...]:
    return (temperature_specs()
            + (ParameterSpec("arrhenius_K", "K", "the Arrhenius shift's activation temperature E_a/R: "
                             "a_T = exp(it (1/T - 1/T_ref))", minimum=0.0,
                             why="a rate's time scale shortens as the rubber warms", temperature="none"),)
            + coefficient_specs())


def arrhenius_coordinates(count: int) -> tuple[SearchCoordinate, ...]:
    return (SearchCoordinate("arrhenius_K", KIND.value, 0.0, 40000.0),) + coefficient_coordinates()


def arrhenius_law(p: tuple[str, ...]) -> tuple[tuple[str, ...], dict[str, str]]:
    """Source lines of the three factors from the law's parameters' texts ``p`` (specs' order)."""
    temperature, reference, activation, elastic, friction = p
    return factor_lines("arrhenius", temperature, reference,
                        f"math.exp({activation} * (1.0 / {temperature} - 1.0 / {reference}))", elastic, friction)


ELEMENT = OptionElement(
    token=ARRHENIUS, word="an Arrhenius temperature law", order=96, usage=ARRHENIUS, specs=arrhenius_specs,
    coordinates=arrhenius_coordinates, law=arrhenius_law, conditions=CONDITIONS, prepare=lambda p: "()", held=HELD,
    law_roles=(("arrhenius_K", "viscous"),) + ROLES,
    neutral=NEUTRAL + (("arrhenius_K", 0.0),))
