"""Complex-step differentiation of the plain kernels: the reference the generated tangents are
held to (``tests/fmu_src/kernels/test_tangents.py``, ``tests/fmu_src/model/test_derived_models.py``).
A kernel run on ``Cs`` numbers, with ``math`` read as ``ComplexMath`` (``on_complex_numbers``),
gives its derivative in the imaginary part, divided by ``STEP``."""
from __future__ import annotations

import cmath
import math
import types

STEP = 1e-30


class Cs(complex):
    """A complex number that the kernels' branches read by its real part (comparisons, abs), so
    that complex-step differentiation follows the branch the real kernel takes."""

    def __new__(cls, value):
        return complex.__new__(cls, value)

    def _wrap(result):
        return Cs(result) if isinstance(result, complex) else result

    for _name in ("add", "radd", "sub", "rsub", "mul", "rmul", "truediv", "rtruediv", "pow", "rpow"):
        locals()[f"__{_name}__"] = (lambda op: lambda self, other: Cs._wrap(getattr(complex, op)(self, other)))(
            f"__{_name}__")

    def __neg__(self):
        return Cs(complex.__neg__(self))

    def __pos__(self):
        return self

    def __abs__(self):
        return self if self.real >= 0.0 else -self

    # piecewise constant (a substep count): the real part's, derivative 0
    def __ceil__(self):
        return math.ceil(self.real)

    def __floor__(self):
        return math.floor(self.real)

    def __int__(self):
        return int(self.real)

    def __lt__(self, other):
        return self.real < _real(other)

    def __le__(self, other):
        return self.real <= _real(other)

    def __gt__(self, other):
        return self.real > _real(other)

    def __ge__(self, other):
        return self.real >= _real(other)

    def __eq__(self, other):
        return self.real == _real(other)

    def __ne__(self, other):
        return self.real != _real(other)

    __hash__ = complex.__hash__


def _real(value):
    return value.real if isinstance(value, complex) else value


def flat(value):
    return [e for v in value for e in flat(v)] if isinstance(value, tuple) else [value]


def bits(value):
    return tuple(bits(e) for e in value) if isinstance(value, tuple) else float(value).hex()


def shifted(value, direction, scale):
    if isinstance(value, tuple):
        return tuple(shifted(v, d, scale) for v, d in zip(value, direction))
    return value + scale * direction


def _analytic(name):
    def function(a):
        return Cs(getattr(cmath, name)(a)) if isinstance(a, complex) else getattr(math, name)(a)
    return staticmethod(function)


class ComplexMath:
    """``math`` for complex step: the analytic functions by cmath on a complex argument, the
    others (signs, tests, rounding) by its real part, as the kernels' branches read it."""

    def __getattr__(self, name):
        return getattr(math, name)

    exp, log, sqrt, sin, cos = _analytic("exp"), _analytic("log"), _analytic("sqrt"), _analytic("sin"), _analytic("cos")

    @staticmethod
    def fabs(a):
        return abs(a) if isinstance(a, complex) else math.fabs(a)

    @staticmethod
    def copysign(a, b):
        magnitude = abs(a) if isinstance(a, complex) else math.fabs(a)
        return magnitude if math.copysign(1.0, _real(b)) > 0.0 else -magnitude

    @staticmethod
    def pow(a, b):
        return a ** b

    @staticmethod
    def isfinite(a):
        return math.isfinite(_real(a))

    @staticmethod
    def isnan(a):
        return math.isnan(_real(a))

    @staticmethod
    def isinf(a):
        return math.isinf(_real(a))


_COMPLEX_NAMESPACES: dict = {}


def on_complex_numbers(function):
    """``function`` with ``math`` read as :class:`ComplexMath` in it and in every function it
    calls (each rebound to a copy of its module's globals), so that complex step runs through
    math.exp and its kin."""
    module = function.__module__
    if module not in _COMPLEX_NAMESPACES:
        namespace = dict(vars(__import__(module, fromlist=["_"])))
        _COMPLEX_NAMESPACES[module] = namespace
        namespace["math"] = ComplexMath()
        for name, value in list(namespace.items()):
            if isinstance(value, types.FunctionType):
                namespace[name] = on_complex_numbers(value)
    namespace = _COMPLEX_NAMESPACES[module]
    own = namespace.get(function.__name__)
    if isinstance(own, types.FunctionType) and own.__code__ is function.__code__ and own.__globals__ is namespace:
        return own
    return types.FunctionType(function.__code__, namespace, function.__name__, function.__defaults__)
