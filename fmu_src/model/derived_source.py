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


def tuple_text(names) -> str:
    names = list(names)
    return "(" + ", ".join(names) + ("," if len(names) == 1 else "") + ")"


def _constants(base: BushingModel, options) -> tuple[list[str], dict[str, int]]:
    """The derived ``prepare``'s parts (expressions of p) and which part each option's constants are."""
    held = set(base.static_spring) if options.knots else set()
    base_values, index = [], 0
    for spec in base.specs:
        if spec.name in held:
            base_values.append("0.0")
        else:
            base_values.append(f"p[{index}]")
            index += 1
    parts, slot = [f"base_prepare({tuple_text(base_values)})"], {}

    def take(name: str, count: int, wrap: str = "{}"):
        nonlocal index
        slot[name] = len(parts)
        parts.append(wrap.format(tuple_text(f"p[{index + i}]" for i in range(count))))
        index += count
    if options.knots:
        take("backbone", 2 * options.knots, "backbone_prepare({})")
    if options.limits:
        take("limits", 11)
    if options.maxwell:   # (k, rate = k/c)
        slot["maxwell"] = len(parts)
        parts.append(f"(p[{index}], p[{index}] / p[{index + 1}])")
        index += 2
    if options.rig:
        take("rig", 2)
    return parts, slot


def wrapper_source(base: BushingModel, options) -> tuple[str, set[str]]:
    """The derived model's kernels, delegating to the renamed base's (module docstring); and the
    shared names they import. A Maxwell element's force is the state's last entry."""
    parts, slot = _constants(base, options)
    zero = f" - m[{slot['rig']}][0]" if options.rig else ""
    u = "x" + zero
    n = len(base.states)
    mx = slot.get("maxwell")
    own = tuple_text(f"state[{i}]" for i in range(n)) if mx is not None else "state"    # the base's state
    out = (lambda name: tuple_text([f"{name}[{i}]" for i in range(n)] + ["{}"])) if mx is not None else None
    source = [f"def prepare(p):\n    return {tuple_text(parts)}\n"]
    if "prepare_step" in vars(sys.modules[base.kernel_module]):
        source.append(f"def prepare_step(m, h):\n    return {tuple_text(['base_prepare_step(m[0], h)'] + [f'm[{i}]' for i in range(1, len(parts))])}\n")
    if mx is None:
        source += [f"def initial_state(m, x0):\n    return base_initial_state(m[0], x0{zero})\n",
                   "def jump(m, state, jump_mm):\n    return base_jump(m[0], state, jump_mm)\n",
                   f"def integrate(m, state, x, v, h, max_substeps):\n"
                   f"    return base_integrate(m[0], state, {u}, v, h, max_substeps)\n",
                   f"def derivatives(m, state, x, v):\n    return base_derivatives(m[0], state, {u}, v)\n"]
    else:
        f = f"state[{n}]"
        source += [
            f"def initial_state(m, x0):\n    s = base_initial_state(m[0], x0{zero})\n    return {out('s').format('0.0')}\n",
            f"def jump(m, state, jump_mm):\n    s, status = base_jump(m[0], {own}, jump_mm)\n"
            f"    return {out('s').format(f'{f} + m[{mx}][0] * jump_mm')}, status\n",
            f"def integrate(m, state, x, v, h, max_substeps):\n"
            f"    s, used, status = base_integrate(m[0], {own}, {u}, v, h, max_substeps)\n"
            f"    f = maxwell_step({f}, m[{mx}][0], maxwell_decay(m[{mx}][1], h), v, h)\n"
            f"    if status == OK and not math.isfinite(f):\n        status = NOT_FINITE\n"
            f"    return {out('s').format('f')}, used, status\n",
            f"def derivatives(m, state, x, v):\n    d = base_derivatives(m[0], {own}, {u}, v)\n"
            f"    return {out('d').format(f'm[{mx}][0] * v - m[{mx}][1] * {f}')}\n"]
    force = [f"    u = {u}", f"    f = base_force(m[0], {own}, u, v)"]
    force += [f"    f = f + backbone_force(m[{slot['backbone']}], u)"] if options.knots else []
    force += [f"    f = f + limits_force(m[{slot['limits']}], u, v)"] if options.limits else []
    force += [f"    f = f + state[{n}]"] if mx is not None else []
    force += [f"    f = f + m[{slot['rig']}][1]"] if options.rig else []
    source.append("def force(m, state, x, v):\n" + "\n".join(force) + "\n    return f\n")
    if base.resting_state is not None:
        # the options' forces at rest (a Maxwell element holds none) taken off what the base holds
        rest = [f"    u = x0{zero}", "    f = force"]
        rest += [f"    f = f - backbone_force(m[{slot['backbone']}], u)"] if options.knots else []
        rest += [f"    f = f - limits_force(m[{slot['limits']}], u, 0.0)"] if options.limits else []
        rest += [f"    f = f - m[{slot['rig']}][1]"] if options.rig else []
        held = "base_resting_state(m[0], u, f)"
        rest += [f"    return {held}"] if mx is None else [f"    s = {held}", f"    return {out('s').format('0.0')}"]
        source.append("def resting_state(m, x0, force):\n" + "\n".join(rest) + "\n")
    switches = [f"s[{i}]" for i in range(len(base.switch_specs))]
    if options.limits:
        switches += [f"u - m[{slot['limits']}][0]", f"u + m[{slot['limits']}][5]"]
    body = f"    u = {u}\n" + (f"    s = base_switches(m[0], {own}, u, v)\n" if base.switch_specs else "")
    source.append("def switches(m, state, x, v):\n" + body + f"    return {tuple_text(switches) if switches else '()'}\n")
    if base.update is not None:
        update = f"base_update(m[0], {own}, {u}, v)"
        source.append(f"def update(m, state, x, v):\n    return {update}\n" if mx is None else
                      f"def update(m, state, x, v):\n    s = {update}\n    return {out('s').format(f'state[{n}]')}\n")
    shared = {"OK", "NOT_FINITE", "maxwell_step", "maxwell_decay"} if mx is not None else set()
    if options.knots:
        source.append(backbone_source(options.knots))
        shared |= {"pchip_slope", "pchip_end_slope", "hermite"}
    if options.limits:
        source.append(LIMITS_SOURCE)
        shared.add("limit_force")
    return "\n\n".join(source), shared


LIMITS_SOURCE = '''def limits_force(c, u, v):
    """Both travel limits' force [N] at u [mm], v [mm/s]; c = (gap, k, exponent, damping, depth)
    of the positive side, then of the negative, then the width."""
    gp, kp, ep, cp, dp, gn, kn, en, cn, dn, width = c
    return limit_force(u, v, gp, kp, ep, cp, dp, width) - limit_force(-u, -v, gn, kn, en, cn, dn, width)
'''


def backbone_source(knots: int) -> str:
    """``backbone_prepare(q)`` (the knots and forces -> the knots, forces and the monotone cubic's
    slopes) and ``backbone_force(b, u)`` for ``knots`` knots, written out."""
    k = knots
    xs = [f"x{i}" for i in range(k)]
    fs = [f"f{i}" for i in range(k)]
    ds = [f"d{i}" for i in range(k)]
    lines = ["def backbone_prepare(q):", f"    {', '.join(xs + fs)} = q"]
    for i in range(k - 1):
        lines.append(f"    h{i} = x{i + 1} - x{i}")
        lines.append(f"    s{i} = (f{i + 1} - f{i}) / h{i}")
    if k == 2:
        lines += ["    d0 = s0", "    d1 = s0"]
    else:
        lines.append("    d0 = pchip_end_slope(h0, h1, s0, s1)")
        for i in range(1, k - 1):
            lines.append(f"    d{i} = pchip_slope(h{i - 1}, h{i}, s{i - 1}, s{i})")
        lines.append(f"    d{k - 1} = pchip_end_slope(h{k - 2}, h{k - 3}, s{k - 2}, s{k - 3})")
    lines.append(f"    return {tuple_text(xs + fs + ds)}")
    prepare = "\n".join(lines) + "\n"
    lines = ["def backbone_force(b, u):", f"    {', '.join(xs + fs + ds)} = b",
             "    if u <= x0:", "        return f0 + d0 * (u - x0)"]
    for i in range(k - 1):
        lines += [f"    if u <= x{i + 1}:",
                  f"        return hermite(u, x{i}, x{i + 1}, f{i}, f{i + 1}, d{i}, d{i + 1})"]
    lines.append(f"    return f{k - 1} + d{k - 1} * (u - x{k - 1})")
    return prepare + "\n\n" + "\n".join(lines) + "\n"


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
