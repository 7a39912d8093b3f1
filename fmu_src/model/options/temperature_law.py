"""What the temperature laws (``wlf``, ``arrhenius``) share: the rubber's temperature and the
reference as parameters (a test's own temperature sets the first: ``OptionElement.conditions``),
the exponential coefficients of the stiffnesses and the sliding levels, and the source lines of
their factors. Each law module adds its time-temperature shift a_T.

    elastic factor  = exp(elastic_per_K (T - T_ref))
    friction factor = exp(friction_per_K (T - T_ref))

At T = T_ref every factor is 1.0 exactly: the model is its base bit for bit.
"""
from __future__ import annotations

from ..definition import SearchCoordinate
from ..parameter_specs import ParameterSpec
from ..search_coordinates import KIND

RUBBER_RANGE_K = (173.15, 473.15)
"""-100 to +200 degC: the temperatures a rubber element's law is taken at."""
REFERENCE_K = 296.15
"""23 degC: the reference temperature and the temperature a fit holds where the tests say none."""
CONDITIONS = (("temperature", "temperature_K"),)
"""The parameter a test's own temperature sets (``Measurement.temperature_K``, its mean)."""
HELD = (("temperature", REFERENCE_K), ("temperature_ref", REFERENCE_K))
"""What a fit holds unless told: the temperature (each test's own replaces it) and the reference."""

_RANGE = dict(minimum=RUBBER_RANGE_K[0], maximum=RUBBER_RANGE_K[1], why="a rubber's service range, -100 to +200 degC")


def temperature_specs() -> tuple[ParameterSpec, ...]:
    return (ParameterSpec("temperature", "K", "the rubber's temperature (a test's own sets it)", temperature="none",
                          **_RANGE),
            ParameterSpec("temperature_ref", "K", "the temperature law's reference: the base's parameters hold there",
                          temperature="none", **_RANGE))


def coefficient_specs() -> tuple[ParameterSpec, ...]:
    return (ParameterSpec("elastic_per_K", "1/K", "the stiffnesses' relative change per kelvin (exponential; "
                          "negative: softer when warm)", temperature="none"),
            ParameterSpec("friction_per_K", "1/K", "the sliding levels' relative change per kelvin (exponential)",
                          temperature="none"))


def coefficient_coordinates() -> tuple[SearchCoordinate, ...]:
    return (SearchCoordinate("elastic_per_K", KIND.value, -0.03, 0.03),
            SearchCoordinate("friction_per_K", KIND.value, -0.03, 0.03))


def factor_lines(prefix: str, temperature: str, reference: str, shift: str, elastic: str, friction: str):
    """The law's source lines (names ``<prefix>_dT``, ``<prefix>_shift`` ...) and each role's
    factor: ``shift`` the text of a_T in ``<prefix>_dT`` [K] (and the parameters' texts)."""
    lines = (f"{prefix}_dT = {temperature} - {reference}",
             f"{prefix}_shift = {shift}",
             f"{prefix}_elastic = math.exp({elastic} * {prefix}_dT)",
             f"{prefix}_friction = math.exp({friction} * {prefix}_dT)")
    return lines, {"viscous": f"{prefix}_shift", "elastic": f"{prefix}_elastic", "friction": f"{prefix}_friction"}


ROLES = (("elastic_per_K", "elastic"), ("friction_per_K", "friction"))
"""The coefficients' roles (``OptionElement.law_roles``)."""

# the law off: every factor 1 at the reference
NEUTRAL = (("temperature", REFERENCE_K), ("temperature_ref", REFERENCE_K), ("elastic_per_K", 0.0),
           ("friction_per_K", 0.0))
