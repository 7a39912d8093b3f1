"""Forward-mode derivatives (tangents) generated from the kernels' own source: no derivative typed by hand.

For a kernel ``f(m, state, x, v)`` (``force``, ``derivatives``, ``switches`` of a model, or any
kernel of the restricted subset that ``native/python_to_c.py`` documents), :func:`tangent` writes
and returns

    f_tangent(m, state, x, v, d_state, d_x, d_v) -> (f(m, state, x, v), directional derivative)

the value bit for bit the kernel's (the kernel's own statements, unchanged, in the same order) and
the derivative in the direction (d_state, d_x, d_v), with the same shape as the value (a float, or
a tuple with 0.0 where an element does not depend on the direction). ``m`` (the prepared
parameters) is constant; which arguments are constant is a choice (``inactive``). This is what FMI
model exchange's Jacobian needs: d(der states)/d(states, inputs) column by column (one call per
seed direction) and dF/d(states, inputs).

How it is generated (source to source, on the syntax tree after ``unrolling``, as numba and the C
read it):

- activity: every local of a function gets an activity, found as the translator finds types (all
  its assignments, until nothing changes): inactive (a constant, an int, a comparison: no tangent),
  active (a float, or a tuple all of whose elements may be), or a tuple of activities (a tuple
  display whose elements differ, such as ``(v, 0.0, 0.0, ...)``). An active local ``a`` has its
  tangent ``d_a``, of the same shape; an inactive element of an active tuple has 0.0 there.
- statements: each assignment ``t = e`` is preceded by ``d_t = T(e)``, the tangent computed from
  the values before the assignment, then the kernel's own statement; ``if``/``while``/``for`` keep
  their tests and loops (the taken branch is differentiated: a branch switch is seen as the
  derivative of the branch taken at that point); ``return e`` becomes ``return e, T(e)``.
- calls of other kernels (functions of the model's module or of ``integration``): followed,
  recursively. A call whose value depends on the direction is hoisted into
  ``_tK, _dtK = g_tangent_N(arguments, their tangents)`` before its statement, and ``g``'s tangent
  is generated for the activities of that call's arguments (one version per pattern, as the
  translator makes one C function per argument types); a call whose value does not depend on the
  direction stays the plain call.
- expressions: ``+ - * /``, ``**``, unary signs, tuple displays and constant indices, conditional
  expressions (the tangent of the branch the test takes), ``abs``, ``min``/``max`` (two
  arguments), ``float``, ``math.exp/log/sqrt/sin/cos/copysign/fabs``; ``int``, ``math.ceil``,
  ``math.floor``, ``math.isfinite``, comparisons, ``not`` and ``and``/``or`` as tests are constant
  (their derivative is 0 where it exists).

Refused, with a :class:`TangentError` (a ``python_to_c.TranslationError``) naming the function and
line: statements and expressions outside that list, an ``and``/``or`` whose value is a float that
depends on the direction, a kernel call whose value depends on the direction inside a conditional
expression's branch or after the first operand of ``and``/``or`` (it could not be hoisted without
evaluating it where the kernel does not), recursion, assignment to anything but names and tuples of
names.

Where a kernel is not differentiable, the tangent is a stated one-sided value, always finite:

- a branch switch (``if z > 0.0``, a conditional expression, ``block_gain``'s sgn(u)*sgn(z)): the
  derivative of the branch the kernel takes at that point; e.g. ``block_gain`` returns A at z = 0,
  so its derivative in z there is 0 (the kernel's own choice of the value at the switch, and the
  derivative of that choice).
- ``abs(a)`` at a = 0 (and at -0.0): +da, the right-hand derivative (abs'(0) = +1).
- ``min(a, b)``/``max(a, b)`` at a tie: the derivative of the argument Python returns (the first).
- ``a ** b`` with a = 0: d/da is 0 for b > 1 (exact), 1 for b == 1 (the one-sided value, exact
  from either side), and 0 for b < 1 where the one-sided value is infinite (the same choice as
  ``block_gain`` makes for |z|^n at z = 0, which only ever raises a positive z to n). Near 0 the
  factor a^(b-1) is exact but clamped to +-SLOPE_CAP where |a| < 1 (only reached for |a| below about
  1e-100/(1 - b) when b < 1), so that it stays finite; d/db (an exponent that depends on the
  direction) is a**b*log(a) for a > 0 and 0 otherwise.
- ``math.sqrt(a)`` at a = 0: 0 (the one-sided value is infinite), clamped to SLOPE_CAP near it.
- ``int``, ``math.ceil``/``floor``: 0 (piecewise constant; at a jump the value of either side).

The generated functions are plain Python of the kernels' subset (assignments, tuples, ``if``,
conditional expressions, ``min``/``max``/``abs``, ``math`` calls, calls of other generated
functions and of the helpers below), each compiled from its own source (kept in ``linecache``, so
``inspect.getsource`` reads it), so that numba and ``python_to_c.Translation`` can take them as
they take the kernels.
"""
from __future__ import annotations

import ast
import copy
import inspect
import itertools
import linecache
import math
import types
from typing import Callable

from . import kernel_language
from .kernel_language import with_bodies
from .vector_tangents import vectorize
from ..syntax_trees import parse

SLOPE_CAP = 1e100
"""Largest magnitude of the slope factor a^(b-1) of ``a ** b`` (and of d sqrt) near a = 0 (module docstring)."""


try:
    from .python_to_c import TranslationError
except ImportError:     # the pythonfmu FMU packs fmu_src's modules without native/
    class TranslationError(ValueError):
        """Stands in for ``native.python_to_c.TranslationError`` where native/ is not packed."""


class TangentError(TranslationError):
    """A kernel the tangent generator cannot differentiate (the message names the function and line)."""


# ---------------------------------------------------------------------------- helpers the generated code calls
def tangent_pow_slope(a, b):
    """a^(b-1), the factor of d(a**b)/da = b*a^(b-1) (module docstring: its value at a = 0 and its cap)."""
    if a == 0.0:
        return 1.0 if b == 1.0 else 0.0
    s = a ** b / a
    if abs(a) < 1.0:
        if s > SLOPE_CAP:
            return SLOPE_CAP
        if s < -SLOPE_CAP:
            return -SLOPE_CAP
    return s


def tangent_pow_log(a, b):
    """d(a**b)/db = a**b*log(a) for a > 0, 0 otherwise."""
    if a > 0.0:
        return a ** b * math.log(a)
    return 0.0


def tangent_sqrt_slope(a):
    """d sqrt(a)/da = 0.5/sqrt(a) for a > 0, clamped to SLOPE_CAP; 0 at a = 0."""
    if a > 0.0:
        s = 0.5 / math.sqrt(a)
        if s > SLOPE_CAP:
            return SLOPE_CAP
        return s
    return 0.0


HELPERS = {f.__name__: f for f in (tangent_pow_slope, tangent_pow_log, tangent_sqrt_slope)}

# ---------------------------------------------------------------------------- activities
# An activity is False (inactive), True (active: a float, or a tuple all of whose elements may be),
# or a tuple of activities (a tuple whose elements differ).


def join(a, b):
    if a is False:
        return b
    if b is False:
        return a
    if a is True or b is True:
        return True
    if len(a) != len(b):
        return True
    return tuple(join(x, y) for x, y in zip(a, b))


def is_active(a) -> bool:
    return a is True or (isinstance(a, tuple) and any(is_active(x) for x in a))


def zeros(a) -> ast.expr:
    """The tangent 0 of a value of activity ``a`` (0.0 for a scalar, a tuple of them)."""
    if isinstance(a, tuple):
        return ast.Tuple([zeros(x) for x in a], ast.Load())
    return ast.Constant(0.0)


def _copy(node):
    return parse(ast.unparse(node), mode="eval").body if isinstance(node, ast.expr) else node




class _Spec(kernel_language.KernelFunction):
    """One kernel differentiated for one pattern of argument activities."""
    error_type = TangentError
    verb = "differentiated"
    facts = "activities"

    def __init__(self, generator: "Generator", function: types.FunctionType, activities: tuple, name: str):
        super().__init__(function, activities)
        self.generator = generator
        self.activities = activities
        self.name = name
        for node in ast.walk(self.tree):
            if isinstance(node, ast.Name) and (node.id.startswith("d_") or node.id.startswith("_t")):
                raise self.error(node, f"the name {node.id!r} is reserved for the generated tangents "
                                       "(d_..., _t...); rename it")
        self.analysing = True
        self.counter = itertools.count()

    @property
    def return_activity(self):
        """The activity of what the kernel returns."""
        return self.result

    # ------------------------------------------------------------------ activity analysis
    def analyse(self):
        self.settle(self.analyse_block, 50)
        self.analysing = False

    def assign_activity(self, target, a, node):
        if isinstance(target, ast.Name):
            self.locals[target.id] = join(self.locals.get(target.id, False), a)
        elif isinstance(target, ast.Tuple):
            for i, element in enumerate(target.elts):
                if isinstance(element, ast.Starred):
                    raise self.error(node, "starred assignment")
                self.assign_activity(element, a if not isinstance(a, tuple) else
                                     (a[i] if i < len(a) else True), node)
        else:
            raise self.error(node, f"assignment to {ast.unparse(target)}: only names and tuples of names")

    def analyse_block(self, statements):
        for s in statements:
            if isinstance(s, ast.Assign):
                if len(s.targets) != 1:
                    raise self.error(s, "chained assignment")
                self.assign_activity(s.targets[0], self.activity(s.value), s)
            elif isinstance(s, ast.AugAssign):
                if not isinstance(s.target, ast.Name):
                    raise self.error(s, "augmented assignment to something other than a name")
                self.assign_activity(s.target, self.activity(self.augmented(s)), s)
            elif isinstance(s, ast.Return):
                if s.value is None:
                    raise self.error(s, "a bare return")
                a = self.activity(s.value)
                self.result = a if self.result is None else join(self.result, a)
            elif isinstance(s, (ast.If, ast.While)):
                self.activity(s.test)
                self.analyse_block(s.body)
                self.analyse_block(s.orelse)
            elif isinstance(s, ast.For):
                if not isinstance(s.target, ast.Name):
                    raise self.error(s, "only `for name in range(...)` loops")
                self.locals[s.target.id] = False
                self.analyse_block(s.body)
                self.analyse_block(s.orelse)
            elif isinstance(s, (ast.Break, ast.Continue, ast.Pass)):
                pass
            elif isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant):
                pass
            else:
                raise self.error(s, f"statement {type(s).__name__} is not differentiated")

    @staticmethod
    def augmented(s: ast.AugAssign) -> ast.BinOp:
        return ast.copy_location(ast.BinOp(ast.Name(s.target.id, ast.Load()), s.op, s.value), s)

    def activity(self, e):
        if isinstance(e, ast.Constant):
            return False
        if isinstance(e, ast.Name):
            if e.id in self.locals:
                return self.locals[e.id]
            self.global_value(e.id, e)
            return False
        if isinstance(e, ast.Attribute):
            if not (isinstance(e.value, ast.Name) and e.value.id not in self.locals
                    and self.global_value(e.value.id, e) is math and e.attr in kernel_language.MATH_CONSTANTS):
                raise self.error(e, f"attribute {ast.unparse(e)}: only "
                                    + " and ".join(f"math.{name}" for name in kernel_language.MATH_CONSTANTS))
            return False
        if isinstance(e, ast.Tuple):
            for element in e.elts:
                if isinstance(element, ast.Starred):
                    raise self.error(e, "a starred element that is not a constant-range tuple(...)")
            return tuple(self.activity(element) for element in e.elts)
        if isinstance(e, ast.Subscript):
            a = self.activity(e.value)
            index = self.literal_index(e)
            if isinstance(a, tuple):
                if not -len(a) <= index < len(a):
                    raise self.error(e, f"index {index} of a tuple of {len(a)}")
                return a[index]
            return a
        if isinstance(e, ast.UnaryOp):
            a = self.activity(e.operand)
            return False if isinstance(e.op, ast.Not) else self.scalar(a, e)
        if isinstance(e, ast.BinOp):
            if not isinstance(e.op, (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow)):
                raise self.error(e, f"operator {type(e.op).__name__} is not differentiated; only + - * / **")
            return self.scalar(join(self.activity(e.left), self.activity(e.right)), e)
        if isinstance(e, ast.Compare):
            for operand in (e.left, *e.comparators):
                self.activity(operand)
            return False
        if isinstance(e, ast.BoolOp):
            if any(is_active(self.activity(value)) and not self.boolean(value) for value in e.values):
                raise self.error(e, f"{ast.unparse(e)}: and/or whose value is a float that depends on the direction")
            return False
        if isinstance(e, ast.IfExp):
            self.activity(e.test)
            return join(self.activity(e.body), self.activity(e.orelse))
        if isinstance(e, ast.Call):
            kind, what = self.callee(e)
            arguments = [self.activity(a) for a in e.args]
            if kind == "kernel":
                return self.generator.analyse(what, tuple(arguments), self, e)
            call = (kernel_language.MATH if kind == "math" else kernel_language.BUILTINS)[what]
            if len(arguments) != call.arguments:
                raise self.error(e, f"{call.written} takes {call.arguments} argument{'s' if call.arguments > 1 else ''}")
            if call.tangent == "zero":
                return False
            carried = arguments if call.active is None else [arguments[i] for i in call.active]
            return self.scalar(join(*carried) if len(carried) == 2 else carried[0], e)
        raise self.error(e, f"expression {type(e).__name__} is not differentiated")

    def scalar(self, a, e):
        if isinstance(a, tuple):
            raise self.error(e, f"arithmetic on a tuple: {ast.unparse(e)}")
        return a

    def boolean(self, e) -> bool:
        return isinstance(e, (ast.Compare, ast.BoolOp)) or (isinstance(e, ast.UnaryOp) and isinstance(e.op, ast.Not)) \
            or (isinstance(e, ast.Constant) and isinstance(e.value, bool))

    # ------------------------------------------------------------------ generation
    def generate(self) -> str:
        arguments = list(self.arguments) + [f"d_{name}" for name, a in zip(self.arguments, self.activities)
                                            if is_active(a)]
        body: list[ast.stmt] = []
        for name, passed in zip(self.arguments, self.activities):
            local = self.locals[name]
            if is_active(local) and local != passed:
                source = ast.Name(f"d_{name}", ast.Load()) if is_active(passed) else None
                body.append(ast.Assign([ast.Name(f"d_{name}", ast.Store())], self.coerce(source, passed, local)))
        body += self.block(self.body)
        tree = ast.FunctionDef(self.name, ast.arguments([], [ast.arg(a) for a in arguments], None, [], [], None, []),
                               body or [ast.Pass()], [], None)
        doc = (f"Tangent of {self.where} for argument activities "
               f"{dict(zip(self.arguments, self.activities))} (generated by fmu_src/kernels/tangents.py).")
        tree.body.insert(0, ast.Expr(ast.Constant(doc)))
        return ast.unparse(ast.fix_missing_locations(ast.Module([tree], [])))

    def block(self, statements) -> list:
        out = []
        for s in statements:
            out += self.statement(s)
        return out

    def statement(self, s) -> list:
        if isinstance(s, (ast.Assign, ast.AugAssign)):
            target = s.targets[0] if isinstance(s, ast.Assign) else s.target
            value = s.value if isinstance(s, ast.Assign) else self.augmented(s)
            if not self.target_active(target):
                return [s]
            hoisted, replaced = self.hoist(value)
            tangent = self.coerce(self.tangent(value, replaced), self.activity(value), self.target_activity(target))
            primal = ast.Assign([target], self.primal(s.value, replaced)) if isinstance(s, ast.Assign) else \
                ast.AugAssign(s.target, s.op, self.primal(s.value, replaced))
            return hoisted + [ast.Assign([self.tangent_target(target)], tangent), primal]
        if isinstance(s, ast.Return):
            hoisted, replaced = self.hoist(s.value)
            tangent = self.coerce(self.tangent(s.value, replaced), self.activity(s.value), self.return_activity)
            return hoisted + [ast.Return(ast.Tuple([self.primal(s.value, replaced), tangent], ast.Load()))]
        if isinstance(s, (ast.If, ast.While, ast.For)):
            return [with_bodies(s, self.block)]
        if isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant):
            return []
        return [s]

    def target_activity(self, target):
        if isinstance(target, ast.Name):
            return self.locals[target.id]
        return tuple(self.target_activity(element) for element in target.elts)

    def target_active(self, target) -> bool:
        return is_active(self.target_activity(target))

    def tangent_target(self, target):
        if isinstance(target, ast.Name):
            if is_active(self.locals[target.id]):
                return ast.Name(f"d_{target.id}", ast.Store())
            return ast.Name(f"_td_unused_{next(self.counter)}", ast.Store())
        return ast.Tuple([self.tangent_target(element) for element in target.elts], ast.Store())

    # hoisting the calls of kernels whose value depends on the direction
    def hoist(self, e):
        """(statements computing each active kernel call of ``e`` and its tangent, {id(call): (value
        name, tangent name)})."""
        statements, replaced = [], {}

        def visit(node, conditional: bool):
            if isinstance(node, ast.IfExp):
                visit(node.test, conditional)
                visit(node.body, True)
                visit(node.orelse, True)
                return
            if isinstance(node, ast.BoolOp):
                visit(node.values[0], conditional)
                for value in node.values[1:]:
                    visit(value, True)
                return
            if isinstance(node, (ast.Compare, ast.UnaryOp)) and (isinstance(node, ast.Compare)
                                                                 or isinstance(node.op, ast.Not)):
                return      # a test: only its value counts, which the kernel's own code computes
            for child in ast.iter_child_nodes(node):
                visit(child, conditional)
            if isinstance(node, ast.Call):
                kind, what = self.callee(node)
                if kind == "kernel" and is_active(self.activity(node)):
                    if conditional:
                        raise self.error(node, f"a call of {what.__name__} whose value depends on the direction "
                                               "inside a conditional expression or after and/or: assign it to a "
                                               "variable in an if statement instead")
                    k = next(self.counter)
                    value, tangent = f"_t{k}", f"_td{k}"
                    arguments = [self.activity(a) for a in node.args]
                    name = self.generator.emit(what, tuple(arguments), self)
                    call = ast.Call(ast.Name(name, ast.Load()),
                                    [self.primal(a, replaced) for a in node.args]
                                    + [self.coerce(self.tangent(a, replaced), act, act)
                                       for a, act in zip(node.args, arguments) if is_active(act)], [])
                    statements.append(ast.Assign([ast.Tuple([ast.Name(value, ast.Store()),
                                                             ast.Name(tangent, ast.Store())], ast.Store())], call))
                    replaced[id(node)] = (value, tangent)

        visit(e, False)
        return statements, replaced

    def primal(self, e, replaced):
        """A copy of ``e`` with the hoisted calls replaced by their values."""
        if not replaced:
            return _copy(e)

        clone = copy.deepcopy(e)
        remapped = {id(b): replaced[id(a)] for a, b in zip(ast.walk(e), ast.walk(clone)) if id(a) in replaced}

        class ReplaceClone(ast.NodeTransformer):
            def visit_Call(self, node):
                if id(node) in remapped:
                    return ast.Name(remapped[id(node)][0], ast.Load())
                self.generic_visit(node)
                return node
        return ReplaceClone().visit(clone)

    # tangent expressions
    def coerce(self, t, have, want):
        """The tangent ``t`` (None: zero) of a value of activity ``have`` as one of activity ``want``."""
        if not is_active(want):
            return zeros(want)
        if t is None or not is_active(have):
            return zeros(want)
        if have == want or want is True:
            return t
        if isinstance(want, tuple) and (have is True or isinstance(have, tuple) and len(want) == len(have)):
            # a tuple (or an active value, a tuple at run time) element by element
            elements = t.elts if isinstance(t, ast.Tuple) else [ast.Subscript(_copy(t), ast.Constant(i), ast.Load())
                                                                for i in range(len(want))]
            have = have if isinstance(have, tuple) else (True,) * len(want)
            return ast.Tuple([self.coerce(x, h, w) for x, h, w in zip(elements, have, want)], ast.Load())
        raise TangentError(f"{self.where}: a tangent of activity {have} where {want} is needed")

    def tangent(self, e, replaced):
        """The tangent of ``e`` as an expression (None where it is 0)."""
        a = self.activity(e)
        if not is_active(a):
            return None
        P = lambda node: self.primal(node, replaced)     # noqa: E731
        T = lambda node: self.tangent(node, replaced)    # noqa: E731
        if isinstance(e, ast.Name):
            return ast.Name(f"d_{e.id}", ast.Load())
        if isinstance(e, ast.Tuple):
            return ast.Tuple([self.coerce(T(x), self.activity(x), self.activity(x)) for x in e.elts], ast.Load())
        if isinstance(e, ast.Subscript):
            tv = T(e.value)
            index = self.literal_index(e)
            if isinstance(tv, ast.Tuple):
                return tv.elts[index]
            return ast.Subscript(tv, ast.Constant(index) if index >= 0 else
                                 ast.UnaryOp(ast.USub(), ast.Constant(-index)), ast.Load())
        if isinstance(e, ast.UnaryOp):
            t = T(e.operand)
            return ast.UnaryOp(ast.USub(), t) if isinstance(e.op, ast.USub) else t
        if isinstance(e, ast.BinOp):
            ta, tb = T(e.left), T(e.right)
            if isinstance(e.op, ast.Add):
                return _add(ta, tb)
            if isinstance(e.op, ast.Sub):
                return _sub(ta, tb)
            if isinstance(e.op, ast.Mult):
                return _add(_mul(ta, P(e.right)), _mul(P(e.left), tb))
            if isinstance(e.op, ast.Div):
                # d(a/b) = (da - (a/b)*db)/b
                numerator = _sub(ta, _mul(ast.BinOp(P(e.left), ast.Div(), P(e.right)), tb))
                return ast.BinOp(numerator, ast.Div(), P(e.right))
            if isinstance(e.op, ast.Pow):
                return self.pow_tangent(P(e.left), P(e.right), ta, tb)
        if isinstance(e, ast.IfExp):
            body = self.coerce(T(e.body), self.activity(e.body), a)
            orelse = self.coerce(T(e.orelse), self.activity(e.orelse), a)
            return ast.IfExp(P(e.test), body, orelse)
        if isinstance(e, ast.Call):
            if id(e) in replaced:
                return ast.Name(replaced[id(e)][1], ast.Load())
            kind, what = self.callee(e)
            if kind == "kernel":
                raise self.error(e, f"a call of {what.__name__} that was not hoisted")
            call = (kernel_language.MATH if kind == "math" else kernel_language.BUILTINS)[what]
            if call.derivative is not None:     # the kernel language's table says how
                return call.derivative(_Builder(self), [P(x) for x in e.args], [T(x) for x in e.args])
        raise self.error(e, f"{ast.unparse(e)} is not differentiated")

    def pow_tangent(self, base, exponent, ta, tb):
        out = None
        if ta is not None:
            slope = ast.Call(ast.Name("tangent_pow_slope", ast.Load()), [base, exponent], [])
            out = _mul(ast.BinOp(_copy(exponent), ast.Mult(), slope), ta)
        if tb is not None:
            out = _add(out, _mul(ast.Call(ast.Name("tangent_pow_log", ast.Load()), [_copy(base), _copy(exponent)], []),
                                 tb))
        return out


def _compare(a, op, b):
    return ast.Compare(a, [op], [b])


def _add(a, b):
    if a is None:
        return b
    if b is None:
        return a
    return ast.BinOp(a, ast.Add(), b)


def _sub(a, b):
    if b is None:
        return a
    if a is None:
        return _neg(b)
    return ast.BinOp(a, ast.Sub(), b)


def _mul(a, b):
    if a is None or b is None:
        return None
    return ast.BinOp(a, ast.Mult(), b)


def _neg(a):
    return None if a is None else ast.UnaryOp(ast.USub(), a)


class _Builder:
    """The syntax a call's tangent rule (``kernel_language.KernelCall.derivative``) is built with:
    products and negations that keep an inactive tangent (None) None, and the calls, tests and
    constants the rules name."""
    COMPARISONS = {"<": ast.Lt, ">": ast.Gt, ">=": ast.GtE}

    def __init__(self, spec):
        self.power = spec.pow_tangent

    mul, neg, copy = staticmethod(_mul), staticmethod(_neg), staticmethod(_copy)

    @staticmethod
    def _tree(x):
        return ast.Constant(x) if isinstance(x, float) else x

    @staticmethod
    def div(a, b):
        return ast.BinOp(a, ast.Div(), b)

    @staticmethod
    def where(test, body, orelse):
        return ast.IfExp(test, body, orelse)

    def compare(self, a, op: str, b):
        return _compare(self._tree(a), self.COMPARISONS[op](), self._tree(b))

    def math(self, name: str, *arguments):
        return ast.Call(ast.Attribute(ast.Name("math", ast.Load()), name, ast.Load()),
                        [self._tree(x) for x in arguments], [])

    def helper(self, name: str, *arguments):
        return ast.Call(ast.Name(name, ast.Load()), [self._tree(x) for x in arguments], [])

    @staticmethod
    def zero():
        return ast.Constant(0.0)


# ---------------------------------------------------------------------------- the generator
class Generator:
    """Generates and compiles tangents; one version per (kernel, argument activities)."""

    _serials = itertools.count()

    def __init__(self, lanes: int = 1):
        self.lanes = lanes
        """Directions the tangents carry at once in :meth:`lane_source` (the fit's: one per search
        coordinate); the compiled one-direction tangents (``compiled``) carry one."""
        self.specs: dict = {}
        self.compiled: dict = {}
        self.namespaces: dict = {}
        self.sources: dict = {}
        # Generators name their tangents alike (one kernel, other activities): the line cache's
        # filename keeps each generator's source apart, for inspect.getsource (numba, the C).
        self.serial = next(Generator._serials)

    def spec(self, function, activities, name=None) -> _Spec:
        function = getattr(function, "py_func", function)
        key = (function, activities)
        if key not in self.specs:
            if name is None:
                same = sum(1 for (f, _) in self.specs if f is function)
                name = f"{function.__module__.rsplit('.', 1)[-1]}_{function.__name__}_tangent_{same}"
            spec = _Spec(self, function, activities, name)
            self.specs[key] = spec
            spec.analyse()
        spec = self.specs[key]
        return spec

    def analyse(self, function, activities, caller: _Spec, node) -> object:
        function = getattr(function, "py_func", function)
        key = (function, activities)
        if key in self.specs and self.specs[key].analysing:
            raise caller.error(node, f"{function.__name__} calls itself (recursion is not differentiated)")
        return self.spec(function, activities).return_activity

    def emit(self, function, activities, caller: _Spec | None = None) -> str:
        """The name of the compiled tangent (generated on first request), bound in the caller's namespace."""
        spec = self.spec(function, activities)
        if spec.name not in self.compiled:
            source = spec.generate()
            filename = f"<tangent {spec.where} {spec.name} #{self.serial}>"
            linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
            namespace = self.namespace(spec.function)
            exec(compile(source, filename, "exec"), namespace)
            self.compiled[spec.name] = namespace[spec.name]
            self.sources[spec.name] = source
        if caller is not None:
            self.namespace(caller.function)[spec.name] = self.compiled[spec.name]
        return spec.name

    def lane_source(self) -> str:
        """The source of every tangent generated so far, each carrying ``lanes`` directions at once
        (a float's tangent a ``lanes``-tuple; ``vector_tangents``): the value computed once for all
        directions, which is what makes the fit's exact Jacobian cheaper than ``lanes`` + 1
        simulations."""
        return vectorize("\n\n".join(self.sources.values()), self.lanes)

    def namespace(self, function) -> dict:
        module = function.__globals__
        key = id(module)
        if key not in self.namespaces:
            namespace = dict(module)
            namespace.update(HELPERS)
            namespace.setdefault("math", math)
            self.namespaces[key] = namespace
        return self.namespaces[key]


_CACHE: dict = {}


def tangent(function: Callable, inactive: tuple = ("m",)) -> Callable:
    """``function``'s tangent ``<name>_tangent(arguments..., d_<each active argument>...)`` ->
    (value, directional derivative); the arguments named in ``inactive`` are constants (no
    tangent). Generated once per process (raises TangentError where it cannot differentiate)."""
    function = getattr(function, "py_func", function)
    key = (function, tuple(inactive))
    if key not in _CACHE:
        parameters = list(inspect.signature(function).parameters)
        activities = tuple(name not in inactive for name in parameters)
        generator = Generator()
        generator.spec(function, activities, name=f"{function.__name__}_tangent")
        generator.emit(function, activities)
        result = generator.compiled[f"{function.__name__}_tangent"]
        result.generator = generator
        _CACHE[key] = result
    return _CACHE[key]


def tangent_source(function: Callable, inactive: tuple = ("m",)) -> str:
    """The Python source of ``function``'s tangent and of every tangent it calls."""
    return "\n\n".join(tangent(function, inactive).generator.sources.values())
