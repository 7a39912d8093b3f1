"""``band``: a band brake's friction through its play: a contact with free play whose stiffness
rises over a depth (a progressive engagement), in series with a slider whose level grows with the
travel into the contact and is released when the contact unloads (self-energizing friction: the
capstan effect of a band that wraps on its drum as the drum drags it).

Its parameters (N-mm-s):

- ``band_gap`` [mm]: half the play, the free travel each side of its centre;
- ``band_k`` [N/mm]: the contact's stiffness once fully engaged;
- ``band_depth`` [mm]: the engagement over which the contact's stiffness rises linearly from 0 to
  ``band_k`` (0: a linear contact), so the contact force at an engagement a beyond the gap is
  k a^2/(2 depth) for a < depth and k (a - depth/2) beyond;
- ``band_f`` [N]: the slider's level as a side engages (Coulomb's friction);
- ``band_ratio_pos``, ``band_ratio_neg`` [1]: how many times that the level grows to over the
  travel ``band_travel`` [mm] into the positive or the negative side (the capstan's
  e^(mu*theta) once the wrap is full); the level a travel s after a side engaged is
  band_f * ratio^(min(s, band_travel)/band_travel); with ``band_travel`` = 0 it is band_f * ratio
  at once (a band brake's two levels, the energized way and the released way).

Limit cases: ratios 1 is Coulomb's friction through a play (gap 0 and depth 0: a Jenkins element,
``iwan1``); ratios above 1 with travel 0 is the classical self-energizing band brake; a level
beyond reach is the play alone, an elastic contact either side of a free travel.

Its states: ``band_engagement`` [mm] (the displacement less the play's centre: the contact
force's argument; 0 at the start, the play centred where the record starts) and
``band_travel_since`` [mm] (the travel into the engaged side since it engaged, signed as the side:
the motion into it counts, a motion back out short of the play leaves it, so a small reversal
under load keeps the level; 0 in the play, where the band is released). The force never jumps: a
reversal unloads the contact elastically.

Each step takes the engagement's trial e + v h and clips it where the contact force meets its
side's level at the step's end: exact where the level grows more slowly with the travel than the
contact's force does (its slope; always with ratios 1), else first order in the step. In model
exchange the engagement rises at v until the contact meets the level, then at the rate the growing
level lets it (the state ``band_sliding`` [1] says which); the play's edges (``band_upper``,
``band_lower``), the slip's start and end (``band_slip``: a reversal, or the level outgrowing the
contact) and the full wrap (``band_wrap``, where the level stops growing) are switches, whose
events release the band in the play and start and stop the slide. At the neutral values (no
contact, no level) the slip's switch is 0 throughout and never fires.
"""
from __future__ import annotations

from ..definition import SearchCoordinate
from ..parameter_specs import ParameterSpec
from ..search_coordinates import KIND
from .element import ElementState, OptionElement, Step

BAND = "band"


def band_specs(count: int = 0) -> tuple[ParameterSpec, ...]:
    return (
        ParameterSpec("band_gap", "mm", "the band's play: half its free travel, each side of its centre",
                      minimum=0.0, why="a gap is a magnitude"),
        ParameterSpec("band_k", "N/mm", "the band's contact stiffness once fully engaged", minimum=0.0,
                      why="a negative stiffness is unstable"),
        ParameterSpec("band_depth", "mm", "the engagement over which the band's contact stiffness rises from 0 "
                      "to band_k (0: a linear contact)", minimum=0.0, why="a depth is a magnitude"),
        ParameterSpec("band_f", "N", "the band's sliding level as a side engages", minimum=0.0,
                      why="a friction level is a magnitude", bound_powers=(0, 0)),
        ParameterSpec("band_ratio_pos", "1", "how many times band_f the level grows to over band_travel "
                      "moving the positive way (the capstan's exp(mu*theta); 1: Coulomb)", minimum=1.0,
                      why="below 1 the band would release as it wraps"),
        ParameterSpec("band_ratio_neg", "1", "how many times band_f the level grows to over band_travel "
                      "moving the negative way", minimum=1.0, why="below 1 the band would release as it wraps"),
        ParameterSpec("band_travel", "mm", "the travel into an engaged side over which the level grows to its "
                      "ratio (0: at once)", minimum=0.0, why="a travel is a magnitude"),
    )


def band_coordinates(count: int) -> tuple[SearchCoordinate, ...]:
    return (SearchCoordinate("band_gap", KIND.travel, -3.0, 0.3),
            SearchCoordinate("band_k", KIND.stiffness, -2.0, 3.0),
            SearchCoordinate("band_depth", KIND.travel, -3.0, 0.0),
            SearchCoordinate("band_f", KIND.force, -3.0, 0.5),
            SearchCoordinate("band_ratio_pos", KIND.exponent, 1.0, 5.0),
            SearchCoordinate("band_ratio_neg", KIND.exponent, 1.0, 5.0),
            SearchCoordinate("band_travel", KIND.travel, -3.0, 0.5))


BAND_SOURCE = '''def band_contact(c, e):
    \"\"\"The band's contact force [N] at an engagement e [mm] (c its prepared constants): 0 in the
    play, then a stiffness rising from 0 to k over the depth, then k.\"\"\"
    gap, k, depth, f, ratio_pos, ratio_neg, travel = c
    a = abs(e) - gap
    if a <= 0.0:
        return 0.0
    if a < depth:
        g = k * a * a / (2.0 * depth)
    else:
        g = k * (a - 0.5 * depth)
    if e < 0.0:
        return -g
    return g


def band_slope(c, e):
    \"\"\"d band_contact/de [N/mm] at e.\"\"\"
    gap, k, depth, f, ratio_pos, ratio_neg, travel = c
    a = abs(e) - gap
    if a <= 0.0:
        return 0.0
    if a < depth:
        return k * a / depth
    return k


def band_travel_on(travel_since, side):
    \"\"\"The travel [mm] into the side of side's sign: travel_since (signed: its sign the engaged
    side's) where it belongs to that side, else 0.\"\"\"
    if (travel_since > 0.0) != (side > 0.0):
        return 0.0
    return abs(travel_since)


def band_level(c, travel_since, side):
    \"\"\"The slider's level [N] on the side of side's sign, travel_since [mm] (signed) after that
    side engaged: band_f on a side the travel does not belong to.\"\"\"
    gap, k, depth, f, ratio_pos, ratio_neg, travel = c
    ratio = ratio_pos if side > 0.0 else ratio_neg
    s = band_travel_on(travel_since, side)
    if s >= travel:
        return f * ratio
    return f * math.exp(math.log(ratio) * s / travel)


def band_level_rate(c, travel_since, side):
    \"\"\"d band_level/d travel [N/mm]: 0 once the level has grown to its ratio.\"\"\"
    gap, k, depth, f, ratio_pos, ratio_neg, travel = c
    if band_travel_on(travel_since, side) >= travel:
        return 0.0
    ratio = ratio_pos if side > 0.0 else ratio_neg
    return band_level(c, travel_since, side) * math.log(ratio) / travel


def band_reach(c, level):
    \"\"\"The engagement's size [mm] at which the contact force is level [N] (k > 0).\"\"\"
    gap, k, depth, f, ratio_pos, ratio_neg, travel = c
    if level < 0.5 * k * depth:
        return gap + math.sqrt(2.0 * depth * level / k)
    return gap + level / k + 0.5 * depth


def band_travel_after(c, e, travel_since, trial):
    \"\"\"The travel [mm] into the engaged side once the engagement e moves to trial [mm], signed as
    the side: 0 in the play; from the play's edge where a side engages anew; grown by the motion
    into it (a motion back out, short of the play, leaves it) where the same side stays engaged.\"\"\"
    gap = c[0]
    if abs(trial) <= gap:
        return 0.0
    if abs(e) > gap and (e > 0.0) == (trial > 0.0):
        if trial > 0.0:
            return travel_since + max(trial - e, 0.0)
        return travel_since - max(e - trial, 0.0)
    if trial > 0.0:
        return trial - gap
    return trial + gap


def band_slide(c, trial, travel_since):
    \"\"\"The engagement [mm] once the slider has slid where the contact force at trial [mm] passes
    the level of its side (a travel_since [mm] after that side engaged).\"\"\"
    gap, k, depth, f, ratio_pos, ratio_neg, travel = c
    if k <= 0.0 or abs(trial) <= gap:
        return trial
    reach = band_reach(c, band_level(c, travel_since, trial))
    if trial > reach:
        return reach
    if trial < -reach:
        return -reach
    return trial


def band_rate(c, e, travel_since, sliding, v):
    \"\"\"d engagement/dt [mm/s] at v [mm/s] (model exchange): v while it sticks; while it slides
    (on into its side), the rate at which the growing level lets it grow.\"\"\"
    gap, k, depth, f, ratio_pos, ratio_neg, travel = c
    if sliding == 0.0 or k <= 0.0 or abs(e) <= gap or e * v <= 0.0:
        return v
    slope = band_slope(c, e)
    rate = band_level_rate(c, travel_since, e) * abs(v)
    if slope <= 0.0 or rate >= slope * abs(v):
        return v
    if e > 0.0:
        return rate / slope
    return -rate / slope


def band_travel_rate(c, e, v):
    \"\"\"d travel/dt [mm/s] (model exchange): the motion into the engaged side, 0 in the play.\"\"\"
    if abs(e) <= c[0] or e * v <= 0.0:
        return 0.0
    return v


def band_slip_switch(c, e, travel_since, sliding, v):
    \"\"\"The slip's switch (model exchange): while it sticks, the contact's force less its side's
    level [N] (it rises through 0 where the slider starts to slide); while it slides, the least of
    e*v [mm^2/s] (it falls through 0 where the motion turns back out of the side) and the contact's
    slope less the level's growth with the travel [N/mm] (through 0 where the level outgrows the
    contact, which then sticks).\"\"\"
    if sliding != 0.0:
        return min(e * v, band_slope(c, e) - band_level_rate(c, travel_since, e))
    return abs(band_contact(c, e)) - band_level(c, travel_since, e)


def band_wrap_switch(c, travel_since):
    \"\"\"The wrap's switch (model exchange): the travel less band_travel [mm]; where it rises
    through 0 the level stops growing (the engagement's rate while sliding falls to 0).\"\"\"
    return abs(travel_since) - c[6]


def band_sliding_after(c, e, travel_since, sliding, v):
    \"\"\"Whether it slides [1] after an event (model exchange): it starts where the contact meets
    its side's level moving on into it, with a slope the level's growth does not outrun, and stops
    where the motion turns back or the level outgrows the contact.\"\"\"
    if e * v <= 0.0 or c[1] <= 0.0 or abs(e) <= c[0]:
        return 0.0
    if band_slope(c, e) <= band_level_rate(c, travel_since, e):
        return 0.0
    if sliding != 0.0 or abs(band_contact(c, e)) >= band_level(c, travel_since, e):
        return 1.0
    return 0.0


def band_slid(trial, e):
    \"\"\"1 where the step's slide moved the engagement off its trial, else 0 [1].\"\"\"
    if e != trial:
        return 1.0
    return 0.0


def band_released(c, e, travel_since):
    \"\"\"The travel [mm] after an event (model exchange): 0 where the engagement is in the play or
    within 1e-6 mm of its edge (an edge's event is located to about that), or on the other side
    (the band released); as it was elsewhere.\"\"\"
    if abs(e) <= c[0] + 1e-6 or e * travel_since < 0.0:
        return 0.0
    return travel_since
'''


def _step(slot) -> Step:
    e, s, _ = slot.states
    m = slot.m
    lines = (f"band_s = band_travel_after({m}, {e}, {s}, {e} + v * h)",
             f"band_e = band_slide({m}, {e} + v * h, band_s)",
             f"band_m = band_slid({e} + v * h, band_e)")
    return Step(lines, ("band_e", "band_s", "band_m"))


def _jump(slot) -> tuple[str, ...]:
    e, s, _ = slot.states
    m = slot.m
    travel = f"band_travel_after({m}, {e}, {s}, {e} + jump_mm)"
    engagement = f"band_slide({m}, {e} + jump_mm, {travel})"
    return (engagement, travel, f"band_slid({e} + jump_mm, {engagement})")


def _update(slot) -> tuple[str, ...]:
    e, s, sliding = slot.states
    m = slot.m
    return (e, f"band_released({m}, {e}, {s})", f"band_sliding_after({m}, {e}, {s}, {sliding}, v)")


ELEMENT = OptionElement(
    token=BAND, word="a band brake's friction through its play", order=50, usage=BAND,
    specs=band_specs, coordinates=band_coordinates,
    helpers=lambda count: BAND_SOURCE,
    force=lambda slot: f"band_contact({slot.m}, {slot.states[0]})",
    states=lambda count: (
        ElementState("band_engagement", "mm", "the band's engagement: the displacement less its play's centre"),
        ElementState("band_travel_since", "mm", "the band's travel into its engaged side since that side engaged, "
                     "signed as the side"),
        ElementState("band_sliding", "1", "1 while the band's slider slides, 0 while it sticks")),
    step=_step, jump=_jump,
    update=_update,
    derivatives=lambda slot: (f"band_rate({slot.m}, {', '.join(slot.states)}, v)",
                              f"band_travel_rate({slot.m}, {slot.states[0]}, v)", "0.0"),
    switches=lambda count: (
        ElementState("band_upper", "m", "band_engagement - band_gap: the positive side's edge"),
        ElementState("band_lower", "m", "band_engagement + band_gap: the negative side's edge"),
        ElementState("band_slip", "1", "sticking: the contact force less its level; sliding: the least of e*v "
                     "and the contact's slope less the level's growth"),
        ElementState("band_wrap", "m", "band_travel_since less band_travel: where the level stops growing")),
    switch_values=lambda slot: (f"{slot.states[0]} - {slot.m}[0]", f"{slot.states[0]} + {slot.m}[0]",
                                f"band_slip_switch({slot.m}, {', '.join(slot.states)}, v)",
                                f"band_wrap_switch({slot.m}, {slot.states[1]})"),
    neutral=(("band_gap", 0.0), ("band_k", 0.0), ("band_depth", 0.0), ("band_f", 0.0), ("band_ratio_pos", 1.0),
             ("band_ratio_neg", 1.0), ("band_travel", 0.0)))
