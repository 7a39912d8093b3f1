"""``limits``: a travel limit on each side (``elements.limit_force``): a gap ``limit_gap_pos``,
``limit_gap_neg`` [mm] (free play: no force inside it), then a stiffness ``limit_k_*`` [N/mm^e]
with an exponent ``limit_exponent_*`` >= 1 and a damping ``limit_c_*`` [N.s/mm] that ramps in over
``limit_depth_*`` [mm], the corners rounded over ``limit_width`` [mm] (0: hard corners, stated as
switches), as MSC Adams' bushing limits, Altair's mount limits and RecurDyn's clearance describe
them."""
from __future__ import annotations

from ..definition import SearchCoordinate
from ..parameter_specs import ParameterSpec
from ..search_coordinates import KIND
from .element import ElementState, OptionElement

LIMITS = "limits"
LIMIT_SIDES = (("pos", "positive"), ("neg", "negative"))
LIMIT_HELD = (("limit_exponent_pos", 2.0), ("limit_exponent_neg", 2.0), ("limit_c_pos", 0.0), ("limit_c_neg", 0.0),
              ("limit_depth_pos", 1.0), ("limit_depth_neg", 1.0))
"""What a fit holds of the limits unless told otherwise (``fit(fixed=...)``): a quadratic stop
(exponent 2), no damping (so the depth is immaterial)."""


def limit_specs(count: int = 0) -> tuple[ParameterSpec, ...]:
    out = []
    for side, word in LIMIT_SIDES:
        out += [
            ParameterSpec(f"limit_gap_{side}", "mm", f"the {word} travel limit's gap: free travel before it engages",
                          minimum=0.0, why="a gap is a magnitude"),
            ParameterSpec(f"limit_k_{side}", "N/mm^e", f"the {word} limit's stiffness: force k*d^e at penetration d "
                          "[mm], e its exponent", minimum=0.0, why="a negative stiffness is unstable", bound_powers=None),
            ParameterSpec(f"limit_exponent_{side}", "1", f"the {word} limit's exponent e (1: linear, 2: a "
                          "progressive bump stop)", minimum=1.0, why="below 1 its stiffness is infinite at contact"),
            ParameterSpec(f"limit_c_{side}", "N.s/mm", f"the {word} limit's damping, fully in at the depth",
                          minimum=0.0, why="a negative dashpot adds energy"),
            ParameterSpec(f"limit_depth_{side}", "mm", f"the penetration over which the {word} limit's damping "
                          "ramps in", minimum=0.0, exclusive=True, why="a ramp needs a length"),
        ]
    out.append(ParameterSpec("limit_width", "mm", "the travel over which each limit's corner engages (0: hard "
                             "corners)", minimum=0.0, why="a width is a magnitude"))
    return tuple(out)


def limit_coordinates(count: int) -> tuple[SearchCoordinate, ...]:
    coordinates = ()
    for side, _ in LIMIT_SIDES:
        coordinates += (SearchCoordinate(f"limit_gap_{side}", KIND.travel, -3.0, 0.3),
                        SearchCoordinate(f"limit_k_{side}", KIND.stiffness, -2.0, 3.0))
    return coordinates + (SearchCoordinate("limit_width", KIND.travel, -4.0, -1.0),)


LIMITS_SOURCE = '''def limits_force(c, u, v):
    """Both travel limits' force [N] at u [mm], v [mm/s]; c = (gap, k, exponent, damping, depth)
    of the positive side, then of the negative, then the width."""
    gp, kp, ep, cp, dp, gn, kn, en, cn, dn, width = c
    return limit_force(u, v, gp, kp, ep, cp, dp, width) - limit_force(-u, -v, gn, kn, en, cn, dn, width)
'''

ELEMENT = OptionElement(
    token=LIMITS, word="travel limits", order=20, usage=LIMITS, specs=limit_specs, coordinates=limit_coordinates,
    helpers=lambda count: LIMITS_SOURCE, shared=frozenset({"limit_force"}),
    force=lambda slot: f"limits_force({slot.m}, u, v)",
    rest_force=lambda slot: f"limits_force({slot.m}, u, 0.0)",
    switches=lambda count: (ElementState("limit_upper", "m", "u - limit_gap_pos: the positive limit's corner"),
                            ElementState("limit_lower", "m", "u + limit_gap_neg: the negative limit's corner")),
    switch_values=lambda slot: (f"u - {slot.m}[0]", f"u + {slot.m}[5]"),
    held=LIMIT_HELD,
    neutral=(("limit_gap_pos", 1.0), ("limit_gap_neg", 1.0), ("limit_k_pos", 0.0), ("limit_k_neg", 0.0),
             ("limit_exponent_pos", 2.0), ("limit_exponent_neg", 2.0), ("limit_c_pos", 0.0), ("limit_c_neg", 0.0),
             ("limit_depth_pos", 1.0), ("limit_depth_neg", 1.0), ("limit_width", 0.0)))
