"""Tuples and sums over a constant range in the kernels, unrolled for numba and for the C translation.

A kernel may write a tuple or a sum of many similar terms, such as the modes of a relaxation
spectrum, as

    tuple(<expression of i> for i in range(N))      sum(<expression of i> for i in range(N))

with N an int literal or an int constant of the kernel's module (``range(a, b)`` likewise). Plain
Python runs that as it stands. numba cannot build a tuple from a generator, and the C
translation knows tuples only of a fixed shape with constant indices, so both read the kernels
through :func:`unroll`, which writes each such call out term by term, i replaced by its values:

    tuple(k[i] * f[i] for i in range(3))   ->   (k[0] * f[0], k[1] * f[1], k[2] * f[2])
    sum(k[i] * f[i] for i in range(3))     ->   0 + k[0] * f[0] + k[1] * f[1] + k[2] * f[2]

The terms' int arithmetic is folded (``state[3 + i]`` becomes ``state[3]``, ``state[4]`` ...,
``stiffness[i // 3]`` ``stiffness[0]``, ``stiffness[0]``, ``stiffness[0]``, ``stiffness[1]`` ...: the C
knows constant indices only), and a tuple written out inside a tuple display is spliced into it:
``(v, 0.0, *tuple(... for i in range(N)))`` is one flat tuple of N + 2 values.

The sum starts from the int 0 and adds left to right, as Python's ``sum`` does, so the unrolled
source gives the same floats bit for bit (a sum of -0.0 terms included). Such a generator with
a condition or two ``for`` clauses is an ``UnrollError`` naming the line; generators over
anything but a constant range are left as they are (plain Python code of the module; a kernel
that used one is refused by numba and by the C translation, which names the line).
"""
from __future__ import annotations

import ast
import builtins
import inspect
import textwrap
from typing import Mapping
from ..syntax_trees import parse


class UnrollError(ValueError):
    """A tuple(...) or sum(...) of a generator that cannot be written out term by term."""


UNROLLED = ("tuple", "sum")


def unroll(tree: ast.AST, namespace: Mapping[str, object], where: str = "", line_offset: int = 0) -> ast.AST:
    """``tree`` (a module or a function) with every tuple(...)/sum(...) over a constant range
    written out; ``namespace``: the globals the range's bounds may name; ``where`` and
    ``line_offset``: how errors name the source (a module or function, and the file line of the
    tree's line 1, minus 1)."""
    tree = _Unroller(namespace, where, line_offset).visit(tree)
    return ast.fix_missing_locations(tree)


def kernel_definition(function) -> tuple[ast.FunctionDef, int]:
    """(``function``'s definition as the compiled paths read it: its source unrolled by
    :func:`unroll` in its module's namespace, the offset of its first line in its file). Raises
    UnrollError."""
    line_offset = function.__code__.co_firstlineno - 1
    source = textwrap.dedent(inspect.getsource(function))
    tree = unroll(parse(source), function.__globals__, f"{function.__module__}.{function.__name__}", line_offset)
    return tree.body[0], line_offset


def kernel_statements(definition: ast.FunctionDef) -> list:
    """A function definition's statements without its docstring."""
    body = definition.body
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        body = body[1:]
    return body


def kernel_global(function, name: str):
    """What ``name`` means in ``function``'s module: a global of it, else a builtin; NameError if
    neither."""
    if name in function.__globals__:
        return function.__globals__[name]
    if hasattr(builtins, name):
        return getattr(builtins, name)
    raise NameError(name)


class _Unroller(ast.NodeTransformer):
    def __init__(self, namespace: Mapping[str, object], where: str, line_offset: int):
        self.namespace = namespace
        self.where = where
        self.line_offset = line_offset

    def error(self, node, message: str) -> UnrollError:
        return UnrollError(f"{self.where}, line {node.lineno + self.line_offset}: {message}")

    def visit_Call(self, node: ast.Call):
        self.generic_visit(node)
        if not (isinstance(node.func, ast.Name) and node.func.id in UNROLLED and len(node.args) == 1
                and not node.keywords and isinstance(node.args[0], ast.GeneratorExp)):
            return node
        generator = node.args[0]
        clause = generator.generators[0]
        if not _over_range(clause.iter):
            return node     # not ours (Python-only code); in a kernel, numba and the C refuse it
        if len(generator.generators) != 1 or clause.ifs or clause.is_async or not isinstance(clause.target, ast.Name):
            raise self.error(node, f"{node.func.id}(... for name in range(...)) with one `for` clause and no "
                                   "condition only")
        bounds = [self.constant(argument) for argument in clause.iter.args]
        if None in bounds:
            return node     # a range that is not constant: as above
        terms = [ast.copy_location(_FoldInts().visit(_Substitute(clause.target.id, i).visit(_copy(generator.elt))),
                                   node)
                 for i in range(*bounds)]
        if node.func.id == "tuple":
            return ast.copy_location(ast.Tuple(terms, ast.Load()), node)
        total: ast.expr = ast.copy_location(ast.Constant(0), node)
        for term in terms:
            total = ast.copy_location(ast.BinOp(total, ast.Add(), term), node)
        return total

    def visit_Tuple(self, node: ast.Tuple):
        self.generic_visit(node)
        if not any(isinstance(e, ast.Starred) and isinstance(e.value, ast.Tuple) for e in node.elts):
            return node
        elements = []
        for element in node.elts:
            if isinstance(element, ast.Starred) and isinstance(element.value, ast.Tuple):
                elements.extend(element.value.elts)
            else:
                elements.append(element)
        return ast.copy_location(ast.Tuple(elements, node.ctx), node)

    def constant(self, node) -> int | None:
        """The int value of a range bound, None if it is not a literal or a constant of the module."""
        if isinstance(node, ast.Constant) and type(node.value) is int:
            return node.value
        if isinstance(node, ast.Name) and type(self.namespace.get(node.id)) is int:
            return self.namespace[node.id]
        return None


def _over_range(node) -> bool:
    return (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "range"
            and 1 <= len(node.args) <= 2 and not node.keywords)


class _Substitute(ast.NodeTransformer):
    """Replace reads of ``name`` by the int ``value``."""

    def __init__(self, name: str, value: int):
        self.name = name
        self.value = value

    def visit_Name(self, node: ast.Name):
        if node.id == self.name and isinstance(node.ctx, ast.Load):
            return ast.copy_location(ast.Constant(self.value), node)
        return node


_INT_OPERATIONS = {ast.Add: int.__add__, ast.Sub: int.__sub__, ast.Mult: int.__mul__, ast.FloorDiv: int.__floordiv__,
                   ast.Mod: int.__mod__}


class _FoldInts(ast.NodeTransformer):
    """``a + b``, ``a - b``, ``a * b``, ``a // b`` and ``a % b`` of int literals as one literal
    (exact, Python's int arithmetic: ``state[6 + i // 3]`` of element i of 3-vectors, written out)."""

    def visit_BinOp(self, node: ast.BinOp):
        self.generic_visit(node)
        if (type(node.op) in _INT_OPERATIONS and isinstance(node.left, ast.Constant)
                and isinstance(node.right, ast.Constant) and type(node.left.value) is int
                and type(node.right.value) is int and not (isinstance(node.op, (ast.FloorDiv, ast.Mod))
                                                           and node.right.value == 0)):
            value = _INT_OPERATIONS[type(node.op)](node.left.value, node.right.value)
            return ast.copy_location(ast.Constant(value), node)
        return node


def _copy(node: ast.AST) -> ast.AST:
    return parse(ast.unparse(node), mode="eval").body
