"""The kernel module of a model with options (``derived``), written as source text.

One definition: the base model's kernels and the functions and numeric constants they reach,
renamed ``base_<name>`` (``base_source``), then the wrapper kernels the options need
(``wrapper_source``: a Maxwell element's force the state's last entry; the backbone's monotone
cubic written out for its knots, ``backbone_source``). The module imports nothing but ``math``
and the shared machinery and elements, so numba compiles it, the C translator translates it and
the tangent generator differentiates it as any model module; the base's own module is untouched.
"""
from __future__ import annotations

import ast
import builtins
import inspect
import sys
import types

from . import elements, integration
from .definition import BushingModel, ModelContractError
from ..syntax_trees import parse
from .options.element import OptionElement, Slot, tuple_text

KERNELS = ("prepare", "initial_state", "jump", "integrate", "force", "derivatives", "switches")
"""The base's kernels a derived model wraps (``update`` and ``prepare_step`` too, where it has them)."""


def _reached(base: BushingModel, module: types.ModuleType) -> tuple[list[str], dict[str, object], set[str]]:
    """(the functions of the base's module its kernels reach, in source order; the numeric
    constants they read; the names they import from the machinery or the elements). Raises
    ModelContractError for a global of another kind."""
    tree = parse(inspect.getsource(module))
    defined = {node.name: node for node in tree.body if isinstance(node, ast.FunctionDef)}
    roots = [getattr(base, name).__name__ for name in KERNELS]
    roots += [name for name in ("prepare_step",) if name in defined]
    if base.resting_state is not None:
        roots.append(base.resting_state.__name__)
    if base.update is not None:
        roots.append(base.update.__name__)
    seen, constants, shared, pending = set(), {}, set(), list(roots)
    while pending:
        name = pending.pop()
        if name in seen:
            continue
        seen.add(name)
        node = defined[name]
        local = {a.arg for a in node.args.args} | {n.id for n in ast.walk(node)
                                                   if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
        for n in ast.walk(node):
            if not (isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)) or n.id in local:
                continue
            value = vars(module).get(n.id)
            if n.id in defined:
                pending.append(n.id)
            elif n.id == "math" or (value is None and hasattr(builtins, n.id)):
                continue
            elif any(value is vars(shared_module).get(n.id) for shared_module in (integration, elements)):
                shared.add(n.id)
            elif isinstance(value, (int, float)) and not isinstance(value, bool):
                constants[n.id] = value
            else:
                raise ModelContractError(f"{module.__name__}.{name} reads {n.id!r} ({type(value).__name__}): a "
                                         "derived model takes a base's functions, numbers and the shared machinery "
                                         "only")
    return [name for name in defined if name in seen], constants, shared


class _Rename(ast.NodeTransformer):
    """Module-level names of the base, read in its functions, renamed ``base_<name>`` (a local of
    the same name is left alone)."""

    def __init__(self, names: set[str]):
        self.names = names
        self.local: set[str] = set()

    def visit_FunctionDef(self, node: ast.FunctionDef):
        outer = self.local
        self.local = {a.arg for a in node.args.args} | {n.id for n in ast.walk(node)
                                                        if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
        if node.name in self.names:
            node.name = f"base_{node.name}"
        node.body = [self.visit(statement) for statement in node.body]
        self.local = outer
        return node

    def visit_Name(self, node: ast.Name):
        if isinstance(node.ctx, ast.Load) and node.id in self.names and node.id not in self.local:
            node.id = f"base_{node.id}"
        return node


def base_source(base: BushingModel) -> tuple[str, set[str]]:
    """The base's kernels and what they reach, renamed ``base_<name>``, as source; and the
    shared names they import."""
    module = sys.modules[base.kernel_module]
    functions, constants, shared = _reached(base, module)
    tree = parse(inspect.getsource(module))
    renamer = _Rename(set(functions) | set(constants))
    lines = [f"base_{name} = {value!r}" for name, value in sorted(constants.items())]
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name in functions:
            node.decorator_list = []
            lines.append(ast.unparse(renamer.visit(node)))
    return "\n\n\n".join(lines), shared


def _layout(base: BushingModel, options) -> tuple[list[str], list[tuple[OptionElement, int, Slot]]]:
    """The derived ``prepare``'s parts (expressions of p) and each option element with its count
    and its slot (its part of the prepared constants, its states after the base's)."""
    held = set(base.static_spring) if options.replaces_static_spring else set()
    base_values, index = [], 0
    for spec in base.specs:
        if spec.name in held:
            base_values.append("0.0")
        else:
            base_values.append(f"p[{index}]")
            index += 1
    parts, placed, state_index = [f"base_prepare({tuple_text(base_values)})"], [], len(base.states)
    for element, count in options.elements:
        size = len(element.specs(count))
        states = tuple(f"state[{state_index + i}]" for i in range(len(element.states(count))))
        state_index += len(states)
        placed.append((element, count, Slot(f"m[{len(parts)}]", states)))
        parts.append(element.prepare(tuple(f"p[{index + i}]" for i in range(size))))
        index += size
    return parts, placed


def wrapper_source(base: BushingModel, options) -> tuple[str, set[str]]:
    """The derived model's kernels, delegating to the renamed base's (module docstring); and the
    shared names they import. The option elements' states follow the base's."""
    parts, placed = _layout(base, options)
    zero = "".join(f" - {element.displacement_zero(slot)}" for element, _, slot in placed
                   if element.displacement_zero is not None)
    u = "x" + zero
    n = len(base.states)
    stateful = [(element, slot) for element, _, slot in placed if slot.states]
    own = tuple_text(f"state[{i}]" for i in range(n)) if stateful else "state"    # the base's state

    def out(name: str, extra) -> str:
        return tuple_text([f"{name}[{i}]" for i in range(n)] + list(extra))

    def each(hook) -> list[str]:
        return [text for element, slot in stateful for text in hook(element)(slot)]
    source = [f"def prepare(p):\n    return {tuple_text(parts)}\n"]
    if "prepare_step" in vars(sys.modules[base.kernel_module]):
        source.append(f"def prepare_step(m, h):\n    return {tuple_text(['base_prepare_step(m[0], h)'] + [f'm[{i}]' for i in range(1, len(parts))])}\n")
    if not stateful:
        source += [f"def initial_state(m, x0):\n    return base_initial_state(m[0], x0{zero})\n",
                   "def jump(m, state, jump_mm):\n    return base_jump(m[0], state, jump_mm)\n",
                   f"def integrate(m, state, x, v, h, max_substeps):\n"
                   f"    return base_integrate(m[0], state, {u}, v, h, max_substeps)\n",
                   f"def derivatives(m, state, x, v):\n    return base_derivatives(m[0], state, {u}, v)\n"]
    else:
        steps = [element.step(slot) for element, slot in stateful]
        lines = "".join(f"    {line}\n" for step in steps for line in step.lines)
        values = [value for step in steps for value in step.values]
        finite = " or ".join(f"not math.isfinite({value})" for value in values)
        finite = f"({finite})" if len(values) > 1 else finite
        # a base without states gives nothing to start or to integrate: its calls would be dead
        # code, and the C translation refuses an unused function
        start = f"    s = base_initial_state(m[0], x0{zero})\n" if n else ""
        rates = f"    d = base_derivatives(m[0], {own}, {u}, v)\n" if n else ""
        source += [
            f"def initial_state(m, x0):\n{start}"
            f"    return {out('s', each(lambda e: e.initial))}\n",
            f"def jump(m, state, jump_mm):\n    s, status = base_jump(m[0], {own}, jump_mm)\n"
            f"    return {out('s', each(lambda e: e.jump))}, status\n",
            f"def integrate(m, state, x, v, h, max_substeps):\n"
            f"    s, used, status = base_integrate(m[0], {own}, {u}, v, h, max_substeps)\n{lines}"
            f"    if status == OK and {finite}:\n        status = NOT_FINITE\n"
            f"    return {out('s', values)}, used, status\n",
            f"def derivatives(m, state, x, v):\n{rates}"
            f"    return {out('d', each(lambda e: e.derivatives))}\n"]
    force = [f"    u = {u}", f"    f = base_force(m[0], {own}, u, v)"]
    force += [f"    f = f + {element.force(slot)}" for element, _, slot in placed if element.force is not None]
    source.append("def force(m, state, x, v):\n" + "\n".join(force) + "\n    return f\n")
    if base.resting_state is not None:
        # the options' forces at rest taken off what the base holds; their states start as they start
        rest = [f"    u = x0{zero}", "    f = force"]
        rest += [f"    f = f - {element.rest_force(slot)}" for element, _, slot in placed
                 if element.rest_force is not None]
        held = "base_resting_state(m[0], u, f)"
        rest += [f"    return {held}"] if not stateful else [f"    s = {held}",
                                                              f"    return {out('s', each(lambda e: e.initial))}"]
        source.append("def resting_state(m, x0, force):\n" + "\n".join(rest) + "\n")
    switches = [f"s[{i}]" for i in range(len(base.switch_specs))]
    switches += [text for element, _, slot in placed for text in element.switch_values(slot)]
    body = f"    u = {u}\n" + (f"    s = base_switches(m[0], {own}, u, v)\n" if base.switch_specs else "")
    source.append("def switches(m, state, x, v):\n" + body + f"    return {tuple_text(switches) if switches else '()'}\n")
    updating = any(element.update is not None for element, _ in stateful)
    if base.update is not None or updating:
        update = f"base_update(m[0], {own}, {u}, v)" if base.update is not None else own
        updated = [text for element, slot in stateful
                   for text in (element.update(slot) if element.update is not None else slot.states)]
        source.append(f"def update(m, state, x, v):\n    return {update}\n" if not stateful else
                      f"def update(m, state, x, v):\n    s = {update}\n"
                      f"    return {out('s', updated)}\n")
    shared = {"OK", "NOT_FINITE"} if stateful else set()
    for element, count, _ in placed:
        shared |= element.shared
        helpers = element.helpers(count)
        if helpers:
            source.append(helpers)
    return "\n\n".join(source), shared


def derived_source(base: BushingModel, options) -> str:
    """The derived model's whole module: its docstring, imports, the renamed base, the wrappers."""
    body, shared = base_source(base)
    wrappers, own = wrapper_source(base, options)
    shared |= own
    machinery = sorted(name for name in shared if name in vars(integration))
    element_names = sorted(name for name in shared if name not in vars(integration))
    imports = "from __future__ import annotations\n\nimport math\n\n"
    if machinery:
        imports += f"from ..model.integration import {', '.join(machinery)}\n"
    if element_names:
        imports += f"from ..model.elements import {', '.join(element_names)}\n"
    doc = (f'"""The {base.name} model with {", ".join(options.tokens)}: generated by fmu_src/model/derived.py from '
           f'{base.kernel_module.rpartition(".")[2]} (its kernels renamed base_*) and the options\' wrappers."""\n')
    return doc + imports + "\n\n" + body + "\n\n\n" + wrappers
