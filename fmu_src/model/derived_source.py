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
    """Module-level names of the base, read in its functions, renamed ``base_<name>`` (or
    ``<prefix><name>``; a local of the same name is left alone)."""

    def __init__(self, names: set[str], prefix: str = "base_"):
        self.names = names
        self.prefix = prefix
        self.local: set[str] = set()

    def visit_FunctionDef(self, node: ast.FunctionDef):
        outer = self.local
        self.local = {a.arg for a in node.args.args} | {n.id for n in ast.walk(node)
                                                        if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
        if node.name in self.names:
            node.name = f"{self.prefix}{node.name}"
        node.body = [self.visit(statement) for statement in node.body]
        self.local = outer
        return node

    def visit_Name(self, node: ast.Name):
        if isinstance(node.ctx, ast.Load) and node.id in self.names and node.id not in self.local:
            node.id = f"{self.prefix}{node.id}"
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
    if any(element.law is not None for element, _ in options.elements):
        return law_wrapper_source(base, options)
    if any(element.series for element, _ in options.elements):
        return series_wrapper_source(base, options)
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


DEVICE_KERNELS = ("prepare", "prepare_step", "initial_state", "jump", "integrate", "derivatives", "force",
                  "resting_state", "switches", "update")
"""The kernels of a series element's device, renamed ``device_<name>`` under the series wrappers."""

SERIES_ITERATIONS = 60
"""Device steps a series element's step may take to find the device's velocity (``options.series``)."""


def renamed(text: str, names: set[str], prefix: str) -> str:
    """Kernel source ``text`` with its functions ``names`` (and the reads of them) renamed
    ``<prefix><name>``: the inner model a wrapper delegates to."""
    renamer = _Rename(names, prefix=prefix)
    return "\n\n\n".join(ast.unparse(renamer.visit(node)) for node in parse(text).body)


def _device_source(base: BushingModel, inner) -> tuple[str, set[str]]:
    """The device's kernels (the base with the options before the series element) as source, named
    ``device_<kernel>``, and the shared names they import."""
    text, shared = wrapper_source(base, inner)
    return renamed(text, set(DEVICE_KERNELS), "device_"), shared


def _series_start_source(n: int, zero: str) -> str:
    """A series element's ``initial_state``: the device virgin at the displacement u where the
    spring holds its force at rest, u + compliance F_device(u) = x0 less the zero (secants from
    u = x0 and the u of a device that held its force there, at least one, so that the tangents
    are the converged start's even where x0 is already the root; an elastic device's g(u) rises
    with a slope of 1 + compliance K)."""
    d = "s" if n else "()"
    start = "    s = device_initial_state(m[0], u)\n" if n else ""
    # a device without states gives nothing to start: its call would be dead code, which the C
    # translation refuses

    def residual(indent: str) -> str:
        return (start.replace("    ", indent, 1) + f"{indent}f = device_force(m[0], {d}, u, 0.0)\n"
                f"{indent}g = u + c * f - x0z\n")
    last = tuple_text([f"s[{i}]" for i in range(n)] + ["u"])
    return (f"def initial_state(m, x0):\n    c = m[1][0]\n    x0z = x0{zero}\n    u = x0z\n{start}"
            f"    if c == 0.0:\n        return {last}\n"
            f"    f = device_force(m[0], {d}, u, 0.0)\n    g = u + c * f - x0z\n"
            f"    ua = u\n    ga = g\n"
            f"    if g != 0.0:\n        u = u - g\n    else:\n        u = u + 1e-7 * (abs(u) + 1.0)\n{residual('    ')}"
            f"    for k in range({SERIES_ITERATIONS}):\n"
            f"        if g == ga:\n            break\n"
            f"        ub = u\n        gb = g\n        u = ub - gb * (ub - ua) / (gb - ga)\n{residual('        ')}"
            f"        ua = ub\n        ga = gb\n"
            f"        if abs(g) <= 4e-16 * (abs(u) + c * abs(f) + abs(x0z)):\n            break\n"
            f"    return {last}\n")


def _series_integrate_source(n: int, zero: str) -> str:
    """A series element's ``integrate`` (``series_wrapper_source``): the device's ``n`` states, then
    its displacement; ``zero`` the text taken off x before the spring (the rig's displacement zero).
    Each of the device's steps gets the substeps ``max_substeps`` allows a step."""
    d = tuple_text(f"state[{i}]" for i in range(n))

    def out(name: str, last: str) -> str:
        return tuple_text([f"{name}[{i}]" for i in range(n)] + [last])

    # the device's velocity w at which the compliance's force at the step's end is the device's:
    # r(w) = x1 - (u0 + w h) - compliance F_device(w) falls with w, at a slope of about
    # h + compliance (C + K h) (the device's dashpot C and stiffness K at the step's start, from its
    # force); a Newton step from w = v on that slope, then secants, the older end's residual halved
    # where two new ones fall on one side (Illinois' regula falsi), until r is within rounding of
    # the travel or stops changing (rounding); then one secant more through the two latest points,
    # kept where it is no worse: its slope is the step's own, so the tangents through it are the
    # converged step's (implicit) derivative, not the path's
    def residual(indent: str) -> str:
        return "".join(indent + line + "\n" for line in (
            "s, used, status = device_integrate(m[0], d, u0, w, h, max_substeps)",
            "total = total + used",
            "if status != OK:", "    return state, total, status",
            "r = x1 - (u0 + w * h) - c * device_force(m[0], s, u0 + w * h, w)"))
    return (
        f"def integrate(m, state, x, v, h, max_substeps):\n"
        f"    c = m[1][0]\n    d = {d}\n"
        # (+ 0.0 * u0, exact for a finite u0, keeps the new u a value of the state's for the
        # tangents, whose zero of a value that is a tuple at run time they cannot size)
        f"    if c == 0.0:\n        s, used, status = device_integrate(m[0], d, x{zero}, v, h, max_substeps)\n"
        f"        return {out('s', f'x{zero} + v * h + 0.0 * state[{n}]')}, used, status\n"
        f"    u0 = state[{n}]\n    x1 = x{zero} + v * h\n    total = 0\n"
        f"    f0 = device_force(m[0], d, u0, 0.0)\n    du = 1e-6 * (abs(u0) + 1.0)\n"
        f"    slope = device_force(m[0], d, u0, 1.0) - f0 + h * (device_force(m[0], d, u0 + du, 0.0) - f0) / du\n"
        f"    if slope < 0.0:\n        slope = 0.0\n    slope = h + c * slope\n"
        f"    w = v\n{residual('    ')}"
        f"    tolerance = 1e-12 * (abs(x1 - u0) + abs(w * h)) + 4e-16 * (abs(x1) + abs(u0))\n"
        f"    wa = w\n    ra = r\n"
        f"    if r != 0.0:\n        w = w + r / slope\n    else:\n        w = w + 1e-7 * (abs(w) + 1.0)\n"
        f"{residual('    ')}"
        f"    for k in range({SERIES_ITERATIONS}):\n"
        f"        if r == ra:\n            break\n"
        f"        wb = w\n        rb = r\n        w = wb - rb * (wb - wa) / (rb - ra)\n{residual('        ')}"
        f"        if abs(r) <= tolerance or abs(w - wb) <= 4e-16 * (abs(w) + abs(wb)) or r == rb:\n"
        f"            if r != rb:\n"
        f"                wc = w\n                rc = r\n                sc = s\n"
        f"                w = wc - rc * (wc - wb) / (rc - rb)\n{residual('                ')}"
        f"                if abs(r) > abs(rc):\n                    w = wc\n                    s = sc\n"
        f"            return {out('s', 'u0 + w * h')}, total, OK\n"
        f"        if (r < 0.0) != (rb < 0.0) or (ra < 0.0) == (r < 0.0):\n            wa = wb\n            ra = rb\n"
        f"        else:\n            ra = 0.5 * ra\n"
        f"    if r == ra:         # the iteration stands still: r is at its rounding\n"
        f"        return {out('s', 'u0 + w * h')}, total, OK\n"
        f"    return state, total, TOO_MANY_SUBSTEPS\n")


def series_wrapper_source(base: BushingModel, options) -> tuple[str, set[str]]:
    """The kernels of a model whose options hold a series element (``options.series``): the device
    (the base and the options before it, ``device_*``) in series with the compliance, the options
    after it (stateless: the rig's offsets) outside both; and the shared names they import."""
    from .options import ELEMENTS, Options
    series = next(element for element, _ in options.elements if element.series)
    inner = Options(tuple(item for item in options.chosen if ELEMENTS[item[0]].order < series.order))
    outer = [(element, count) for element, count in options.elements if element.order > series.order]
    for element, count in outer:
        if element.states(count) or element.switches(count) or element.series:
            raise ModelContractError(f"the {element.token} option has states or switches: it cannot sit outside "
                                     f"the {series.token} option's device")
    device, shared = _device_source(base, inner)
    held = len(base.static_spring) if inner.replaces_static_spring else 0
    k = len(base.specs) - held + sum(len(element.specs(count)) for element, count in inner.elements)
    n = len(base.states) + sum(len(element.states(count)) for element, count in inner.elements)
    parts = [f"device_prepare({tuple_text(f'p[{i}]' for i in range(k))})", f"(p[{k}],)"]
    index, slots = k + 1, []
    for element, count in outer:
        size = len(element.specs(count))
        slots.append((element, Slot(f"m[{len(parts)}]")))
        parts.append(element.prepare(tuple(f"p[{index + i}]" for i in range(size))))
        index += size
    zero = "".join(f" - {element.displacement_zero(slot)}" for element, slot in slots
                   if element.displacement_zero is not None)
    outside = "".join(f" + {element.force(slot)}" for element, slot in slots if element.force is not None)
    resting = "".join(f" - {element.rest_force(slot)}" for element, slot in slots if element.rest_force is not None)
    d = tuple_text(f"state[{i}]" for i in range(n))

    def out(name: str, last: str) -> str:
        return tuple_text([f"{name}[{i}]" for i in range(n)] + [last])
    source = [f"def prepare(p):\n    return {tuple_text(parts)}\n"]
    if "def device_prepare_step" in device:
        source.append(f"def prepare_step(m, h):\n    return "
                      f"{tuple_text(['device_prepare_step(m[0], h)'] + [f'm[{i}]' for i in range(1, len(parts))])}\n")
    source += [
        _series_start_source(n, zero),
        f"def jump(m, state, jump_mm):\n"
        f"    if m[1][0] == 0.0:\n        s, status = device_jump(m[0], {d}, jump_mm)\n"
        f"        return {out('s', f'state[{n}] + jump_mm')}, status\n"
        f"    return state, OK\n",
        _series_integrate_source(n, zero),
    ]
    rate = (f"    c = m[1][0]\n    d = {d}\n    u = state[{n}]\n    w = v\n"
            f"    if c == 0.0:\n        u = x{zero}\n"
            f"    else:\n        f0 = device_force(m[0], d, u, 0.0)\n"
            f"        w = ((x{zero} - u) / c - f0) / (device_force(m[0], d, u, 1.0) - f0)\n")
    source += [
        # a device without states gives nothing to rate: its call would be dead code
        f"def derivatives(m, state, x, v):\n{rate}" + ("    r = device_derivatives(m[0], d, u, w)\n" if n else "")
        + f"    return {out('r', 'w')}\n",
        f"def force(m, state, x, v):\n    c = m[1][0]\n"
        f"    if c == 0.0:\n        f = device_force(m[0], {d}, x{zero}, v)\n"
        f"    else:\n        f = (x{zero} - state[{n}]) / c\n    return f{outside}\n",
        f"def switches(m, state, x, v):\n{rate}    return device_switches(m[0], d, u, w)\n"]
    if "def device_resting_state" in device:
        source.append(f"def resting_state(m, x0, force):\n    f = force{resting}\n"
                      f"    u = x0{zero} - m[1][0] * f\n" + ("    s = device_resting_state(m[0], u, f)\n" if n else "")
                      + f"    return {out('s', 'u')}\n")
    if "def device_update" in device:
        source.append(f"def update(m, state, x, v):\n{rate}    s = device_update(m[0], d, u, w)\n"
                      f"    return {out('s', 'u')}\n")
    return device + "\n\n\n" + "\n\n".join(source), shared | {"OK", "TOO_MANY_SUBSTEPS"}


def law_wrapper_source(base: BushingModel, options) -> tuple[str, set[str]]:
    """The kernels of a model whose options hold a law on its parameters (``OptionElement.law``: a
    temperature law): the model without the law (every kernel as it is, its ``prepare`` renamed
    ``unconditioned_prepare``) under a ``prepare`` that multiplies each of its parameters by its
    role's factor (``ParameterSpec.temperature_role``) first; and the shared names they import."""
    from .options import Options
    laws = [(element, count) for element, count in options.elements if element.law is not None]
    if len(laws) > 1:
        raise ModelContractError(f"{' and '.join(element.token for element, _ in laws)}: give one law on the "
                                 "parameters")
    law, count = laws[0]
    heating = [(element, c) for element, c in options.elements if element.heating]
    inner = Options(tuple(item for item in options.chosen
                          if item[0] != law.token and not any(item[0] == e.token for e, _ in heating)))
    text, shared = wrapper_source(base, inner)
    held = set(base.static_spring) if options.replaces_static_spring else set()
    specs = [spec for spec in base.specs if spec.name not in held]
    specs += [spec for element, c in options.elements for spec in element.specs(c)]
    own = {spec.name for element, c in [laws[0], *heating] for spec in element.specs(c)}
    index = {spec.name: i for i, spec in enumerate(specs)}

    def law_body(temperature: str, parameter) -> tuple[str, str]:
        """(the law's lines at ``temperature``, the inner model's scaled parameters' tuple), the
        parameters' texts ``parameter(i)``."""
        texts = [temperature] + [parameter(index[spec.name]) for spec in law.specs(count)[1:]]
        lines, factors = law.law(tuple(texts))
        scaled = [f"{parameter(i)} * {factors[spec.temperature_role]}" if spec.temperature_role in factors
                  else parameter(i) for i, spec in enumerate(specs) if spec.name not in own]
        # a factor no parameter takes is left out (the C translation refuses a value never read)
        unused = {name for name in factors.values() if not any(name in text for text in scaled)}
        body = "".join(f"    {line}\n" for line in lines if line.split(" = ")[0] not in unused)
        return body, tuple_text(scaled)
    temperature = f"p[{index[law.specs(count)[0].name]}]"
    if heating:
        return heated_source(base, inner, text, shared, law_body, temperature, index, heating[0])
    text = renamed(text, {"prepare"}, "unconditioned_")
    body, scaled = law_body(temperature, lambda i: f"p[{i}]")
    prepare = f"def prepare(p):\n{body}    return unconditioned_prepare({scaled})\n"
    return text + "\n\n\n" + prepare, shared


HEATED_KERNELS = DEVICE_KERNELS
"""The kernels of a heated model's inner model, renamed ``unheated_<name>`` under the thermal wrapper."""


def heated_source(base: BushingModel, inner, text: str, shared: set[str], law_body, ambient: str, index: dict,
                  heating) -> tuple[str, set[str]]:
    """The kernels of a model with a temperature law and a thermal state (``options.heating``):
    the inner model (without the law and the heating, its kernels renamed ``unheated_*``) at the
    rubber's temperature, the state's last entry; ``heated_constants(m, T)`` its constants there
    (the law at T); the thermal state stepped by the trapezoid of F v and the cooling law.
    ``ambient``: the text of the law's temperature parameter (then the surroundings')."""
    element, count = heating
    inner_text = renamed(text, set(HEATED_KERNELS), "unheated_")
    n = len(base.states) + sum(len(e.states(c)) for e, c in inner.elements)
    size = len(index)
    capacity, resistance = (index[spec.name] for spec in element.specs(count))
    own = tuple_text(f"state[{i}]" for i in range(n))

    def out(name: str, last: str) -> str:
        return tuple_text([f"{name}[{i}]" for i in range(n)] + [last])
    body, scaled = law_body(ambient, lambda i: f"p[{i}]")
    at_T, scaled_T = law_body("temperature_K", lambda i: f"m[1][{i}]")
    if "def unheated_prepare_step" in inner_text:
        raise ModelContractError(f"the {base.name} model's step has constants of its own per step size "
                                 "(prepare_step): self-heating, which prepares the model again at every step's "
                                 "temperature, is not generated for it yet")
    source = [
        f"def prepare(p):\n{body}    return (unheated_prepare({scaled}), {tuple_text(f'p[{i}]' for i in range(size))}, "
        f"(p[{capacity}], p[{resistance}], {ambient}))\n",
        f"def heated_constants(m, temperature_K):\n{at_T}    return unheated_prepare({scaled_T})\n",
        "def initial_state(m, x0):\n" + ("    s = unheated_initial_state(m[0], x0)\n" if n else "")
        + f"    return {out('s', 'm[2][2]')}\n",
        f"def jump(m, state, jump_mm):\n    c = heated_constants(m, state[{n}])\n"
        f"    s, status = unheated_jump(c, {own}, jump_mm)\n    return {out('s', f'state[{n}]')}, status\n",
        f"def integrate(m, state, x, v, h, max_substeps):\n"
        f"    temperature_K = state[{n}]\n    c = heated_constants(m, temperature_K)\n"
        f"    f0 = unheated_force(c, {own}, x, v)\n"
        f"    s, used, status = unheated_integrate(c, {own}, x, v, h, max_substeps)\n"
        f"    f1 = unheated_force(c, s, x + v * h, v)\n"
        f"    # the trapezoid of F v [N.mm/s = mW] over the step, in W\n"
        f"    power = 0.0005 * (f0 + f1) * v\n"
        f"    decay = math.exp(-h / (m[2][0] * m[2][1]))\n"
        f"    heated = m[2][2] + (temperature_K - m[2][2]) * decay + power * m[2][1] * (1.0 - decay)\n"
        f"    if status == OK and not math.isfinite(heated):\n        status = NOT_FINITE\n"
        f"    return {out('s', 'heated')}, used, status\n",
        f"def force(m, state, x, v):\n    return unheated_force(heated_constants(m, state[{n}]), {own}, x, v)\n",
        f"def derivatives(m, state, x, v):\n    c = heated_constants(m, state[{n}])\n"
        + (f"    d = unheated_derivatives(c, {own}, x, v)\n" if n else "")
        + f"    power = 0.001 * unheated_force(c, {own}, x, v) * v\n"
        f"    return {out('d', f'(power - (state[{n}] - m[2][2]) / m[2][1]) / m[2][0]')}\n",
        f"def switches(m, state, x, v):\n    return unheated_switches(heated_constants(m, state[{n}]), {own}, x, v)\n"]
    if "def unheated_resting_state" in inner_text:
        source.append("def resting_state(m, x0, force):\n" + ("    s = unheated_resting_state(m[0], x0, force)\n"
                                                              if n else "")
                      + f"    return {out('s', 'm[2][2]')}\n")
    if "def unheated_update" in inner_text:
        source.append(f"def update(m, state, x, v):\n    s = unheated_update(heated_constants(m, state[{n}]), {own}, x, v)\n"
                      f"    return {out('s', f'state[{n}]')}\n")
    return inner_text + "\n\n\n" + "\n\n".join(source), shared | {"OK", "NOT_FINITE"}


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
