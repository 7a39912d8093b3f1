"""The calls a kernel may make: one table, read by every tool that reads the kernels.

The models' kernels are written in a small subset of Python (``docs/adding_a_model.md``). Plain
Python and numba run them as they are; the C translator (``fmu_src.native.python_to_c``) and the
tangent generator (``fmu_src.tangents``) read their source and must take the same calls, or refuse
the same ones, each naming the function and the line. This table is what they take:

- ``module``: ``math`` (written ``math.<name>``) or ``builtins``;
- ``arguments``: how many;
- ``result``: ``float``, ``int`` (a count: ceil, floor, trunc, int, len), ``bool`` (a test), or
  ``same`` (the arguments' type: abs, min, max of ints is an int);
- ``tangent``: ``chain`` (a function of its arguments with a derivative: the tangent generator holds
  its rule, ``tangents.CHAIN_RULES``) or ``zero`` (a count or a test: no derivative);
- ``c``: the C of the call, its arguments as doubles in ``{0}``, ``{1}`` (``bw_int`` is the
  translator's helper for Python's int of a float); None where the C depends on the arguments'
  types (abs, min, max, int, float, len), which the translator writes itself.

``tests/test_kernel_language.py`` runs every entry in Python, numba and C (bit for bit) and its
tangent against complex step (or, for the zero-tangent entries, checks the tangent is 0).
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class KernelCall:
    """A call a kernel may make (see the module docstring)."""
    name: str
    module: str
    arguments: int
    result: str
    tangent: str
    c: str | None = None

    @property
    def written(self) -> str:
        """How a kernel writes it: ``math.exp``, ``abs``."""
        return f"math.{self.name}" if self.module == "math" else self.name


CALLS = (
    KernelCall("exp", "math", 1, "float", "chain", "exp({0})"),
    KernelCall("log", "math", 1, "float", "chain", "log({0})"),
    KernelCall("sqrt", "math", 1, "float", "chain", "sqrt({0})"),
    KernelCall("sin", "math", 1, "float", "chain", "sin({0})"),
    KernelCall("cos", "math", 1, "float", "chain", "cos({0})"),
    KernelCall("fabs", "math", 1, "float", "chain", "fabs({0})"),
    KernelCall("copysign", "math", 2, "float", "chain", "copysign({0}, {1})"),
    KernelCall("pow", "math", 2, "float", "chain", "pow({0}, {1})"),
    KernelCall("ceil", "math", 1, "int", "zero", "bw_int(ceil({0}))"),
    KernelCall("floor", "math", 1, "int", "zero", "bw_int(floor({0}))"),
    KernelCall("trunc", "math", 1, "int", "zero", "bw_int({0})"),
    KernelCall("isfinite", "math", 1, "bool", "zero", "(isfinite({0}) != 0)"),
    KernelCall("isnan", "math", 1, "bool", "zero", "(isnan({0}) != 0)"),
    KernelCall("isinf", "math", 1, "bool", "zero", "(isinf({0}) != 0)"),
    KernelCall("abs", "builtins", 1, "same", "chain"),
    KernelCall("min", "builtins", 2, "same", "chain"),
    KernelCall("max", "builtins", 2, "same", "chain"),
    KernelCall("float", "builtins", 1, "float", "chain"),
    KernelCall("int", "builtins", 1, "int", "zero"),
    KernelCall("len", "builtins", 1, "int", "zero"),
    KernelCall("bool", "builtins", 1, "bool", "zero"),
)
MATH = {call.name: call for call in CALLS if call.module == "math"}
BUILTINS = {call.name: call for call in CALLS if call.module == "builtins"}
MATH_CONSTANTS = ("pi", "inf")
"""The math module's constants a kernel may read."""


def describe_calls() -> str:
    """The calls as an error message lists them."""
    return "other kernels (Python functions), " + ", ".join(call.written for call in CALLS)
