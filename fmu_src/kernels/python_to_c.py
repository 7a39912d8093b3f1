"""Translate the models' kernels, restricted Python, into C99: one definition, a third way to run it.

The kernels (``definition``: ``prepare``, ``initial_state``, ``step``, ``force`` ... and
the shared machinery of ``integration``) are plain float arithmetic on scalars and tuples, which
numba compiles. This module translates the same source into C, function by function, for the
native FMU (``fmu_src/fmi/native``):

- types are inferred from the arguments a function is called with (as numba does): ``double``,
  ``int`` (counts and status codes; Python's bools too) and tuples of them, which become C structs
  (``typedef struct {...} bw_tuple_<k>``) returned and passed by value. A function called with
  other argument types is translated once more under another name.
- the statements the kernels use: assignment (also unpacking a tuple), augmented assignment,
  ``if``/``elif``/``else``, ``while``, ``for name in range(stop)`` or ``range(start, stop)``
  with ``else``, ``break``, ``continue``, ``return``; expressions with ``+ - * / **`` (``**``
  with a float operand), comparisons ``< <= > >= == !=`` (chained too), ``not``, ``and``/``or``
  (see below), conditional expressions, constant tuple indices, int constants within C's int,
  calls of other kernels (Python functions, not recursive) and of the calls of
  ``fmu_src/kernels/kernel_language.py`` (``math.<name>`` written so, the module imported as
  ``import math``) and the constants ``math.inf``, ``math.pi``; ``tuple(...)`` and ``sum(...)`` of a generator over a
  constant range, written out term by term first (``fmu_src/kernels/unrolling.py``).
- Python's semantics where C's differ: ``/`` of two ints is a float division; ``int(x)`` of a
  NaN or of a value beyond C's int gives the largest int (Python would raise: the kernels'
  callers then refuse the step, as they do for too many substeps); ``min``/``max`` return the
  first of equal arguments. Where Python raises on floats (a division by zero, ``0.0 ** -1``, an
  overflow in ``**`` or ``math.exp``), the C gives inf or NaN as numba's ``error_model="numpy"``
  does, and the kernels' callers refuse a step whose state is not finite.

Refused, with a ``TranslationError`` naming the function and the line, because C would compute
something else: ``and``/``or`` whose value is used as a number (Python gives an operand, C 0 or
1; allowed as the test of an ``if``, ``while`` or conditional expression, where only the truth
counts, or where every operand is a comparison, ``not ...``, ``True``/``False`` or
``math.isfinite(...)``); a ``for`` variable read outside its loop's body (C leaves ``stop``
after the loop, Python ``stop - 1``), assigned in it, or reused by an inner loop; ``//`` and
``%`` (they round differently on negative operands), ``int ** int`` (an int in Python, possibly
a float in C), ``is``/``in``, bit operations; calls of any other function (``round``, a
``math`` function imported by name with ``from math import ...``, a method); ints beyond C's
int; a tuple as a truth value. Anything else the translator does not know is refused the same
way: a kernel that the C cannot follow must fail the build, not run differently. The C is compiled without contraction
of multiplications and additions (``-ffp-contract=off``), so on the same processor it gives the
same floats as the Python and numba kernels (``tests/fmu_src/fmi/test_native_fmu.py`` checks 1e-12, and
bitwise where it can).
"""
from __future__ import annotations

import ast
import math
import types
from dataclasses import dataclass, field
from typing import Callable, Union

from . import kernel_language

DOUBLE, INT = "double", "int"
Type = Union[str, tuple]
"""A kernel value's type: DOUBLE, INT, or a tuple of types."""

C_INT_MIN, C_INT_MAX = -2 ** 31, 2 ** 31 - 1
"""The range of C's int (32 bits on every platform the native FMU is built for)."""
SUPPORTED_CALLS = kernel_language.describe_calls()
MATH_CONSTANTS = {"inf": "HUGE_VAL", "pi": "3.141592653589793"}
assert set(MATH_CONSTANTS) == set(kernel_language.MATH_CONSTANTS)
C_RESERVED = frozenset("""auto break case char const continue default do double else enum extern float for goto if
inline int long register restrict return short signed sizeof static struct switch typedef union unsigned void volatile
while abs fabs pow exp log sqrt sin cos ceil floor trunc copysign isfinite isnan isinf bw_int main errno""".split())

PRELUDE = "#include <limits.h>\n#include <math.h>\n#include <stdlib.h>\n"
HELPERS = {
    "bw_int": """/* Python's int(x) of a float: truncation; a NaN or a value beyond int gives INT_MAX (Python
   raises there, and the kernels' callers refuse the step on too many substeps). */
static int bw_int(double x) {
    if (!(x > (double)INT_MIN - 1.0 && x < (double)INT_MAX + 1.0)) return INT_MAX;
    return (int)x;
}""",
    # Python's min and max of two values: the first of equal ones
    "bw_min_d": "static double bw_min_d(double a, double b) { return b < a ? b : a; }",
    "bw_max_d": "static double bw_max_d(double a, double b) { return b > a ? b : a; }",
    "bw_min_i": "static int bw_min_i(int a, int b) { return b < a ? b : a; }",
    "bw_max_i": "static int bw_max_i(int a, int b) { return b > a ? b : a; }",
}


class TranslationError(ValueError):
    """A kernel the C translation cannot follow (the message names the function and line)."""


def live_reads(tree: ast.AST) -> set[str]:
    """The names a function's C reads: every name loaded but in the value of an assignment to a
    name that nothing reads (the translation drops such an assignment, so what only it read would
    be set and never used, which C warns of), to a fixpoint: a tangent computed for a value that
    feeds only a count (``d_g0`` of a gain that sets the substeps) drops with what it alone read. A
    name whose only use is ``len(name)`` is not read either (the C writes the tuple's length)."""
    assignments = [node for node in ast.walk(tree) if isinstance(node, (ast.Assign, ast.AugAssign))
                   and isinstance(node.targets[0] if isinstance(node, ast.Assign) else node.target, ast.Name)
                   and (not isinstance(node, ast.Assign) or len(node.targets) == 1)]
    owner = {}
    for node in assignments:
        target = (node.targets[0] if isinstance(node, ast.Assign) else node.target).id
        for child in ast.walk(node.value):
            owner[id(child)] = target
    # len(t) of a tuple is a constant of its type in C, which reads nothing of t
    lengths = {id(argument) for node in ast.walk(tree) if isinstance(node, ast.Call)
               and isinstance(node.func, ast.Name) and node.func.id == "len" for argument in node.args}
    loads = [n for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)
             and id(n) not in lengths]
    read = {n.id for n in loads}
    while True:
        live = {n.id for n in loads if id(n) not in owner or owner[id(n)] in read}
        if live == read:
            return read
        read = live


def merge(a: Type, b: Type) -> Type:
    """The type that holds values of both: int and double give double; tuples merge by element."""
    if a == b:
        return a
    if isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b):
        return tuple(merge(x, y) for x, y in zip(a, b))
    if {a, b} == {DOUBLE, INT}:
        return DOUBLE
    raise TypeError(f"{describe(a)} and {describe(b)} cannot be merged")


def describe(t: Type) -> str:
    return f"({', '.join(describe(e) for e in t)}{',' if len(t) == 1 else ''})" if isinstance(t, tuple) else t


@dataclass
class Translation:
    """The C of a set of kernels: struct typedefs, constants, prototypes and definitions."""
    prefix: str = "bw"
    structs: dict = field(default_factory=dict)          # type -> C name, in order of creation
    constants: dict = field(default_factory=dict)        # (module, name) -> (C name, C literal, type)
    functions: dict = field(default_factory=dict)        # (function, argument types) -> _Function
    order: list = field(default_factory=list)            # _Functions in the order they were finished
    helpers: set = field(default_factory=set)            # the HELPERS the C calls

    def c_type(self, t: Type) -> str:
        if not isinstance(t, tuple):
            return t
        if t not in self.structs:
            for element in t:
                self.c_type(element)
            self.structs[t] = f"{self.prefix}_tuple_{len(self.structs)}"
        return self.structs[t]

    def function(self, function: Callable, argument_types: tuple) -> "_Function":
        """The translation of ``function`` for ``argument_types`` (made on first request)."""
        function = getattr(function, "py_func", function)   # a numba dispatcher: its Python source
        if not isinstance(function, types.FunctionType):
            raise TranslationError(f"{function!r} is not a Python function: only {SUPPORTED_CALLS} are translated")
        key = (function, argument_types)
        if key not in self.functions:
            same_name = sum(f.function is function for f in self.functions.values())
            name = f"{self.prefix}_{function.__module__.rsplit('.', 1)[-1]}_{function.__name__}".replace("__", "_")
            # Generated functions (tangents.py) of different origin can share a Python name.
            taken = {f.name for f in self.functions.values()}
            unique, count = name + (f"_{same_name}" if same_name else ""), same_name
            while unique in taken:
                count += 1
                unique = f"{name}_{count}"
            translated = _Function(self, function, argument_types, unique)
            self.functions[key] = translated
            translated.translate()
            self.order.append(translated)
        return self.functions[key]

    def source(self) -> str:
        """The C: typedefs, constants, prototypes, definitions (all ``static``)."""
        lines = [PRELUDE] + [HELPERS[name] for name in HELPERS if name in self.helpers] + [""]
        for f in self.order:        # an argument only indexed, never unpacked, has its struct too
            for t in f.argument_types:
                self.c_type(t)
        for t, name in self.structs.items():
            fields = " ".join(f"{self.c_type(e)} f{i};" for i, e in enumerate(t)) or "int unused;"
            lines.append(f"typedef struct {{ {fields} }} {name};   /* {describe(t)} */")
        lines.append("")
        for c_name, literal, t in self.constants.values():
            lines.append(f"static const {t} {c_name} = {literal};")
        lines.append("")
        for f in self.order:
            lines.append(f.prototype() + ";")
        lines.append("")
        for f in self.order:
            lines.append(f.definition())
        return "\n".join(lines)


class _Function(kernel_language.KernelFunction):
    """One function of the kernels translated for one tuple of argument types."""
    error_type = TranslationError
    verb = "translated"
    facts = "types"

    def __init__(self, translation: Translation, python: types.FunctionType, argument_types: tuple, name: str):
        super().__init__(python, argument_types)
        self.translation = translation
        self.argument_types = argument_types
        self.name = name
        # C warns of variables set but never read: names never read are neither declared nor set
        self.read = live_reads(self.tree)
        self.loop_names = {n.target.id for n in ast.walk(self.tree)
                           if isinstance(n, ast.For) and isinstance(n.target, ast.Name)}
        self.check_loop_variables(self.tree, frozenset())
        self.truth_tests = self.truth_test_nodes()
        self.temporaries = 0
        self.loops: list = []

    @property
    def return_type(self) -> Type | None:
        """The C type of what the function returns."""
        return self.result

    # ------------------------------------------------------------------ errors
    def check_loop_variables(self, node, open_loops: frozenset):
        """Refuse a ``for`` variable read outside its loop's body (after the loop C leaves it at
        ``stop``, Python at ``stop - 1``), assigned other than by its ``for`` (C would change the
        count), or reused by a loop inside its loop. ``open_loops``: the variables of the loops
        around ``node``."""
        if isinstance(node, ast.For) and isinstance(node.target, ast.Name):
            name = node.target.id
            if name in open_loops:
                raise self.error(node, f"the loop variable {name!r} is reused by a loop inside its loop; use "
                                       "another name")
            self.check_loop_variables(node.iter, open_loops)
            for statement in node.body:
                self.check_loop_variables(statement, open_loops | {name})
            for statement in node.orelse:
                self.check_loop_variables(statement, open_loops)
            return
        if isinstance(node, ast.Name) and node.id in self.loop_names:
            if isinstance(node.ctx, ast.Store):
                raise self.error(node, f"the loop variable {node.id!r} is assigned other than by its for; only "
                                       "its loop may set it")
            if node.id not in open_loops:
                raise self.error(node, f"the loop variable {node.id!r} is read outside its loop's body (after "
                                       "the loop Python leaves it at stop - 1, C at stop); copy it into "
                                       "another variable inside the loop")
        for child in ast.iter_child_nodes(node):
            self.check_loop_variables(child, open_loops)

    def truth_test_nodes(self) -> set:
        """The ids of the expressions whose truth alone counts: the tests of ``if``, ``while`` and
        conditional expressions, the operands of ``not`` and the operands of an ``and``/``or``
        that is itself such a test (there C's 0/1 and Python's operand agree)."""
        tests = []
        for node in ast.walk(self.tree):
            if isinstance(node, (ast.If, ast.While, ast.IfExp)):
                tests.append(node.test)
            elif isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
                tests.append(node.operand)
        found = set()
        while tests:
            node = tests.pop()
            found.add(id(node))
            if isinstance(node, ast.BoolOp):
                tests.extend(node.values)
        return found

    def is_boolean(self, e) -> bool:
        """Whether ``e``'s Python value is a bool (so that C's 0 or 1 is the same number)."""
        if isinstance(e, ast.Compare) or (isinstance(e, ast.UnaryOp) and isinstance(e.op, ast.Not)):
            return True
        if isinstance(e, ast.Constant):
            return isinstance(e.value, bool)
        if isinstance(e, ast.BoolOp):
            return all(self.is_boolean(value) for value in e.values)
        if isinstance(e, ast.Call):
            kind, what = self.callee(e)
            return kind != "kernel" and (kernel_language.MATH if kind == "math"
                                         else kernel_language.BUILTINS)[what].result == "bool"
        return False

    def check_truth_value(self, e):
        """Refuse a tuple as a truth value (Python: whether it is empty; C cannot test a struct)."""
        if isinstance(self.type_of(e), tuple):
            raise self.error(e, f"a tuple as a truth value: {ast.unparse(e)}")

    # ------------------------------------------------------------------ types
    def translate(self):
        """Infer the locals' and the return type (the statements until nothing changes), then
        write the C."""
        self.settle(self.infer_block, 20)
        self.translation.c_type(self.return_type)
        self.code = self.emit_block(self.body, 1)

    def assign_type(self, target, t: Type, node):
        if isinstance(target, ast.Name):
            if target.id in self.locals:
                try:
                    t = merge(self.locals[target.id], t)
                except TypeError as exc:
                    raise self.error(node, f"{target.id}: {exc}") from None
            self.locals[target.id] = t
        elif isinstance(target, ast.Tuple):
            if not isinstance(t, tuple) or len(t) != len(target.elts):
                raise self.error(node, f"cannot unpack {describe(t)} into {len(target.elts)} names")
            for element, element_type in zip(target.elts, t):
                self.assign_type(element, element_type, node)
        else:
            raise self.error(node, f"cannot assign to {ast.dump(target)}")

    def infer_block(self, statements):
        for s in statements:
            self.infer_statement(s)

    def infer_statement(self, s):
        if isinstance(s, ast.Assign):
            if len(s.targets) != 1:
                raise self.error(s, "chained assignment")
            self.assign_type(s.targets[0], self.type_of(s.value), s)
        elif isinstance(s, ast.AugAssign):
            target = ast.Name(s.target.id, ast.Load()) if isinstance(s.target, ast.Name) else None
            if target is None:
                raise self.error(s, "augmented assignment to something other than a name")
            self.assign_type(s.target, self.type_of(ast.BinOp(target, s.op, s.value)), s)
        elif isinstance(s, ast.Return):
            if s.value is None:
                raise self.error(s, "a bare return")
            t = self.type_of(s.value)
            try:
                self.result = t if self.result is None else merge(self.result, t)
            except TypeError as exc:
                raise self.error(s, f"returns {exc}") from None
        elif isinstance(s, ast.If):
            self.check_truth_value(s.test)
            self.infer_block(s.body)
            self.infer_block(s.orelse)
        elif isinstance(s, ast.While):
            self.check_truth_value(s.test)
            self.infer_block(s.body)
            self.infer_block(s.orelse)
        elif isinstance(s, ast.For):
            self.range_arguments(s)
            self.assign_type(s.target, INT, s)
            self.infer_block(s.body)
            self.infer_block(s.orelse)
        elif isinstance(s, (ast.Break, ast.Continue, ast.Pass)):
            pass
        elif isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant):
            pass    # a string as a comment
        elif isinstance(s, (ast.Import, ast.ImportFrom)):
            raise self.error(s, f"an import in a kernel ({ast.unparse(s)}); import at the module's top: "
                                "import math, from ..model.integration import ...")
        else:
            raise self.error(s, f"statement {type(s).__name__} is not supported")

    def range_arguments(self, s: ast.For):
        call = s.iter
        if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and call.func.id == "range"
                and 1 <= len(call.args) <= 2 and not call.keywords and isinstance(s.target, ast.Name)):
            raise self.error(s, "only `for name in range(stop)` or `range(start, stop)` loops")
        for argument in call.args:
            if self.type_of(argument) != INT:
                raise self.error(s, "range() takes ints")
        return call.args if len(call.args) == 2 else [ast.Constant(0), call.args[0]]

    def type_of(self, e) -> Type:
        if isinstance(e, ast.Constant):
            if isinstance(e.value, bool):
                return INT
            if isinstance(e.value, int):
                self.check_int_range(e.value, e)
                return INT
            if isinstance(e.value, float):
                return DOUBLE
            raise self.error(e, f"constant {e.value!r}: only int and float constants")
        if isinstance(e, ast.Name):
            if e.id in self.locals:
                return self.locals[e.id]
            value = self.global_value(e.id, e)
            return self.constant_type(value, e)
        if isinstance(e, ast.Attribute):
            if self.math_module(e.value) and e.attr in MATH_CONSTANTS:
                return DOUBLE
            raise self.error(e, f"attribute {ast.unparse(e)}: only math.inf and math.pi")
        if isinstance(e, ast.Tuple):
            return tuple(self.type_of(element) for element in e.elts)
        if isinstance(e, ast.Subscript):
            t = self.type_of(e.value)
            index = self.constant_index(e, t)
            return t[index]
        if isinstance(e, ast.UnaryOp):
            t = self.type_of(e.operand)
            if isinstance(e.op, ast.Not):
                self.check_truth_value(e.operand)
                return INT
            if isinstance(e.op, (ast.USub, ast.UAdd)) and not isinstance(t, tuple):
                return t
            raise self.error(e, f"unary {type(e.op).__name__} of {describe(t)}")
        if isinstance(e, ast.BinOp):
            left, right = self.type_of(e.left), self.type_of(e.right)
            if isinstance(left, tuple) or isinstance(right, tuple):
                raise self.error(e, "arithmetic on tuples")
            if isinstance(e.op, (ast.Div, ast.Pow)):
                if isinstance(e.op, ast.Pow) and left == right == INT:
                    raise self.error(e, "int ** int")
                return DOUBLE
            if isinstance(e.op, (ast.Add, ast.Sub, ast.Mult)):
                return INT if left == right == INT else DOUBLE
            if isinstance(e.op, (ast.FloorDiv, ast.Mod)):
                raise self.error(e, f"operator {'//' if isinstance(e.op, ast.FloorDiv) else '%'}: Python rounds "
                                    "towards minus infinity, C towards zero; only + - * / **")
            raise self.error(e, f"operator {type(e.op).__name__}: only + - * / **")
        if isinstance(e, ast.BoolOp):
            for value in e.values:
                self.check_truth_value(value)
            if id(e) not in self.truth_tests and not self.is_boolean(e):
                word = "and" if isinstance(e.op, ast.And) else "or"
                raise self.error(e, f"{word} used as a number ({ast.unparse(e)}): Python gives one of the "
                                    "operands, C gives 0 or 1; allowed as an if/while/conditional test or where "
                                    "every operand is a comparison, not ..., True/False or math.isfinite(...)")
            return INT
        if isinstance(e, ast.Compare):
            for operand in (e.left, *e.comparators):
                if isinstance(self.type_of(operand), tuple):
                    raise self.error(e, "comparison of tuples")
            for op in e.ops:
                if not isinstance(op, (ast.Lt, ast.LtE, ast.Gt, ast.GtE, ast.Eq, ast.NotEq)):
                    raise self.error(e, f"comparison {type(op).__name__}: only < <= > >= == !=")
            return INT
        if isinstance(e, ast.IfExp):
            self.check_truth_value(e.test)
            try:
                return merge(self.type_of(e.body), self.type_of(e.orelse))
            except TypeError as exc:
                raise self.error(e, str(exc)) from None
        if isinstance(e, ast.Call):
            return self.call_type(e)
        raise self.error(e, f"expression {type(e).__name__} is not supported")

    def constant_index(self, e: ast.Subscript, t: Type) -> int:
        if not isinstance(t, tuple):
            raise self.error(e, f"indexing a {describe(t)}")
        value = self.literal_index(e)
        if not -len(t) <= value < len(t):
            raise self.error(e, f"index {value!r} of a tuple of {len(t)}")
        return value % len(t)

    def check_int_range(self, value: int, node):
        if not C_INT_MIN <= value <= C_INT_MAX:
            raise self.error(node, f"the int {value} is beyond C's int ({C_INT_MIN} .. {C_INT_MAX}); write it as a "
                                   "float if it is one")

    def constant_type(self, value, node) -> Type:
        if isinstance(value, bool) or isinstance(value, int):
            self.check_int_range(int(value), node)
            return INT
        if isinstance(value, float):
            return DOUBLE
        raise self.error(node, f"global {ast.unparse(node)} is a {type(value).__name__}, not a number")

    def call_type(self, e: ast.Call) -> Type:
        kind, what = self.callee(e)
        arguments = [self.type_of(a) for a in e.args]
        if kind != "kernel":
            call = (kernel_language.MATH if kind == "math" else kernel_language.BUILTINS)[what]
            if len(arguments) != call.arguments:
                raise self.error(e, f"{call.written} takes {call.arguments} argument{'s' if call.arguments > 1 else ''}")
            if what == "len":
                if not isinstance(arguments[0], tuple):
                    raise self.error(e, f"len() of a number: {ast.unparse(e)}")
                return INT
            if any(isinstance(a, tuple) for a in arguments):
                raise self.error(e, f"{what}() of a tuple")
            if call.result == "same":
                return arguments[0] if len(arguments) == 1 else INT if arguments == [INT, INT] else DOUBLE
            return DOUBLE if call.result == "float" else INT
        callee = self.translation.function(what, tuple(arguments))
        if callee.return_type is None:
            raise self.error(e, f"{what.__name__} calls itself (recursion is not translated)")
        return callee.return_type

    # ------------------------------------------------------------------ C
    def prototype(self) -> str:
        t = self.translation
        parameters = ", ".join(f"{t.c_type(a)} {self.c_name(n)}" for n, a in zip(self.arguments, self.argument_types)) \
            or "void"
        return f"static {t.c_type(self.return_type)} {self.name}({parameters})"

    def definition(self) -> str:
        t = self.translation
        declarations = [f"    {t.c_type(v)} {self.c_name(name)};" for name, v in self.locals.items()
                        if name not in self.arguments and (name in self.read or name in self.loop_names)]
        declarations += [f"    (void){self.c_name(name)};" for name in self.arguments if name not in self.read]
        origin = f"/* {self.function.__module__}.{self.function.__name__}{self.signature_comment()} */"
        return "\n".join([origin, self.prototype() + " {", *declarations, *self.code, "}", ""])

    def signature_comment(self) -> str:
        return "(" + ", ".join(f"{n}: {describe(a)}" for n, a in zip(self.arguments, self.argument_types)) + ")"

    @staticmethod
    def c_name(name: str) -> str:
        """A Python name as a C identifier (a C keyword or library name gets a trailing _)."""
        return name + "_" if name in C_RESERVED else name

    def temporary(self) -> str:
        self.temporaries += 1
        return f"t_{self.temporaries}"

    def emit_block(self, statements, depth: int) -> list[str]:
        lines = []
        for s in statements:
            lines += self.emit_statement(s, depth)
        return lines

    def emit_statement(self, s, depth: int) -> list[str]:
        pad = "    " * depth
        if isinstance(s, ast.Assign):
            return self.emit_assignment(s.targets[0], s.value, depth)
        if isinstance(s, ast.AugAssign):
            return self.emit_assignment(s.target, ast.BinOp(ast.Name(s.target.id, ast.Load()), s.op, s.value), depth)
        if isinstance(s, ast.Return):
            return [f"{pad}return {self.converted(s.value, self.return_type)};"]
        if isinstance(s, ast.If):
            lines = [f"{pad}if ({self.condition(s.test)}) {{", *self.emit_block(s.body, depth + 1)]
            if s.orelse:
                lines += [f"{pad}}} else {{", *self.emit_block(s.orelse, depth + 1)]
            return lines + [f"{pad}}}"]
        if isinstance(s, ast.While):
            if s.orelse:
                raise self.error(s, "while ... else")
            self.loops.append(None)
            body = self.emit_block(s.body, depth + 1)
            self.loops.pop()
            return [f"{pad}while ({self.condition(s.test)}) {{", *body, f"{pad}}}"]
        if isinstance(s, ast.For):
            start, stop = (self.expression(a) for a in self.range_arguments(s))
            flag = self.temporary() if s.orelse else None      # set by a break: the else is skipped
            end = self.temporary()                               # range() evaluates its stop once
            self.loops.append(flag)
            body = self.emit_block(s.body, depth + 1)
            self.loops.pop()
            name = self.c_name(s.target.id)
            lines = [f"{pad}int {flag} = 0;"] if flag else []
            lines += [f"{pad}const int {end} = {stop};",
                      f"{pad}for ({name} = {start}; {name} < {end}; {name}++) {{", *body, f"{pad}}}"]
            if flag:
                lines += [f"{pad}if (!{flag}) {{", *self.emit_block(s.orelse, depth + 1), f"{pad}}}"]
            return lines
        if isinstance(s, ast.Break):
            if not self.loops:
                raise self.error(s, "break outside a loop")
            flag = self.loops[-1]
            return [f"{pad}{flag} = 1;", f"{pad}break;"] if flag else [f"{pad}break;"]
        if isinstance(s, ast.Continue):
            return [f"{pad}continue;"]
        if isinstance(s, ast.Pass) or (isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant)):
            return []
        raise self.error(s, f"statement {type(s).__name__}")

    def emit_assignment(self, target, value, depth: int) -> list[str]:
        pad = "    " * depth
        if isinstance(target, ast.Name):
            if target.id not in self.read:
                return []        # the kernels are pure: a value never read need not be computed
            return [f"{pad}{self.c_name(target.id)} = {self.converted(value, self.locals[target.id])};"]
        # unpacking: evaluate the right side once, then each name from its field
        t = self.type_of(value)
        temporary = self.temporary()
        lines = [f"{pad}{self.translation.c_type(t)} {temporary} = {self.expression(value)};"]
        lines += self.unpack(target, temporary, t, pad)
        return [f"{pad}{{", *["    " + line for line in lines], f"{pad}}}"]

    def unpack(self, target, source: str, t: Type, pad: str) -> list[str]:
        lines = []
        for i, (element, element_type) in enumerate(zip(target.elts, t)):
            if isinstance(element, ast.Tuple):
                lines += self.unpack(element, f"{source}.f{i}", element_type, pad)
            elif element.id in self.read:
                try:
                    cast = self.cast(f"{source}.f{i}", element_type, self.locals[element.id])
                except TypeError as exc:
                    raise self.error(element, str(exc)) from None
                lines.append(f"{pad}{self.c_name(element.id)} = {cast};")
        return lines

    def cast(self, code: str, have: Type, want: Type) -> str:
        if have == want:
            return code
        if want == DOUBLE and have == INT:
            return f"(double)({code})"
        raise TypeError(f"{describe(have)} where {describe(want)} is needed")

    def converted(self, e, want: Type) -> str:
        """``e`` as a value of type ``want`` (ints widened to double, tuples field by field)."""
        have = self.type_of(e)
        if have == want:
            return self.expression(e)
        if isinstance(want, tuple):
            if not isinstance(e, ast.Tuple):
                raise self.error(e, f"{describe(have)} where {describe(want)} is needed")
            fields = ", ".join(self.converted(element, w) for element, w in zip(e.elts, want))
            return f"({self.translation.c_type(want)}){{{fields}}}"
        try:
            return self.cast(self.expression(e), have, want)
        except TypeError as exc:
            raise self.error(e, str(exc)) from None

    def expression(self, e) -> str:
        if isinstance(e, ast.Constant):
            if isinstance(e.value, bool):
                return "1" if e.value else "0"
            if isinstance(e.value, int):
                return str(e.value)
            return self.float_literal(e.value, e)
        if isinstance(e, ast.Name):
            if e.id in self.locals:
                return self.c_name(e.id)
            return self.global_constant(e)
        if isinstance(e, ast.Attribute):
            return MATH_CONSTANTS[e.attr]
        if isinstance(e, ast.Tuple):
            t = self.type_of(e)
            fields = ", ".join(self.expression(element) for element in e.elts)
            return f"({self.translation.c_type(t)}){{{fields}}}" if e.elts else f"({self.translation.c_type(t)}){{0}}"
        if isinstance(e, ast.Subscript):
            return f"{self.expression(e.value)}.f{self.constant_index(e, self.type_of(e.value))}"
        if isinstance(e, ast.UnaryOp):
            operand = self.expression(e.operand)
            return f"(!{operand})" if isinstance(e.op, ast.Not) else f"({'-' if isinstance(e.op, ast.USub) else '+'}{operand})"
        if isinstance(e, ast.BinOp):
            left, right = self.expression(e.left), self.expression(e.right)
            if isinstance(e.op, ast.Pow):
                return f"pow({self.as_double(e.left, left)}, {self.as_double(e.right, right)})"
            if isinstance(e.op, ast.Div):
                return f"({self.as_double(e.left, left)} / {self.as_double(e.right, right)})"
            symbol = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*"}[type(e.op)]
            return f"({left} {symbol} {right})"
        if isinstance(e, ast.BoolOp):
            symbol = " && " if isinstance(e.op, ast.And) else " || "
            return "(" + symbol.join(self.expression(v) for v in e.values) + ")"
        if isinstance(e, ast.Compare):
            symbols = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==", ast.NotEq: "!="}
            parts, left = [], e.left
            for op, right in zip(e.ops, e.comparators):
                parts.append(f"({self.expression(left)} {symbols[type(op)]} {self.expression(right)})")
                left = right
            return parts[0] if len(parts) == 1 else "(" + " && ".join(parts) + ")"
        if isinstance(e, ast.IfExp):
            t = self.type_of(e)
            return f"({self.expression(e.test)} ? {self.converted(e.body, t)} : {self.converted(e.orelse, t)})"
        if isinstance(e, ast.Call):
            return self.call(e)
        raise self.error(e, f"expression {type(e).__name__}")

    def condition(self, test) -> str:
        """The C of an if/while test: a single comparison without the parentheses the expression
        gives it, since clang warns of ``if ((a == b))`` as a possible mistyped assignment
        (-Wparentheses-equality, an error under -Werror)."""
        code = self.expression(test)
        if isinstance(test, ast.Compare) and len(test.ops) == 1:
            return code[1:-1]
        return code

    def as_double(self, e, code: str) -> str:
        return f"(double){code}" if self.type_of(e) == INT else code

    def float_literal(self, value: float, node) -> str:
        if math.isnan(value):
            raise self.error(node, "a NaN constant")
        if math.isinf(value):
            return "HUGE_VAL" if value > 0 else "(-HUGE_VAL)"
        text = repr(value)     # the shortest decimal that reads back as the same double
        return text if any(c in text for c in ".en") else text + ".0"

    def global_constant(self, e: ast.Name) -> str:
        value = self.global_value(e.id, e)
        t = self.constant_type(value, e)
        module = self.function.__module__.rsplit(".", 1)[-1]
        key = (module, e.id)
        constants = self.translation.constants
        if key not in constants:
            literal = str(int(value)) if t == INT else self.float_literal(float(value), e)
            constants[key] = (f"{self.translation.prefix}_{module}_{e.id}".replace("__", "_"), literal, t)
        return constants[key][0]

    def call(self, e: ast.Call) -> str:
        kind, what = self.callee(e)
        arguments = [self.expression(a) for a in e.args]
        types_ = [self.type_of(a) for a in e.args]
        if kind == "math":
            form = kernel_language.MATH[what].c
            if "bw_int" in form:
                self.translation.helpers.add("bw_int")
            return form.format(*(self.as_double(a, c) for a, c in zip(e.args, arguments)))
        if kind == "builtin":
            if what == "len":
                return str(len(types_[0]))
            if what == "bool":
                return f"({arguments[0]} != 0)"
            if what == "int":
                if types_[0] == INT:
                    return arguments[0]
                self.translation.helpers.add("bw_int")
                return f"bw_int({arguments[0]})"
            if what == "float":
                return f"(double)({arguments[0]})"
            if what == "abs":
                return f"fabs({arguments[0]})" if types_[0] == DOUBLE else f"abs({arguments[0]})"
            suffix = "i" if types_ == [INT, INT] else "d"
            self.translation.helpers.add(f"bw_{what}_{suffix}")
            converted = [self.as_double(a, c) if suffix == "d" else c for a, c in zip(e.args, arguments)]
            return f"bw_{what}_{suffix}({', '.join(converted)})"
        target = self.translation.function(what, tuple(types_))
        return f"{target.name}({', '.join(arguments)})"
