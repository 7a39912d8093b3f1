"""Vector-mode tangents: the generated tangents (``tangents``) rewritten to carry K directions at once.

Reached through the generator: ``tangents.Generator(lanes=K).lane_source()``. The rewrite reads
the generator's one-direction source, recognising tangents by the names the generator reserves
for them (``d_...``, ``_td...``: a kernel that uses such a name is refused there).

A tangent that ``fmu_src.kernels.tangents.Generator`` writes computes the kernel's value and one directional
derivative. The fit needs the derivatives of the forces in every direction of its search space
(d = 14 for the proposed model) along one simulation, and the value is most of a step's cost (the
powers, exponentials and the branch logic), so computing it once for all K directions is what
makes an exact Jacobian cheaper than K + 1 simulations. :func:`vectorize` rewrites a generated
tangent's source so that every tangent value has each float replaced by a K-tuple of floats (its
K directions, the "vector layout"): ``d_x`` of a float is a K-tuple, ``d_state`` of a 4-tuple a
4-tuple of K-tuples, and so on; the kernel's own statements (the value) are left as they are, so
the value stays bit for bit the kernel's.

The rewrite, per statement of the generated source (whose tangent statements are recognised by
their names: ``d_...`` and ``_td...`` hold tangents, nothing else does):

- a tangent assignment ``d_t = T``: T's IfExps that involve a tangent are lifted to ``if``
  statements (``d_a - (X if c else Y)`` becomes ``if c: d_t = d_a - X else: d_t = d_a - Y``), so
  that each branch is computed only where the kernel's test takes it; the parts of T that do not
  involve a tangent (products of primal values, ``tangent_pow_slope(...)``, ...) are computed once
  into temporaries; T, linear in the tangents it reads, is collected into one coefficient per
  tangent (an expression of values, computed once: ``(d_a*h + a*d_h)/c`` has the coefficients
  h/c of d_a and a/c of d_h), and lane k is the sum of each tangent's element k times its
  coefficient: a multiplication and an addition per tangent read and lane, the least there is.
  A zero (0.0) becomes a K-tuple of zeros, a tuple display a tuple of the rewritten elements, a
  name or constant index of a tangent stays as it is.
- a call of another generated tangent (``_tK, _tdK = f_tangent(values..., tangents...)``): its
  tangent arguments rewritten as above; the callee is rewritten too (every function of the source
  is).
- ``return value, T``: T rewritten as above.
- everything else (the kernel's statements, ``if``/``while``/``for`` with their tests): unchanged,
  the bodies rewritten.

The result is plain Python of the kernels' subset (tuples, arithmetic, ``if``), which numba
compiles (``identification/forward/parameter_jacobian.py``); lane k equals what the one-direction tangent
computes for direction k to rounding (the same derivative, its terms summed in another order:
tested to 1e-10), and the value is the kernel's bit for bit (its statements untouched).
"""
from __future__ import annotations

import ast
import copy
import itertools

from .kernel_language import with_bodies
from ..syntax_trees import parse

TANGENT_PREFIXES = ("d_", "_td")
"""The names the generated tangents hold their tangents in (``tangents`` reserves them)."""


def _is_tangent_name(name: str) -> bool:
    return name.startswith(TANGENT_PREFIXES)


def involves_tangent(node: ast.AST) -> bool:
    """Whether ``node`` reads a tangent (a ``d_...`` or ``_td...`` name)."""
    return any(isinstance(n, ast.Name) and _is_tangent_name(n.id) for n in ast.walk(node))


def _is_chain(node: ast.AST) -> bool:
    """A tangent name or a constant index of one (``d_blk[3]``, ``_td0[1]``): a value in vector layout."""
    while isinstance(node, ast.Subscript):
        node = node.value
    return isinstance(node, ast.Name) and _is_tangent_name(node.id)


class _Vectorizer:
    def __init__(self, lanes: int, tangent_arguments: dict[str, int]):
        self.lanes = lanes
        self.tangent_arguments = tangent_arguments     # generated function -> its count of value arguments
        self.counter = itertools.count()

    # ------------------------------------------------------------------ expressions
    def zeros(self, constant: ast.Constant) -> ast.Tuple:
        if not (isinstance(constant.value, float) and constant.value == 0.0):
            raise ValueError(f"a tangent constant other than 0.0: {ast.unparse(constant)}")
        return ast.Tuple([ast.Constant(0.0) for _ in range(self.lanes)], ast.Load())

    def vector(self, e: ast.expr, prelude: list) -> ast.expr:
        """``e`` (a tangent expression of the one-direction code) in vector layout; statements it
        needs first are appended to ``prelude``."""
        if _is_chain(e):
            return e
        if isinstance(e, ast.Constant):
            return self.zeros(e)
        if isinstance(e, ast.Tuple):
            return ast.Tuple([self.vector(element, prelude) for element in e.elts], ast.Load())
        if isinstance(e, ast.Subscript):       # a constant index of a tangent computed here
            return ast.Subscript(self.vector(e.value, prelude), e.slice, ast.Load())
        lifted = self.lift(e)
        if isinstance(lifted, ast.IfExp):
            name = f"_vt{next(self.counter)}"
            body, orelse = [], []
            body.append(ast.Assign([ast.Name(name, ast.Store())], self.vector(lifted.body, body)))
            orelse.append(ast.Assign([ast.Name(name, ast.Store())], self.vector(lifted.orelse, orelse)))
            prelude.append(ast.If(lifted.test, body, orelse))
            return ast.Name(name, ast.Load())
        # scalar arithmetic on tangents, linear in them: each tangent's coefficient once, then K lanes
        form = self.linear(self.hoist_values(e, prelude))
        terms = []
        for chain, coefficient in form.values():
            if coefficient is not None and not _is_constant(coefficient):
                name = f"_vc{next(self.counter)}"
                prelude.append(ast.Assign([ast.Name(name, ast.Store())], coefficient))
                coefficient = ast.Name(name, ast.Load())
            terms.append((chain, coefficient))
        if not terms:
            return self.zeros(ast.Constant(0.0))
        return ast.Tuple([self.lane_sum(terms, k) for k in range(self.lanes)], ast.Load())

    def linear(self, e: ast.expr) -> dict:
        """``e`` (a tangent expression, linear in its tangents, after :meth:`hoist_values`) as
        {tangent: (its chain, its coefficient: an expression of values, or None for 1)}."""
        if _is_chain(e):
            return {ast.unparse(e): (e, None)}
        if isinstance(e, ast.Constant):
            return {}
        if isinstance(e, ast.UnaryOp) and isinstance(e.op, (ast.USub, ast.UAdd)):
            form = self.linear(e.operand)
            if isinstance(e.op, ast.UAdd):
                return form
            return {key: (chain, _negated(c)) for key, (chain, c) in form.items()}
        if isinstance(e, ast.BinOp) and isinstance(e.op, (ast.Add, ast.Sub)):
            form = dict(self.linear(e.left))
            for key, (chain, c) in self.linear(e.right).items():
                c = c if isinstance(e.op, ast.Add) else _negated(c)
                form[key] = (chain, _sum(form[key][1], c)) if key in form else (chain, c)
            return form
        if isinstance(e, ast.BinOp) and isinstance(e.op, ast.Mult):
            if involves_tangent(e.left) and not involves_tangent(e.right):
                return {key: (chain, _product(c, e.right)) for key, (chain, c) in self.linear(e.left).items()}
            if involves_tangent(e.right) and not involves_tangent(e.left):
                return {key: (chain, _product(e.left, c)) for key, (chain, c) in self.linear(e.right).items()}
        if isinstance(e, ast.BinOp) and isinstance(e.op, ast.Div) and not involves_tangent(e.right):
            return {key: (chain, ast.BinOp(c if c is not None else ast.Constant(1.0), ast.Div(), copy.deepcopy(e.right)))
                    for key, (chain, c) in self.linear(e.left).items()}
        raise ValueError(f"a tangent expression that is not linear in the tangents: {ast.unparse(e)}")

    @staticmethod
    def lane_sum(terms: list, k: int) -> ast.expr:
        """Lane k: the sum of each tangent's element k times its coefficient."""
        out = None
        for chain, coefficient in terms:
            element = ast.Subscript(copy.deepcopy(chain), ast.Constant(k), ast.Load())
            negative = _is_constant(coefficient) and _constant_value(coefficient) == -1.0
            if coefficient is not None and not negative and not (_is_constant(coefficient)
                                                                 and _constant_value(coefficient) == 1.0):
                element = ast.BinOp(copy.deepcopy(coefficient), ast.Mult(), element)
            if out is None:
                out = ast.UnaryOp(ast.USub(), element) if negative else element
            else:
                out = ast.BinOp(out, ast.Sub() if negative else ast.Add(), element)
        return out

    def lift(self, e: ast.expr) -> ast.expr:
        """``e`` with its outermost IfExp that involves a tangent lifted to the top:
        E[X if c else Y] -> (E[X] if c else E[Y]) (``e`` itself if it has none)."""
        found = None

        def visit(node):
            nonlocal found
            if found is not None:
                return
            if isinstance(node, ast.IfExp) and (involves_tangent(node.body) or involves_tangent(node.orelse)):
                found = node
                return
            for child in ast.iter_child_nodes(node):
                visit(child)

        visit(e)
        if found is None or found is e:
            return e

        def replaced(by):
            clone = copy.deepcopy(e)
            target = next(b for a, b in zip(ast.walk(e), ast.walk(clone)) if a is found)

            class Replace(ast.NodeTransformer):
                def visit(self, node):
                    if node is target:
                        return copy.deepcopy(by)
                    return self.generic_visit(node)
            return Replace().visit(clone)

        return ast.IfExp(found.test, replaced(found.body), replaced(found.orelse))

    def hoist_values(self, e: ast.expr, prelude: list) -> ast.expr:
        """``e`` with each largest part that involves no tangent (and is more than a name or a
        constant) computed into a temporary in ``prelude``: once for all K lanes."""
        if not involves_tangent(e):
            if isinstance(e, ast.Name) or _is_constant(e):
                return e
            name = f"_vp{next(self.counter)}"
            prelude.append(ast.Assign([ast.Name(name, ast.Store())], e))
            return ast.Name(name, ast.Load())
        if _is_chain(e):
            return e
        if isinstance(e, ast.BinOp):
            return ast.BinOp(self.hoist_values(e.left, prelude), e.op, self.hoist_values(e.right, prelude))
        if isinstance(e, ast.UnaryOp):
            return ast.UnaryOp(e.op, self.hoist_values(e.operand, prelude))
        if isinstance(e, ast.Call):
            return ast.Call(e.func, [self.hoist_values(a, prelude) for a in e.args], [])
        raise ValueError(f"a tangent expression the vector mode does not know: {ast.unparse(e)}")

    # ------------------------------------------------------------------ statements
    def block(self, statements: list) -> list:
        out = []
        for s in statements:
            out += self.statement(s)
        return out

    def statement(self, s: ast.stmt) -> list:
        if isinstance(s, ast.Assign) and involves_tangent(s.targets[0]):
            target = s.targets[0]
            if isinstance(target, ast.Tuple) and isinstance(s.value, ast.Call) \
                    and isinstance(s.value.func, ast.Name) and s.value.func.id in self.tangent_arguments:
                # _tK, _tdK = f_tangent(values..., tangents...)
                prelude = []
                values = self.tangent_arguments[s.value.func.id]
                arguments = s.value.args[:values] + [self.vector(a, prelude) for a in s.value.args[values:]]
                return prelude + [ast.Assign([target], ast.Call(s.value.func, arguments, []))]
            prelude = []
            value = self.vector(s.value, prelude)
            return prelude + [ast.Assign([target], value)]
        if isinstance(s, ast.AugAssign) and involves_tangent(s.target):
            raise ValueError(f"an augmented assignment to a tangent: {ast.unparse(s)}")
        if isinstance(s, ast.Return):
            if not (isinstance(s.value, ast.Tuple) and len(s.value.elts) == 2):
                raise ValueError(f"a generated tangent's return is (value, tangent): {ast.unparse(s)}")
            prelude = []
            tangent = self.vector(s.value.elts[1], prelude)
            return prelude + [ast.Return(ast.Tuple([s.value.elts[0], tangent], ast.Load()))]
        if isinstance(s, (ast.If, ast.While, ast.For)):
            return [with_bodies(s, self.block)]
        return [s]


def _is_constant(e) -> bool:
    return isinstance(e, ast.Constant) or (isinstance(e, ast.UnaryOp) and isinstance(e.op, ast.USub)
                                           and isinstance(e.operand, ast.Constant))


def _constant_value(e) -> float:
    return e.value if isinstance(e, ast.Constant) else -e.operand.value


def _negated(c):
    """-c for a coefficient (None: 1)."""
    if c is None:
        return ast.Constant(-1.0)
    if _is_constant(c):
        return ast.Constant(-_constant_value(c))
    return ast.UnaryOp(ast.USub(), c)


def _sum(a, b):
    return ast.BinOp(a if a is not None else ast.Constant(1.0), ast.Add(), b if b is not None else ast.Constant(1.0))


def _product(a, b):
    """a*b for coefficients (None: 1), in the order given."""
    if a is None:
        return copy.deepcopy(b)
    if b is None:
        return copy.deepcopy(a)
    return ast.BinOp(copy.deepcopy(a), ast.Mult(), copy.deepcopy(b))


def vectorize(source: str, lanes: int) -> str:
    """The generated tangents in ``source`` (one or more ``def``s from ``tangents.Generator``) with
    every tangent carrying ``lanes`` directions (module docstring). Raises ValueError on a
    statement it does not recognise."""
    if lanes < 1:
        raise ValueError(f"lanes = {lanes}: give 1 or more")
    tree = parse(source)
    functions = [node for node in tree.body if isinstance(node, ast.FunctionDef)]
    values = {f.name: sum(1 for a in f.args.args if not a.arg.startswith("d_")) for f in functions}
    vectorizer = _Vectorizer(lanes, values)
    for function in functions:
        function.body = vectorizer.block(function.body)
    return ast.unparse(ast.fix_missing_locations(tree))
