"""``parse``: Python source to a syntax tree, one thread at a time.

CPython 3.11 converts a parsed tree to Python objects with a recursion counter kept per
interpreter, not per thread (python/cpython#106905, fixed in 3.12): two threads parsing at once
(a fit's search generating a model's compiled source while the exact Jacobian's tangents are
generated beside it) can raise "SystemError: AST constructor recursion depth mismatch". Every
``ast.parse`` of the kernel language's readers goes through here and holds one lock.
"""
from __future__ import annotations

import ast
import threading

_PARSING = threading.Lock()


def parse(source: str, mode: str = "exec") -> ast.AST:
    """``ast.parse(source, mode=mode)``, serialised across threads."""
    with _PARSING:
        return ast.parse(source, mode=mode)
