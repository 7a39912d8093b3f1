"""Checks on a generated module's source before it is compiled: every name a function reads is bound.

The generated modules (``numba_binding``: a model's kernels with the FMU's batched step;
``identification.forward.population``: the population loop; ``identification.forward.parameter_jacobian``: the loop
with the kernels' tangents) are put together from templates, functions written in their home
module that read names only the generated module defines (``prepare``, ``step_prepared``,
``_VALUES``, ``_STORE`` ...). A name left unbound would surface only when numba first types the
function, as a typing error far from its cause; :func:`check_bound_names` finds it when the
module is generated, naming the function and the name.
"""
from __future__ import annotations

import ast
import builtins
from ..syntax_trees import parse


class GenerationError(RuntimeError):
    """A generated module that cannot work (the message names the module, the function and the name)."""


def module_bindings(statements) -> set[str] | None:
    """The names the module's top level binds (functions, classes, assignments, imports, loop
    targets; into if/try/with/for bodies, not into functions), or None where a star import makes
    them unknowable."""
    bound: set[str] = set()
    for node in statements:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            bound.add(node.name)
            continue
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            for alias in node.names:
                if alias.name == "*":
                    return None
                bound.add(alias.asname or alias.name.split(".")[0])
            continue
        for child in ast.walk(node):
            if isinstance(child, ast.Name) and isinstance(child.ctx, ast.Store):
                bound.add(child.id)
        for field in ("body", "orelse", "finalbody", "handlers"):
            inner = getattr(node, field, None)
            if isinstance(inner, list) and inner and not isinstance(node, ast.ClassDef):
                nested = module_bindings([s for s in inner if isinstance(s, ast.stmt)]
                                          + [s for h in inner if isinstance(h, ast.ExceptHandler) for s in h.body])
                if nested is None:
                    return None
                bound |= nested
    return bound


def free_names(function: ast.FunctionDef) -> set[str]:
    """The names ``function`` reads that it (its arguments, assignments, comprehensions, nested
    functions) does not bind."""
    local = {a.arg for a in ast.walk(function) if isinstance(a, ast.arg)}
    local |= {n.id for n in ast.walk(function) if isinstance(n, ast.Name) and isinstance(n.ctx, (ast.Store, ast.Del))}
    local |= {n.name for n in ast.walk(function) if isinstance(n, (ast.FunctionDef, ast.ClassDef)) and n is not function}
    return {n.id for n in ast.walk(function) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)} - local


def unbound_names(source: str) -> list[tuple[str, int, str]]:
    """(function, line, name) of every name a top-level function of ``source`` reads that neither
    it nor the module's top level binds, nor the builtins."""
    tree = parse(source)
    bound = module_bindings(tree.body)
    if bound is None:
        return []
    bound |= set(dir(builtins))
    found = []
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            found += [(node.name, node.lineno, name) for name in sorted(free_names(node) - bound)]
    return found


def check_bound_names(source: str, module: str, injected=()) -> None:
    """Raise GenerationError naming each function of the generated module ``module`` that reads
    a name the module does not bind (:func:`unbound_names`) and that is not one of ``injected``
    (bound in its namespace before it runs)."""
    missing = [found for found in unbound_names(source) if found[2] not in injected]
    if missing:
        raise GenerationError(f"the generated module {module} cannot run: "
                              + "; ".join(f"{function} (line {line}) reads {name!r}, which it does not bind"
                                          for function, line, name in missing))
