"""``heating``: self-heating, a thermal state for a model with a temperature law (``wlf``,
``arrhenius``): the rubber's temperature ``rubber_temperature`` T [K] rises with the power the
model takes from the motion and falls towards the surroundings' temperature T_amb (the law's
``temperature``, then the surroundings'), and the law takes T instead of it at every step:

    thermal_capacity dT/dt = P - (T - T_amb) / thermal_resistance,    P = F v  [W]

``thermal_capacity`` C_th [J/K] (the rubber's mass times its specific heat: 0.3 kg at about
1.8 kJ/(kg K) is 540 J/K), ``thermal_resistance`` R_th [K/W] (from the rubber to the
surroundings; C_th R_th is the time constant). P is the power the motion puts in, F v: over a
cycle the work of the loop, which the model's dissipative elements turn into heat; within a cycle
it also carries the springs' stored energy back and forth, a swing of at most its stored energy
over C_th (a 150 N/mm bushing at 3 mm stores 0.7 J: 1.3 mK at 540 J/K), which the heat's time
scale never sees. Over a step of constant velocity P is the trapezoid of F v and T follows the
cooling law exactly: T1 = T_amb + (T0 - T_amb) e^(-h/tau) + P R_th (1 - e^(-h/tau)).

The run starts at T = T_amb. Both FMUs show the state ``rubber_temperature`` [K]."""
from __future__ import annotations

from ..definition import SearchCoordinate
from ..parameter_specs import ParameterSpec
from ..search_coordinates import KIND
from .element import ElementState, OptionElement

HEATING = "heating"


def heating_specs(count: int = 0) -> tuple[ParameterSpec, ...]:
    return (ParameterSpec("thermal_capacity", "J/K", "the rubber's heat capacity (mass times specific heat)",
                          minimum=0.0, exclusive=True, why="a body without heat capacity has no temperature of its "
                          "own", temperature="none"),
            ParameterSpec("thermal_resistance", "K/W", "the thermal resistance from the rubber to the surroundings",
                          minimum=0.0, exclusive=True, why="a resistance of 0 holds the rubber at the surroundings' "
                          "temperature: leave the option out", temperature="none"))


def heating_coordinates(count: int) -> tuple[SearchCoordinate, ...]:
    return (SearchCoordinate("thermal_capacity", KIND.value, 10.0, 1e5),
            SearchCoordinate("thermal_resistance", KIND.value, 0.01, 100.0))


ELEMENT = OptionElement(
    token=HEATING, word="self-heating", order=97, usage=HEATING, specs=heating_specs,
    coordinates=heating_coordinates, heating=True,
    states=lambda count: (ElementState("rubber_temperature", "K", "the rubber's temperature, heated by the "
                                                                   "motion's power and cooled towards the "
                                                                   "surroundings'"),),
    held=(("thermal_capacity", 540.0), ("thermal_resistance", 1.0)))
