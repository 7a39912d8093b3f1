"""``wlf``: a temperature law (time-temperature superposition with the Williams-Landel-Ferry
shift): at the rubber's temperature ``temperature`` T [K] every rate-dependent parameter of the
model (a dashpot [N.s/mm], a Maxwell element's dashpot, a limit's damping) is multiplied by the
shift a_T, every stiffness and static force by an elastic factor and every sliding level [N] by a
friction factor:

    log10 a_T = -wlf_c1 (T - T_ref) / (wlf_c2 + T - T_ref)
    elastic factor  = exp(elastic_per_K (T - T_ref))
    friction factor = exp(friction_per_K (T - T_ref))

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

WLF = "wlf"
LN10 = 2.302585092994046
"""ln 10: a_T = exp(-ln10 C1 dT / (C2 + dT)), C1 in decades."""
RUBBER_RANGE_K = (173.15, 473.15)
"""-100 to +200 degC: the temperatures a rubber element's law is taken at."""
REFERENCE_K = 296.15
"""23 degC: the reference temperature and the temperature a fit holds where the tests say none."""

_RANGE = dict(minimum=RUBBER_RANGE_K[0], maximum=RUBBER_RANGE_K[1], why="a rubber's service range, -100 to +200 degC")


def wlf_specs(count: int = 0) -> tuple[ParameterSpec, ...]:
    return (ParameterSpec("temperature", "K", "the rubber's temperature (a test's own sets it)", temperature="none",
                          **_RANGE),
            ParameterSpec("temperature_ref", "K", "the temperature law's reference: the base's parameters hold there",
                          temperature="none", **_RANGE),
            ParameterSpec("wlf_c1", "1", "the WLF shift's C1 [decades]: log10 a_T = -C1 dT / (C2 + dT)",
                          minimum=0.0, why="a rate's time scale shortens as the rubber warms", temperature="none"),
            ParameterSpec("wlf_c2", "K", "the WLF shift's C2", minimum=0.0, exclusive=True,
                          why="the shift's singular point lies below the reference", temperature="none"),
            ParameterSpec("elastic_per_K", "1/K", "the stiffnesses' relative change per kelvin (exponential; "
                          "negative: softer when warm)", temperature="none"),
            ParameterSpec("friction_per_K", "1/K", "the sliding levels' relative change per kelvin (exponential)",
                          temperature="none"))


def wlf_constraints(count: int = 0) -> tuple[Constraint, ...]:
    return (Constraint((("wlf_c2", 1.0), ("temperature", 1.0), ("temperature_ref", -1.0)), 0.0, True, True, "K",
                       "the WLF shift is singular at C2 + T - T_ref = 0 and undefined below"),)


def wlf_coordinates(count: int) -> tuple[SearchCoordinate, ...]:
    return (SearchCoordinate("wlf_c1", KIND.value, 0.0, 30.0),
            SearchCoordinate("wlf_c2", KIND.value, 60.0, 600.0),
            SearchCoordinate("elastic_per_K", KIND.value, -0.03, 0.03),
            SearchCoordinate("friction_per_K", KIND.value, -0.03, 0.03))


def wlf_law(p: tuple[str, ...]) -> tuple[tuple[str, ...], dict[str, str]]:
    """Source lines of the three factors from the law's parameters' texts ``p`` (specs' order)."""
    temperature, reference, c1, c2, elastic, friction = p
    lines = (f"wlf_dT = {temperature} - {reference}",
             f"wlf_shift = math.exp(-{LN10!r} * {c1} * wlf_dT / ({c2} + wlf_dT))",
             f"wlf_elastic = math.exp({elastic} * wlf_dT)",
             f"wlf_friction = math.exp({friction} * wlf_dT)")
    return lines, {"viscous": "wlf_shift", "elastic": "wlf_elastic", "friction": "wlf_friction"}


ELEMENT = OptionElement(
    token=WLF, word="a WLF temperature law", order=95, usage=WLF, specs=wlf_specs, coordinates=wlf_coordinates,
    constraints=wlf_constraints, law=wlf_law, conditions=(("temperature", "temperature_K"),),
    prepare=lambda p: "()",
    held=(("temperature", REFERENCE_K), ("temperature_ref", REFERENCE_K)),
    # the law off: every factor 1 at the reference (C2 any value the box holds)
    neutral=(("temperature", REFERENCE_K), ("temperature_ref", REFERENCE_K), ("wlf_c1", 0.0), ("wlf_c2", 100.0),
             ("elastic_per_K", 0.0), ("friction_per_K", 0.0)))
