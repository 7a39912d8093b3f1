"""``parse``: Python source to a syntax tree, one thread at a time.

CPython 3.11 converts a parsed tree to Python objects with a recursion counter kept per
interpreter, not per thread (python/cpython#106905, fixed in 3.12): two threads parsing at once
(a fit's search generating a model's compiled source while the exact Jacobian's tangents are
generated beside it) can raise "SystemError: AST constructor recursion depth mismatch". Every
``ast.parse`` of the kernel language's readers goes through here and holds one lock. Other
libraries parse too, numba among them (``numba.misc.firstlinefinder`` parses a function's
source while it compiles it, on the thread that compiles the race's modules), so on CPython
before 3.12 this module also puts ``ast.parse`` itself behind the same lock, for every caller of
the process: the lock is held only while one parse runs. A second copy of this module (the
one a pythonfmu FMU carries in its resources, loaded into the same process) finds the wrapper in
place and takes its lock: one lock for the process.
"""
from __future__ import annotations

import ast
import sys
import threading

_PARSING = getattr(ast.parse, "parsing_lock", None) or threading.RLock()
_UNSERIALISED_PARSE = getattr(ast.parse, "__wrapped__", ast.parse)


def parse(source: str, mode: str = "exec") -> ast.AST:
    """``ast.parse(source, mode=mode)``, serialised across threads."""
    with _PARSING:
        return _UNSERIALISED_PARSE(source, mode=mode)


def _serialised_parse(*args, **kwargs):
    with _PARSING:
        return _UNSERIALISED_PARSE(*args, **kwargs)


_serialised_parse.__wrapped__ = _UNSERIALISED_PARSE
_serialised_parse.parsing_lock = _PARSING
_serialised_parse.__doc__ = _UNSERIALISED_PARSE.__doc__

if sys.version_info < (3, 12):
    ast.parse = _serialised_parse
