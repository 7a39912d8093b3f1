"""``maxwell``: a Maxwell element in parallel (``maxwell_k`` [N/mm] in series with ``maxwell_c``
[N.s/mm]: a relaxation of time constant c/k, filled rubber's rate dependence), its force a state of
its own (``maxwell_f`` [N]), stepped exactly over a step of constant velocity
(``elements.maxwell_step``). It holds no force at rest (it has relaxed)."""
from __future__ import annotations

import math

from ..definition import SearchCoordinate
from ..parameter_specs import ParameterSpec
from ..search_coordinates import KIND
from .element import ElementState, OptionElement, Step

MAXWELL = "maxwell"


def maxwell_specs(count: int = 0) -> tuple[ParameterSpec, ...]:
    return (ParameterSpec("maxwell_k", "N/mm", "the parallel Maxwell element's spring", minimum=0.0,
                          why="a negative spring is unstable"),
            ParameterSpec("maxwell_c", "N.s/mm", "the parallel Maxwell element's dashpot (time constant c/k)",
                          minimum=0.0, exclusive=True, why="a Maxwell element without a dashpot is a spring"))


def maxwell_coordinates(count: int) -> tuple[SearchCoordinate, ...]:
    return (SearchCoordinate("maxwell_k", KIND.stiffness, -4.0, 1.0),
            SearchCoordinate("maxwell_c", KIND.time_constant, -math.inf, 4.0, over=("maxwell_k",)))


ELEMENT = OptionElement(
    token=MAXWELL, word="a Maxwell element", order=30, usage=MAXWELL, specs=maxwell_specs, coordinates=maxwell_coordinates,
    # its constants: (k, rate = k/c)
    prepare=lambda p: f"({p[0]}, {p[0]} / {p[1]})",
    shared=frozenset({"maxwell_step", "maxwell_decay"}),
    force=lambda slot: slot.states[0],
    states=lambda count: (ElementState("maxwell_f", "N", "the parallel Maxwell element's force"),),
    jump=lambda slot: (f"{slot.states[0]} + {slot.m}[0] * jump_mm",),
    step=lambda slot: Step((f"f = maxwell_step({slot.states[0]}, {slot.m}[0], maxwell_decay({slot.m}[1], h), v, h)",),
                           ("f",)),
    derivatives=lambda slot: (f"{slot.m}[0] * v - {slot.m}[1] * {slot.states[0]}",),
    neutral=(("maxwell_k", 0.0), ("maxwell_c", 1.0)))
