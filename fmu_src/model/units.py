"""Units, read from their names: every unit a parameter, port or state is declared in is a product
of powers of N, mm, m, s, rad, kg, Hz, K, J and W (``N.s^2/mm``, ``m/s/s``, ``m2/s``), so its SI form (the
base units and factor FMI and SSP declare) and its form on a rotational axis are computed from
the name, not tabulated per model: a model that declares a new unit needs no entry anywhere else.

A unit with a symbolic power (``N^(1-n)/mm``, the Bouc-Wen ``beta``'s; ``N.s^alpha/mm``, the
fractional element's) has no SI form: :func:`si_form` gives None, and the FMUs declare it by name.
"""
from __future__ import annotations

import re
from fractions import Fraction

SYMBOLS = {"N": ({"kg": 1, "m": 1, "s": -2}, Fraction(1)), "mm": ({"m": 1}, Fraction(1, 1000)),
           "m": ({"m": 1}, Fraction(1)), "s": ({"s": 1}, Fraction(1)), "rad": ({"rad": 1}, Fraction(1)),
           "kg": ({"kg": 1}, Fraction(1)), "Hz": ({"s": -1}, Fraction(1)), "K": ({"K": 1}, Fraction(1)),
           "J": ({"kg": 1, "m": 2, "s": -2}, Fraction(1)), "W": ({"kg": 1, "m": 2, "s": -3}, Fraction(1))}
"""Each symbol a unit may use: its SI base exponents and factor (value_SI = factor * value)."""
BASE_ORDER = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")
"""FMI's order of a BaseUnit's exponents."""
_FACTOR = re.compile(r"^(?P<symbol>[A-Za-z]+?)(?:\^(?P<caret>-?\d+)|(?P<bare>\d+))?$")


class UnitError(ValueError):
    """A unit name that is not a product of powers of ``SYMBOLS``."""


def _factors(unit: str) -> list[tuple[str, int]]:
    """(symbol, power) of each factor of ``unit``: ``.`` multiplies, each ``/`` divides by the
    factor after it (``m/s/s`` is m.s^-2), a power is ``^k`` or a trailing digit (``m2``)."""
    if unit == "1":
        return []
    out = []
    for i, part in enumerate(unit.split("/")):
        if i and "." in part:
            raise UnitError(f"unit {unit!r}: write a product after '/' as '/a/b', not '/a.b'")
        for factor in part.split("."):
            if factor == "1" and i == 0:
                continue
            match = _FACTOR.match(factor)
            if match is None or match["symbol"] not in SYMBOLS:
                raise UnitError(f"unit {unit!r}: {factor!r} is not one of {', '.join(SYMBOLS)} with an "
                                "integer power")
            power = int(match["caret"] or match["bare"] or 1)
            out.append((match["symbol"], -power if i else power))
    return out


def is_symbolic(unit: str) -> bool:
    """Whether ``unit`` has a symbolic power (``^(1-n)``, ``^alpha``): no SI form."""
    return bool(re.search(r"\^\(|\^[A-Za-z]", unit))


def si_form(unit: str) -> dict[str, str] | None:
    """``unit``'s SI base exponents and factor as FMI's BaseUnit writes them (``{"kg": "1", "s":
    "-2", "factor": "1000"}`` for N/mm; ``{}`` for a pure number), or None for a symbolic unit.
    Raises UnitError for a name it cannot read."""
    if is_symbolic(unit):
        return None
    exponents: dict[str, int] = {}
    factor = Fraction(1)
    for symbol, power in _factors(unit):
        base, scale = SYMBOLS[symbol]
        for name, exponent in base.items():
            exponents[name] = exponents.get(name, 0) + exponent * power
        factor *= scale ** power
    form = {name: str(exponents[name]) for name in BASE_ORDER if exponents.get(name)}
    if factor != 1:
        form["factor"] = str(factor.numerator) if factor.denominator == 1 else repr(float(factor))
    return form


def rotational(unit: str) -> str:
    """A translational parameter's unit on a rotational axis: the kernels read rad where they read
    mm and give N.mm where they give N (``N/mm`` -> ``N.mm/rad``, ``N^(1-n)/mm`` ->
    ``(N.mm)^(1-n)/rad``)."""
    unit = re.sub(r"\bmm\b", "rad", unit)
    unit = re.sub(r"\bN\^", "(N.mm)^", unit)
    return re.sub(r"\bN\b(?!\.mm\)\^)", "N.mm", unit)
