"""The contract of an option element: one part any model can take, defined once in its module.

An option element (``OptionElement``) owns its part of a derived model (``derived``): its
parameters (specs, units, bounds, constraints), its prepared constants, its states and how they
start, jump, step and change (model exchange), its force, what it holds at rest, its switches
(event indicators), its search coordinates, what a fit holds of it and its neutral values (those
that leave the base's force as it is). Its kernel parts are written as kernel-language source text
(``derived_source`` puts them into the derived model's kernels), so numba compiles them, the C
translator translates them and the tangent generator differentiates them as any model's.

Where a hook writes text it gets a ``Slot``: the text of its prepared constants in the wrapper
(``m[2]``) and of its states in the state vector (``state[4]``, ...). Inside the kernels ``u`` is
the base's displacement [mm] (x less any displacement zero), ``v`` the velocity [mm/s], ``h`` the
step [s] and ``jump_mm`` a jump of the displacement [mm].
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..definition import SearchCoordinate
from ..parameter_specs import Constraint, ParameterSpec


def tuple_text(names) -> str:
    """A tuple's source text: ``(a, b)``, ``(a,)``, ``()``."""
    names = list(names)
    return "(" + ", ".join(names) + ("," if len(names) == 1 else "") + ")"


@dataclass(frozen=True)
class Slot:
    """Where an element's parts sit in a derived model's kernels: ``m`` the text of its prepared
    constants, ``states`` the texts of its states (empty for an element without state)."""
    m: str
    states: tuple[str, ...] = ()


@dataclass(frozen=True)
class ElementState:
    """One state an element adds (after the base's and the earlier elements'): its name, unit and
    meaning, as ``StateSpec`` states them."""
    name: str
    unit: str
    description: str


@dataclass(frozen=True)
class Step:
    """An element's states over one step of the walk: ``lines`` of source that compute them from
    its old states, ``v`` (constant over the step) and ``h`` (the step), and the ``values`` (names
    of those lines' results, unique to the element) that are its new states, checked finite."""
    lines: tuple[str, ...]
    values: tuple[str, ...]


def _no_text(slot: Slot) -> tuple[str, ...]:
    return ()


@dataclass(frozen=True)
class OptionElement:
    """One option element (module docstring). ``token`` is its name in a model's name
    (``proposed+limits``); an element ``counted`` takes a count after it (``backbone9``: 9 knots),
    within ``count_range``. ``word`` names it in a model's title, ``usage`` in an error's list of
    options. The hooks with ``count`` take the element's count (0 for an element without one)."""
    token: str
    word: str
    usage: str
    order: int
    """Its place among the options (in a model's name, its parameters, its kernels' terms): lower first."""
    specs: Callable[[int], tuple[ParameterSpec, ...]]
    coordinates: Callable[[int], tuple[SearchCoordinate, ...]]
    constraints: Callable[[int], tuple[Constraint, ...]] = lambda count: ()
    counted: bool = False
    count_range: tuple[int, int] = (0, 0)
    series: bool = False
    """True: the element sits in series with the base and the elements before it in order (the
    device), and the elements after it (stateless: the rig's offsets) outside both; its one state is
    the device's displacement and ``derived_source.series_wrapper_source`` writes its kernels
    (its own hooks other than ``specs``, ``coordinates``, ``states`` and ``prepare`` unused)."""
    replaces_static_spring: bool = False
    """True: the base's static spring (``BushingModel.static_spring``) is held at 0 and this element
    carries the static force instead (and a slow loop's least-squares start does not apply)."""
    prepare: Callable[[tuple[str, ...]], str] = tuple_text
    """Its prepared constants' source from its parameters' texts (``p[5]``, ...)."""
    helpers: Callable[[int], str] = lambda count: ""
    """Source of the kernels its texts call (defined in the derived module)."""
    shared: frozenset = frozenset()
    """Names its texts import from the machinery (``integration``) or the shared ``elements``."""
    displacement_zero: Callable[[Slot], str] | None = None
    """Text of a displacement the base's displacement is measured from (u = x - it); None: none."""
    force: Callable[[Slot], str] | None = None
    """Text of the force [N] it adds at (u, v, its states); None: none."""
    rest_force: Callable[[Slot], str] | None = None
    """Text of the force [N] it holds at rest at u (its states as they start); None: none."""
    states: Callable[[int], tuple[ElementState, ...]] = lambda count: ()
    """Its states for its count (after the base's and the earlier elements'); with any, ``step``."""
    initial: Callable[[Slot], tuple[str, ...]] = lambda slot: tuple("0.0" for _ in slot.states)
    jump: Callable[[Slot], tuple[str, ...]] = lambda slot: slot.states
    step: Callable[[Slot], Step] | None = None
    derivatives: Callable[[Slot], tuple[str, ...]] = _no_text
    update: Callable[[Slot], tuple[str, ...]] | None = None
    """Its states after an event of model exchange (a switch crossed: ``v``, ``x`` at hand), one
    text per state; None: they do not change there."""
    switches: Callable[[int], tuple[ElementState, ...]] = lambda count: ()
    """Its switches (event indicators) for its count, as ``switch_values`` gives them."""
    switch_values: Callable[[Slot], tuple[str, ...]] = _no_text
    law: Callable[[tuple[str, ...]], tuple[tuple[str, ...], dict[str, str]]] | None = None
    """A law on the model's other parameters (a temperature law): from its own parameters' texts,
    the source lines of its factors and the name of each role's factor (``ParameterSpec.
    temperature_role``: ``viscous``, ``elastic``, ``friction``); every other parameter of the
    model is multiplied by its role's factor before the model is prepared
    (``derived_source.law_wrapper_source``), a role without a factor left as it is. None: none."""
    law_roles: tuple[tuple[str, str], ...] = ()
    """(constant, role) of a law's constants: one whose role no other parameter of the model takes
    (``friction_per_K`` in a model without a sliding level) moves nothing, so the fit holds it at
    its neutral value instead of searching it."""
    heating: bool = False
    """True: a thermal state, the rubber's temperature, heated by the power the model takes from
    the motion and cooled towards the law's temperature (then the surroundings'); its two
    constants are its parameters and ``derived_source.heated_source`` writes the kernels (its own
    hooks other than ``specs``, ``coordinates``, ``constraints`` and ``prepare`` unused). Needs a
    law (``law``) in the same model."""
    conditions: tuple[tuple[str, str], ...] = ()
    """(parameter, the ``Measurement`` field that sets it): parameters a test's own conditions set
    (``temperature`` from its ``temperature_K``), held by the fit, the set's value where a test
    says nothing."""
    held: tuple[tuple[str, float], ...] = ()
    """What a fit holds of it unless told otherwise (``fit(fixed=...)``)."""
    neutral: tuple[tuple[str, float], ...] = ()
    """Its values that leave the base's force as it is (a slow loop's friction alone)."""
