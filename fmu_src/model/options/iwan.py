"""``iwan<N>``: distributed slip, an Iwan (Maxwell-slip) element of N spring-slider pairs in
parallel: the classical model of amplitude-dependent pre-sliding in friction joints and of filled
rubber's Payne effect (the secant stiffness falls and the loop widens with the amplitude).

Its parameters: ``iwan_k`` [N/mm], the pairs' stiffness together (k/N each), and ``iwan_f`` [N],
its force when every pair slides (the sum of their slip levels). The levels are spread evenly,
level_i = iwan_f * 2i / (N(N+1)), i = 1..N: the first pair slides at the smallest force, the
last at N times it. With N = 1 it is one Jenkins element (a spring and a Coulomb slider in
series). Its states are the pairs' forces ``iwan_f1`` ... [N] (0 at rest: a virgin element).

Each pair is elastic-perfectly plastic, f_i <- clip(f_i + (k/N) du, -level_i, level_i): exact
whatever the step (rate independent, and the travel is monotone within a step of constant
velocity), so the walk needs no substeps for it. Its virgin curve is sum_i min((k/N) u, level_i)
and it follows Masing's rules (a branch from a reversal is the virgin curve doubled in both
axes), as a parallel set of Jenkins elements must. In model exchange each pair's force rises at
(k/N) v until it meets its level, then holds while the motion goes on: each pair's slip starts and
ends at an event (its switch ``iwan_slip<i>``), and its state ``iwan_sliding<i>`` [1] says which
law holds, so a variable-step solver neither steps a pair past its level nor chatters on it.
"""
from __future__ import annotations

from ..definition import SearchCoordinate
from ..parameter_specs import ParameterSpec
from ..search_coordinates import KIND
from .element import ElementState, OptionElement, Step, tuple_text

IWAN = "iwan"
MAX_PAIRS = 16
"""The most spring-slider pairs an Iwan element takes (each pair is a state)."""


def iwan_specs(pairs: int) -> tuple[ParameterSpec, ...]:
    return (ParameterSpec("iwan_k", "N/mm", f"the Iwan element's stiffness: its {pairs} spring-sliders' springs "
                          "together", minimum=0.0, why="a negative spring is unstable"),
            ParameterSpec("iwan_f", "N", "the Iwan element's force when every slider slides (the sum of their "
                          "levels, spread evenly)", minimum=0.0, why="a slip level is a magnitude", bound_powers=(0, 0)))


def iwan_coordinates(pairs: int) -> tuple[SearchCoordinate, ...]:
    # pre-sliding is stiffer than the device's secant: the box reaches 100x its scale
    return (SearchCoordinate("iwan_k", KIND.stiffness, -4.0, 2.0),
            SearchCoordinate("iwan_f", KIND.force, -3.0, 0.5))


def iwan_source(pairs: int) -> str:
    """``iwan_prepare(q)`` ((k, f) -> (k/N, level_1 ... level_N)) and the pairs' step and rate."""
    n = pairs
    levels = [f"f * {2.0 * (i + 1) / (n * (n + 1))!r}" for i in range(n)]
    return (f'''def iwan_prepare(q):
    """(stiffness of one pair [N/mm], the pairs' slip levels [N]) of (iwan_k, iwan_f)."""
    k, f = q
    return {tuple_text([f"k / {float(n)!r}"] + levels)}


def iwan_step(force, k, level, du):
    """A spring-slider pair's force [N] after a travel du [mm]: its spring k [N/mm] takes the
    travel until the force meets the slider's level [N], where it slides."""
    g = force + k * du
    if g > level:
        return level
    if g < -level:
        return -level
    return g


def iwan_slid(force, k, level, du):
    """1 where a pair's travel du [mm] from its force [N] ends in a slide, else 0 [1]."""
    g = force + k * du
    if g > level or g < -level:
        return 1.0
    return 0.0


def iwan_rate(force, k, sliding, v):
    """d force/dt [N/s] of a pair at v [mm/s] (model exchange): its spring's, 0 while it slides on."""
    if sliding != 0.0 and force * v > 0.0:
        return 0.0
    return k * v


def iwan_slip_switch(force, level, sliding, v):
    """A pair's switch (model exchange): while it sticks, |force| less its level [N] (it rises
    through 0 where the pair starts to slide); while it slides, force*v [N.mm/s] (it falls through
    0 where the motion turns back)."""
    if sliding != 0.0:
        return force * v
    return abs(force) - level


def iwan_sliding_after(force, level, sliding, v):
    """Whether a pair slides [1] after an event (model exchange): from where its force meets its
    level moving on, until the motion turns back."""
    if force * v <= 0.0:
        return 0.0
    if sliding != 0.0 or abs(force) >= level:
        return 1.0
    return 0.0
''')


def _pairs(slot) -> tuple[tuple[str, str, str], ...]:
    """Each pair's (force's text, sliding's text, its level's text)."""
    n = len(slot.states) // 2
    return tuple((slot.states[i], slot.states[n + i], f"{slot.m}[{i + 1}]") for i in range(n))


def _step(slot) -> Step:
    pairs = _pairs(slot)
    forces = tuple(f"iwan{i + 1}" for i in range(len(pairs)))
    slides = tuple(f"iwan_m{i + 1}" for i in range(len(pairs)))
    lines = tuple(f"{value} = iwan_step({f}, {slot.m}[0], {level}, v * h)"
                  for value, (f, _, level) in zip(forces, pairs))
    lines += tuple(f"{value} = iwan_slid({f}, {slot.m}[0], {level}, v * h)"
                   for value, (f, _, level) in zip(slides, pairs))
    return Step(lines, forces + slides)


def _states(pairs: int) -> tuple[ElementState, ...]:
    return (tuple(ElementState(f"iwan_f{i + 1}", "N", f"the Iwan element's pair {i + 1}: its force (slip level "
                               f"{i + 1} of {pairs}, smallest first)") for i in range(pairs))
            + tuple(ElementState(f"iwan_sliding{i + 1}", "1", f"1 while the Iwan element's pair {i + 1} slides, 0 "
                                 "while it sticks") for i in range(pairs)))


ELEMENT = OptionElement(
    token=IWAN, word="an Iwan element", order=40,
    usage=f"{IWAN}<N> (an Iwan element of N spring-sliders, 1 to {MAX_PAIRS})",
    specs=iwan_specs, coordinates=iwan_coordinates, counted=True, count_range=(1, MAX_PAIRS),
    prepare=lambda p: f"iwan_prepare({tuple_text(p)})",
    helpers=iwan_source,
    force=lambda slot: "(" + " + ".join(f for f, _, _ in _pairs(slot)) + ")",
    states=_states,
    step=_step,
    jump=lambda slot: (tuple(f"iwan_step({f}, {slot.m}[0], {level}, jump_mm)" for f, _, level in _pairs(slot))
                       + tuple(f"iwan_slid({f}, {slot.m}[0], {level}, jump_mm)" for f, _, level in _pairs(slot))),
    update=lambda slot: (tuple(f for f, _, _ in _pairs(slot))
                         + tuple(f"iwan_sliding_after({f}, {level}, {s}, v)" for f, s, level in _pairs(slot))),
    derivatives=lambda slot: (tuple(f"iwan_rate({f}, {slot.m}[0], {s}, v)" for f, s, _ in _pairs(slot))
                              + tuple("0.0" for _ in _pairs(slot))),
    switches=lambda pairs: tuple(ElementState(f"iwan_slip{i + 1}", "1", f"pair {i + 1} sticking: |force| less its "
                                              "level; sliding: force*v") for i in range(pairs)),
    switch_values=lambda slot: tuple(f"iwan_slip_switch({f}, {level}, {s}, v)" for f, s, level in _pairs(slot)),
    neutral=(("iwan_k", 0.0), ("iwan_f", 0.0)))
