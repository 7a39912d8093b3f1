"""The options any model takes, one element per module, and the set of them a derived model has.

Each module here defines one option element (``element.OptionElement``) as ``ELEMENT``:
``backbone`` (a measured static curve), ``limits`` (travel limits), ``maxwell`` (a parallel
Maxwell element), ``iwan`` (distributed slip: spring-sliders in parallel), ``band`` (a band brake's
self-energizing friction through its play), ``series`` (a compliance in series with the model and
the elements before it), ``rig`` (a measured
test's displacement and load-cell zeros), ``wlf`` and ``arrhenius`` (temperature laws: the
rubber's temperature shifts the model's dashpots and scales its stiffnesses and sliding levels). The table
(``ELEMENTS``) is discovered from the modules, in each element's ``order``: a new element is its
module, its independent reference and its tests, and touches no other element's file.

``Options`` is which elements a derived model has (and the counts of those counted), named by
their tokens in one order: ``backbone9``, ``limits``, ``maxwell``, ``iwan4``, ``band``, ``series``, ``rig``,
``wlf``, ``arrhenius``.
"""
from __future__ import annotations

import importlib
import pkgutil
import re
from dataclasses import dataclass

from ..parameter_specs import ParameterError
from .element import OptionElement


def _discover() -> dict[str, OptionElement]:
    found = []
    for info in pkgutil.iter_modules(__path__):
        if info.name in ("element", "temperature_law"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        element = getattr(module, "ELEMENT", None)
        if isinstance(element, OptionElement):
            found.append(element)
    found.sort(key=lambda e: e.order)
    return {element.token: element for element in found}


ELEMENTS: dict[str, OptionElement] = _discover()
"""The option elements by token, in their order."""


def _usage() -> str:
    words = [element.usage for element in ELEMENTS.values()]
    return ", ".join(words[:-1]) + " and " + words[-1] if len(words) > 1 else words[0]


def _token_of(word: str) -> tuple[OptionElement, int] | None:
    """(the element, its count) a lower-case option name names, or None."""
    for element in ELEMENTS.values():
        if element.counted:
            match = re.fullmatch(rf"{re.escape(element.token)}(\d+)", word)
            if match:
                return element, int(match.group(1))
        elif word == element.token:
            return element, 0
    return None


@dataclass(frozen=True)
class Options:
    """The option elements a derived model has: ``chosen`` (token, count) pairs in the elements'
    order (count 0 for an element not counted). Build it with ``Options.parse``."""
    chosen: tuple[tuple[str, int], ...] = ()

    def __post_init__(self):
        seen = {}
        for token, count in self.chosen:
            element = ELEMENTS.get(token)
            if element is None:
                raise ParameterError(f"unknown model option {token!r}; the options are {_usage()}")
            if element.counted:
                low, high = element.count_range
                if not low <= count <= high:
                    raise ParameterError(f"{element.token}{count}: the count must be {low} to {high} ({element.usage})")
            elif count:
                raise ParameterError(f"the {token} option takes no count ({token}{count})")
            if token in seen and seen[token] != count:
                raise ParameterError(f"{token}{seen[token]} and {token}{count}: give one {token}")
            seen[token] = count
        laws = [token for token in seen if ELEMENTS[token].law is not None]
        if len(laws) > 1:
            raise ParameterError(f"{' and '.join(laws)}: a model takes one law on its parameters (each is a "
                                 "temperature law); give one")
        heating = [token for token in seen if ELEMENTS[token].heating]
        if heating and not laws:
            lawful = [element.token for element in ELEMENTS.values() if element.law is not None]
            raise ParameterError(f"{heating[0]}: a thermal state heats the rubber of a model with a temperature law; "
                                 f"add one of {', '.join(lawful)}")
        object.__setattr__(self, "chosen", tuple(sorted(seen.items(), key=lambda item: ELEMENTS[item[0]].order)))

    @property
    def elements(self) -> tuple[tuple[OptionElement, int], ...]:
        """(element, count) of each option, in order."""
        return tuple((ELEMENTS[token], count) for token, count in self.chosen)

    @property
    def tokens(self) -> tuple[str, ...]:
        """The options' names in their one order (``backbone9``, ``limits``, ``maxwell``, ``iwan4``, ``band``,
        ``series``, ``rig``)."""
        return tuple(f"{token}{count}" if ELEMENTS[token].counted else token for token, count in self.chosen)

    def __bool__(self) -> bool:
        return bool(self.chosen)

    def __contains__(self, token: str) -> bool:
        return any(t == token for t, _ in self.chosen)

    def count(self, token: str) -> int:
        """The count of the element ``token`` (a backbone's knots); 0 where it is absent."""
        return dict(self.chosen).get(token, 0)

    def without(self, token: str) -> "Options":
        return Options(tuple(item for item in self.chosen if item[0] != token))

    def union(self, other: "Options") -> "Options":
        """Both sets' options (a counted element in both with different counts is refused)."""
        return Options(self.chosen + other.chosen)

    @property
    def neutral(self) -> tuple[tuple[str, float], ...]:
        """(parameter, value) of every element's neutral values (``OptionElement.neutral``: with
        them the base's force is as it is), in the elements' order."""
        return tuple(pair for element, _ in self.elements for pair in element.neutral)

    @property
    def replaces_static_spring(self) -> bool:
        return any(element.replaces_static_spring for element, _ in self.elements)

    @classmethod
    def parse(cls, tokens) -> "Options":
        """From option names (``backbone5``, ``limits``, ``iwan4``, ``rig`` ...; any order, any case)."""
        chosen = []
        for token in tokens:
            found = _token_of(token.strip().lower())
            if found is None:
                raise ParameterError(f"unknown model option {token!r}; the options are {_usage()}")
            chosen.append((found[0].token, found[1]))
        return cls(tuple(chosen))

    @classmethod
    def of_identifier_words(cls, words) -> "Options | None":
        """The options an FMI identifier's trailing words name (``Backbone7``, ``Limits``), or None
        where one of them names no option."""
        chosen = []
        for word in words:
            found = _token_of(word.lower()) if word[:1].isupper() and word[1:] == word[1:].lower() else None
            if found is None:
                return None
            chosen.append((found[0].token, found[1]))
        return cls(tuple(chosen))
