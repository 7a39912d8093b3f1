"""The kernel language: the calls a kernel may make (one table) and what every tool that reads a
kernel needs of it (:class:`KernelFunction`), written once.

The models' kernels are written in a small subset of Python (``docs/adding_a_model.md``). Plain
Python and numba run them as they are; the C translator (``fmu_src.kernels.python_to_c``) and the
tangent generator (``fmu_src.kernels.tangents``) read their source and must take the same calls, or refuse
the same ones, each naming the function and the line. This table is what they take:

- ``module``: ``math`` (written ``math.<name>``) or ``builtins``;
- ``arguments``: how many;
- ``result``: ``float``, ``int`` (a count: ceil, floor, trunc, int, len), ``bool`` (a test), or
  ``same`` (the arguments' type: abs, min, max of ints is an int);
- ``tangent``: ``chain`` (a function of its arguments with a derivative) or ``zero`` (a count or a
  test: no derivative);
- ``derivative``: a ``chain`` call's tangent rule, the syntax of its tangent from its arguments
  and theirs (the tangent generator applies it and decides no call by its name), and ``active``:
  the arguments whose dependence the result carries (copysign's sign argument is a branch);
- ``c``: the C of the call, its arguments as doubles in ``{0}``, ``{1}`` (``bw_int`` is the
  translator's helper for Python's int of a float); None where the C depends on the arguments'
  types (abs, min, max, int, float, len), which the translator writes itself.

:class:`KernelFunction` is the analysis both tools share: a kernel's tree, its arguments, its errors
with lines, the fixpoint over its locals, what its names and calls mean, its tuple indices. Each
tool adds what it infers (C types, activities) and what it writes (C, tangents), and keeps its own
naming of the versions it makes per argument pattern. :func:`with_bodies` is how both the tangent
generator and its lanes (``vector_tangents``) keep a kernel's control flow.

``tests/fmu_src/kernels/test_kernel_language.py`` runs every entry in Python, numba and C (bit for bit) and its
tangent against complex step (or, for the zero-tangent entries, checks the tangent is 0).
"""
from __future__ import annotations

import ast
import builtins
import math
import types
from dataclasses import dataclass
from typing import Callable

from .unrolling import UnrollError, kernel_definition, kernel_global, kernel_statements


@dataclass(frozen=True)
class KernelCall:
    """A call a kernel may make (see the module docstring). ``derivative(b, x, t)``: its tangent
    as a syntax tree, from its arguments' trees ``x`` and their tangents' ``t`` (None for an
    inactive one), built with ``b`` (the tangent generator's builder: ``mul``, ``neg``, ``div``,
    ``where``, ``compare``, ``math``, ``helper``, ``copy``, ``zero``, ``power``); None for
    a call whose tangent class is ``zero``. ``active``: the arguments whose activity the result
    carries (default: all)."""
    name: str
    module: str
    arguments: int
    result: str
    tangent: str
    c: str | None = None
    derivative: Callable | None = None
    active: tuple[int, ...] | None = None

    @property
    def written(self) -> str:
        """How a kernel writes it: ``math.exp``, ``abs``."""
        return f"math.{self.name}" if self.module == "math" else self.name


def _sign_of(b, x, t):
    """|x|'s derivative: the branch the value takes (+ at 0, as Python's abs and C's fabs)."""
    return b.where(b.compare(x[0], ">=", 0.0), t[0], b.neg(t[0]))


def _first_of_equal(op: str):
    """min's or max's derivative: Python returns the first of equal arguments, so at a tie the
    first's."""
    return lambda b, x, t: b.where(b.compare(x[1], op, x[0]), t[1] or b.zero(), t[0] or b.zero())


CALLS = (
    KernelCall("exp", "math", 1, "float", "chain", "exp({0})", lambda b, x, t: b.mul(b.math("exp", x[0]), t[0])),
    KernelCall("log", "math", 1, "float", "chain", "log({0})", lambda b, x, t: b.div(t[0], x[0])),
    KernelCall("sqrt", "math", 1, "float", "chain", "sqrt({0})",
               lambda b, x, t: b.mul(b.helper("tangent_sqrt_slope", x[0]), t[0])),
    KernelCall("sin", "math", 1, "float", "chain", "sin({0})", lambda b, x, t: b.mul(b.math("cos", x[0]), t[0])),
    KernelCall("cos", "math", 1, "float", "chain", "cos({0})",
               lambda b, x, t: b.neg(b.mul(b.math("sin", x[0]), t[0]))),
    KernelCall("fabs", "math", 1, "float", "chain", "fabs({0})", _sign_of),
    # copysign(a, s) = |a|*sgn(s): the sign of a times the sign of s carries a's tangent; s's sign
    # is a branch (its derivative 0 away from s = 0), so only a is active
    KernelCall("copysign", "math", 2, "float", "chain", "copysign({0}, {1})",
               lambda b, x, t: b.mul(b.mul(b.math("copysign", 1.0, b.copy(x[0])), b.math("copysign", 1.0, x[1])),
                                     t[0]), active=(0,)),
    KernelCall("pow", "math", 2, "float", "chain", "pow({0}, {1})", lambda b, x, t: b.power(x[0], x[1], t[0], t[1])),
    KernelCall("ceil", "math", 1, "int", "zero", "bw_int(ceil({0}))"),
    KernelCall("floor", "math", 1, "int", "zero", "bw_int(floor({0}))"),
    KernelCall("trunc", "math", 1, "int", "zero", "bw_int({0})"),
    KernelCall("isfinite", "math", 1, "bool", "zero", "(isfinite({0}) != 0)"),
    KernelCall("isnan", "math", 1, "bool", "zero", "(isnan({0}) != 0)"),
    KernelCall("isinf", "math", 1, "bool", "zero", "(isinf({0}) != 0)"),
    KernelCall("abs", "builtins", 1, "same", "chain", derivative=_sign_of),
    KernelCall("min", "builtins", 2, "same", "chain", derivative=_first_of_equal("<")),
    KernelCall("max", "builtins", 2, "same", "chain", derivative=_first_of_equal(">")),
    KernelCall("float", "builtins", 1, "float", "chain", derivative=lambda b, x, t: t[0]),
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


class KernelFunction:
    """One kernel read for one pattern of facts about its arguments: C types for the translator
    (``native.python_to_c``), activities for the tangent generator (``tangents``). What both need
    of a kernel is here, written once: its syntax tree after unrolling and its plain positional
    arguments, errors that name the function and the file's line, the fixpoint that settles the
    locals' facts (:meth:`settle`), what a global name and a call mean (:meth:`global_value`,
    :meth:`callee`, against the table above), and constant tuple indices. A subclass sets
    ``error_type`` (its exception), ``verb`` (``translated``, ``differentiated``: what a refused call
    is not) and ``facts`` (what it settles: ``types``, ``activities``), and writes one pass of its
    inference."""
    error_type: type = ValueError
    verb = "read"
    facts = "facts"

    def __init__(self, function, argument_facts: tuple):
        self.function = function
        self.where = f"{function.__module__}.{function.__name__}"
        try:
            self.tree, self.line_offset = kernel_definition(function)
        except UnrollError as exc:
            raise self.error_type(str(exc)) from None
        if not isinstance(self.tree, ast.FunctionDef):
            raise self.error_type(f"{self.where}: not a function definition")
        args = self.tree.args
        if args.vararg or args.kwarg or args.kwonlyargs or args.defaults or args.posonlyargs:
            raise self.error(self.tree, "only plain positional parameters")
        self.arguments = [a.arg for a in args.args]
        if len(self.arguments) != len(argument_facts):
            raise self.error(self.tree, f"called with {len(argument_facts)} arguments")
        self.locals = dict(zip(self.arguments, argument_facts))
        self.result = None
        """What the kernel returns (its type or activity), once settled."""

    def error(self, node, message: str) -> Exception:
        """The error at ``node``: the function and the line in its file, then ``message``."""
        return self.error_type(f"{self.where}, line {getattr(node, 'lineno', 1) + self.line_offset}: {message}")

    @property
    def body(self) -> list:
        """The kernel's statements (its docstring left out)."""
        return kernel_statements(self.tree)

    def settle(self, infer_block, passes: int) -> None:
        """Run ``infer_block`` over the body until the locals' facts and the result no longer
        change (at most ``passes`` times); refuse a kernel whose facts do not settle or that
        returns nothing."""
        for _ in range(passes):
            before = (dict(self.locals), self.result)
            infer_block(self.body)
            if (dict(self.locals), self.result) == before:
                break
        else:
            raise self.error(self.tree, f"the {self.facts} of its variables do not settle")
        if self.result is None:
            raise self.error(self.tree, "returns nothing")

    def global_value(self, name: str, node):
        """The value of the global ``name`` as the kernel sees it (its module's, or a substitution's)."""
        try:
            return kernel_global(self.function, name)
        except NameError:
            raise self.error(node, f"unknown name {name!r}") from None

    def math_module(self, node) -> bool:
        """Whether ``node`` is the name ``math`` and means the math module."""
        if not (isinstance(node, ast.Name) and node.id == "math" and node.id not in self.locals):
            return False
        if self.global_value("math", node) is not math:
            raise self.error(node, "the name math is not the math module here")
        return True

    def callee(self, e: ast.Call):
        """('math', name), ('builtin', name) or ('kernel', function) of a call in the table or of
        another kernel; anything else is refused, naming the call and what is allowed."""
        if e.keywords:
            raise self.error(e, "keyword arguments")
        f = e.func
        if isinstance(f, ast.Attribute) and self.math_module(f.value):
            if f.attr in MATH:
                return "math", f.attr
            raise self.error(e, f"math.{f.attr} is not {self.verb}; only {describe_calls()}")
        if isinstance(f, ast.Name) and f.id not in self.locals:
            value = self.global_value(f.id, e)
            if f.id in BUILTINS and value is getattr(builtins, f.id):
                return "builtin", f.id
            if any(value is member for member in vars(math).values()):
                written = f"math.{getattr(value, '__name__', f.id)}"
                raise self.error(e, f"{f.id} is {written} imported by name; write {written} (import math)")
            if isinstance(getattr(value, "py_func", value), types.FunctionType):
                return "kernel", getattr(value, "py_func", value)
            raise self.error(e, f"call of {f.id} ({type(value).__name__}) is not {self.verb}; only "
                                f"{describe_calls()}")
        raise self.error(e, f"call of {ast.unparse(f)} is not {self.verb}; only {describe_calls()}")

    def literal_index(self, e: ast.Subscript) -> int:
        """The constant int index of ``e`` (``t[3]``, ``t[-1]``): tuples are indexed by constants only."""
        index = e.slice
        if isinstance(index, ast.UnaryOp) and isinstance(index.op, ast.USub) and isinstance(index.operand, ast.Constant):
            value = -index.operand.value
        elif isinstance(index, ast.Constant):
            value = index.value
        else:
            raise self.error(e, "only constant tuple indices")
        if not isinstance(value, int) or isinstance(value, bool):
            raise self.error(e, f"index {value!r}: only int tuple indices")
        return value


def with_bodies(s, block):
    """The ``if``, ``while`` or ``for`` statement ``s`` with its test or loop kept and its bodies
    rewritten by ``block`` (an empty body a ``pass``): how the tangent generator and its lanes
    rewrite (``vector_tangents``) keep the kernel's control flow."""
    body, orelse = block(s.body) or [ast.Pass()], block(s.orelse)
    if isinstance(s, ast.If):
        return ast.If(s.test, body, orelse)
    if isinstance(s, ast.While):
        return ast.While(s.test, body, orelse)
    return ast.For(s.target, s.iter, body, orelse, None)
