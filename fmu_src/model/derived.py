"""Options any model can take: a measured backbone, travel limits, the rig's offsets.

A derived model is a registered model (its *base*) with options, named
``<base>+<option>[+<option>...]``, its FMI identifier the base's with the options appended
(``proposed+limits`` -> ``BoucWenBushing_Limits``):

- ``backbone<K>``: a measured static force-deflection curve through K knots (``backbone_x1`` ...
  [mm], ``backbone_F1`` ... [N]), the monotone cubic of ``elements.pchip_slope`` (scipy's
  PchipInterpolator: monotone data give a monotone curve) and straight beyond the end knots with
  their slopes; it replaces the base's static spring (``BushingModel.static_spring``, held at 0)
  and adds to its force. A model whose static spring carries more than its static force (the
  paper's k0 also carries the left block's hysteresis) names none, and the backbone adds to it;
- ``limits``: a travel limit on each side (``elements.limit_force``): a gap ``limit_gap_pos``,
  ``limit_gap_neg`` [mm] (free play: no force inside it), then a stiffness ``limit_k_*``
  [N/mm^e] with an exponent ``limit_exponent_*`` >= 1 and a damping ``limit_c_*`` [N.s/mm] that
  ramps in over ``limit_depth_*`` [mm], the corners rounded over ``limit_width`` [mm] (0: hard
  corners, stated as switches), as MSC Adams' bushing limits, Altair's mount limits and
  RecurDyn's clearance describe them;
- ``rig``: a displacement zero ``rig_displacement_zero`` [mm] and a load-cell zero
  ``rig_force_zero`` [N] of a measured test, F_measured = F(x - zero) + force zero: what a fit
  estimates as nuisance parameters and keeps out of the FMU (an FMU takes them, where asked, as
  its mounting's ``offset`` and ``preload``).

Every option works on the base's displacement u = x - the displacement zero (x where there is no
rig option): F = base(u) + backbone(u) + limits(u, v) + force zero.

One definition. The derived model is a kernel module of its own, generated as source text and
registered beside the models (``<package>.<base>__<options>``): the base's kernels and the
functions and numeric constants they reach, renamed ``base_<name>``, then the wrapper kernels
the options need. It imports nothing but ``math`` and the shared machinery and elements, so numba
compiles it, the C translator translates it and the tangent generator differentiates it as it
does any model module; the base model itself, its generated C and its compiled module are
unchanged. ``registry.get_model`` makes a derived model from its name or identifier on demand
(in every worker process and inside a packed pythonfmu FMU alike).
"""
from __future__ import annotations

import ast
import builtins
import inspect
import linecache
import re
import sys
import types
from dataclasses import dataclass, replace

from . import elements, integration
from .definition import BushingModel, ModelContractError, SearchBox, SearchCoordinate, StateSpec
from .parameter_specs import Constraint, ParameterError, ParameterSpec
from .search_coordinates import KIND

SEPARATOR = "+"
BACKBONE, LIMITS, RIG = "backbone", "limits", "rig"
MAX_KNOTS = 32
"""The most knots a backbone takes (a static curve needs a few; each is two FMU parameters)."""
KERNELS = ("prepare", "initial_state", "jump", "integrate", "force", "derivatives", "switches")
"""The base's kernels a derived model wraps (``update`` and ``prepare_step`` too, where it has them)."""
LIMIT_SIDES = (("pos", "positive"), ("neg", "negative"))
LIMIT_HELD = (("limit_exponent_pos", 2.0), ("limit_exponent_neg", 2.0), ("limit_c_pos", 0.0), ("limit_c_neg", 0.0),
              ("limit_depth_pos", 1.0), ("limit_depth_neg", 1.0))
"""What a fit holds of the limits unless told otherwise (``fit(fixed=...)``): a quadratic stop
(exponent 2), no damping (so the depth is immaterial)."""


@dataclass(frozen=True)
class Options:
    """Which options a derived model has: ``knots`` of a backbone (0: none), ``limits``, ``rig``."""
    knots: int = 0
    limits: bool = False
    rig: bool = False

    def __post_init__(self):
        if self.knots and not 2 <= self.knots <= MAX_KNOTS:
            raise ParameterError(f"a backbone of {self.knots} knots: give 2 to {MAX_KNOTS}")

    @property
    def tokens(self) -> tuple[str, ...]:
        """The options' names in their one order: backbone<K>, limits, rig."""
        return ((f"{BACKBONE}{self.knots}",) if self.knots else ()) + ((LIMITS,) if self.limits else ()) \
            + ((RIG,) if self.rig else ())

    def __bool__(self) -> bool:
        return bool(self.tokens)

    def without_rig(self) -> "Options":
        return replace(self, rig=False)

    @classmethod
    def parse(cls, tokens) -> "Options":
        """From option names (``backbone5``, ``limits``, ``rig``; any order, any case)."""
        knots, limits, rig = 0, False, False
        for token in tokens:
            word = token.strip().lower()
            match = re.fullmatch(rf"{BACKBONE}(\d+)", word)
            if match:
                knots = int(match.group(1))
            elif word == LIMITS:
                limits = True
            elif word == RIG:
                rig = True
            else:
                raise ParameterError(f"unknown model option {token!r}; the options are {BACKBONE}<K> (a backbone of "
                                     f"K knots, 2 to {MAX_KNOTS}), {LIMITS} and {RIG}")
        return cls(knots, limits, rig)


def split_name(name: str) -> tuple[str, Options]:
    """(the base's name or identifier, the options) of a derived model's name
    (``proposed+limits``) or identifier (``BoucWenBushing_Limits``)."""
    if SEPARATOR in name:
        base, *tokens = name.split(SEPARATOR)
        return base, Options.parse(tokens)
    base, *tokens = name.split("_")
    # an identifier: the base's (which may hold underscores) and then the options' capitalised words
    words = name.split("_")
    for cut in range(1, len(words) + 1):
        tail = words[cut:]
        if all(re.fullmatch(r"(Backbone\d+|Limits|Rig)", word) for word in tail):
            return "_".join(words[:cut]), Options.parse(tail)
    return name, Options()


def derived_name(base: BushingModel, options: Options) -> str:
    return SEPARATOR.join((base.name, *options.tokens))


def derived_identifier(base: BushingModel, options: Options) -> str:
    return "_".join((base.identifier, *(token.capitalize() for token in options.tokens)))


# ------------------------------------------------------------------------------ parameters
def backbone_specs(knots: int) -> tuple[ParameterSpec, ...]:
    """The knots' positions [mm] and forces [N]: ``backbone_x1`` ... ``backbone_xK``, ``backbone_F1`` ..."""
    return (tuple(ParameterSpec(f"backbone_x{i + 1}", "mm", f"the backbone's knot {i + 1}: its displacement "
                                "(increasing from knot to knot)", bound_powers=None) for i in range(knots))
            + tuple(ParameterSpec(f"backbone_F{i + 1}", "N", f"the backbone's knot {i + 1}: its static force "
                                  "(not decreasing from knot to knot)", bound_powers=(0, 0)) for i in range(knots)))


def backbone_constraints(knots: int) -> tuple[Constraint, ...]:
    """Knots increasing, forces not decreasing: refused otherwise (both FMUs and parameter files)."""
    out = []
    for i in range(1, knots):
        out.append(Constraint(((f"backbone_x{i + 1}", 1.0), (f"backbone_x{i}", -1.0)), 0.0, True, True, "mm",
                              "the backbone's knots must increase"))
        out.append(Constraint(((f"backbone_F{i + 1}", 1.0), (f"backbone_F{i}", -1.0)), 0.0, False, True, "N",
                              "a backbone is monotone: its forces must not decrease from knot to knot"))
    return tuple(out)


def limit_specs() -> tuple[ParameterSpec, ...]:
    out = []
    for side, word in LIMIT_SIDES:
        out += [
            ParameterSpec(f"limit_gap_{side}", "mm", f"the {word} travel limit's gap: free travel before it engages",
                          minimum=0.0, why="a gap is a magnitude"),
            ParameterSpec(f"limit_k_{side}", "N/mm", f"the {word} limit's stiffness: force k*d^e at penetration d "
                          "[mm] (N/mm^e)", minimum=0.0, why="a negative stiffness is unstable", bound_powers=None),
            ParameterSpec(f"limit_exponent_{side}", "1", f"the {word} limit's exponent e (1: linear, 2: a "
                          "progressive bump stop)", minimum=1.0, why="below 1 its stiffness is infinite at contact"),
            ParameterSpec(f"limit_c_{side}", "N.s/mm", f"the {word} limit's damping, fully in at the depth",
                          minimum=0.0, why="a negative dashpot adds energy"),
            ParameterSpec(f"limit_depth_{side}", "mm", f"the penetration over which the {word} limit's damping "
                          "ramps in", minimum=0.0, exclusive=True, why="a ramp needs a length"),
        ]
    out.append(ParameterSpec("limit_width", "mm", "the travel over which each limit's corner engages (0: hard "
                             "corners)", minimum=0.0, why="a width is a magnitude"))
    return tuple(out)


def rig_specs() -> tuple[ParameterSpec, ...]:
    return (ParameterSpec("rig_displacement_zero", "mm", "the rig's displacement zero: the model sees x - it",
                          bound_powers=None),
            ParameterSpec("rig_force_zero", "N", "the load cell's zero: added to the model's force",
                          bound_powers=(0, 0)))


def option_specs(options: Options) -> tuple[ParameterSpec, ...]:
    return ((backbone_specs(options.knots) if options.knots else ()) + (limit_specs() if options.limits else ())
            + (rig_specs() if options.rig else ()))


# ------------------------------------------------------------------------------ source
def _reached(base: BushingModel, module: types.ModuleType) -> tuple[list[str], dict[str, object], set[str]]:
    """(the functions of the base's module its kernels reach, in source order; the numeric
    constants they read; the names they import from the machinery or the elements). Raises
    ModelContractError for a global of another kind."""
    tree = ast.parse(inspect.getsource(module))
    defined = {node.name: node for node in tree.body if isinstance(node, ast.FunctionDef)}
    roots = [getattr(base, name).__name__ for name in KERNELS]
    roots += [name for name in ("prepare_step",) if name in defined]
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
    tree = ast.parse(inspect.getsource(module))
    renamer = _Rename(set(functions) | set(constants))
    lines = [f"base_{name} = {value!r}" for name, value in sorted(constants.items())]
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name in functions:
            node.decorator_list = []
            lines.append(ast.unparse(renamer.visit(node)))
    return "\n\n\n".join(lines), shared


def _tuple(names) -> str:
    names = list(names)
    return "(" + ", ".join(names) + ("," if len(names) == 1 else "") + ")"


def wrapper_source(base: BushingModel, options: Options) -> tuple[str, set[str]]:
    """The derived model's kernels, delegating to the renamed base's (module docstring); and the
    shared names they import."""
    held = set(base.static_spring) if options.knots else set()
    base_values = [("0.0" if spec.name in held else None) for spec in base.specs]
    index = 0
    for i, value in enumerate(base_values):
        if value is None:
            base_values[i] = f"p[{index}]"
            index += 1
    parts, slots = [f"base_prepare({_tuple(base_values)})"], []
    if options.knots:
        k = options.knots
        parts.append(f"backbone_prepare({_tuple(f'p[{index + i}]' for i in range(2 * k))})")
        slots.append(("backbone", len(parts) - 1))
        index += 2 * k
    if options.limits:
        parts.append(_tuple(f"p[{index + i}]" for i in range(11)))
        slots.append(("limits", len(parts) - 1))
        index += 11
    if options.rig:
        parts.append(_tuple(f"p[{index + i}]" for i in range(2)))
        slots.append(("rig", len(parts) - 1))
        index += 2
    slot = dict(slots)
    zero = f" - m[{slot['rig']}][0]" if options.rig else ""
    u = "x" + zero
    has_step = "prepare_step" in vars(sys.modules[base.kernel_module])
    source = [f"def prepare(p):\n    return {_tuple(parts)}\n"]
    if has_step:
        rest = ", ".join(f"m[{i}]" for i in range(1, len(parts)))
        source.append(f"def prepare_step(m, h):\n    return (base_prepare_step(m[0], h), {rest})\n" if rest else
                      "def prepare_step(m, h):\n    return (base_prepare_step(m[0], h),)\n")
    source.append(f"def initial_state(m, x0):\n    return base_initial_state(m[0], x0{zero})\n")
    source.append("def jump(m, state, jump_mm):\n    return base_jump(m[0], state, jump_mm)\n")
    source.append(f"def integrate(m, state, x, v, h, max_substeps):\n"
                  f"    return base_integrate(m[0], state, {u}, v, h, max_substeps)\n")
    force = [f"    u = {u}", "    f = base_force(m[0], state, u, v)"]
    if options.knots:
        force.append(f"    f = f + backbone_force(m[{slot['backbone']}], u)")
    if options.limits:
        force.append(f"    f = f + limits_force(m[{slot['limits']}], u, v)")
    if options.rig:
        force.append(f"    f = f + m[{slot['rig']}][1]")
    source.append("def force(m, state, x, v):\n" + "\n".join(force) + "\n    return f\n")
    source.append(f"def derivatives(m, state, x, v):\n    return base_derivatives(m[0], state, {u}, v)\n")
    switches = len(base.switch_specs)
    own = [f"s[{i}]" for i in range(switches)]
    if options.limits:
        own += [f"u - m[{slot['limits']}][0]", f"u + m[{slot['limits']}][5]"]
    body = f"    u = {u}\n"
    body += f"    s = base_switches(m[0], state, u, v)\n" if switches else ""
    source.append("def switches(m, state, x, v):\n" + body + f"    return {_tuple(own) if own else '()'}\n")
    if base.update is not None:
        source.append(f"def update(m, state, x, v):\n    return base_update(m[0], state, {u}, v)\n")
    shared = set()
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
    lines.append(f"    return {_tuple(xs + fs + ds)}")
    prepare = "\n".join(lines) + "\n"
    lines = ["def backbone_force(b, u):", f"    {', '.join(xs + fs + ds)} = b",
             "    if u <= x0:", "        return f0 + d0 * (u - x0)"]
    for i in range(k - 1):
        lines += [f"    if u <= x{i + 1}:",
                  f"        return hermite(u, x{i}, x{i + 1}, f{i}, f{i + 1}, d{i}, d{i + 1})"]
    lines.append(f"    return f{k - 1} + d{k - 1} * (u - x{k - 1})")
    return prepare + "\n\n" + "\n".join(lines) + "\n"


def derived_source(base: BushingModel, options: Options) -> str:
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


# ------------------------------------------------------------------------------ the model
def _module(base: BushingModel, options: Options) -> types.ModuleType:
    """The derived model's kernel module, generated and registered once per process."""
    package = base.kernel_module.rpartition(".")[0]
    name = f"{package}.{base.name}__{'_'.join(options.tokens)}"
    if name in sys.modules:
        return sys.modules[name]
    source = derived_source(base, options)
    filename = f"<derived model {name}>"
    linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
    module = types.ModuleType(name, None)
    module.__file__ = filename
    module.__package__ = package
    sys.modules[name] = module
    try:
        exec(compile(source, filename, "exec"), module.__dict__)
    except BaseException:
        del sys.modules[name]
        raise
    return module


def _search(base: BushingModel, options: Options) -> SearchBox:
    """The derived model's box: the base's (less its static spring, with a backbone) and the options'."""
    held_out = set(base.static_spring) if options.knots else set()
    if base.search is not None:
        box = base.search
        coordinates = tuple(c for c in box.coordinates if c.parameter not in held_out)
        unit_weights, zeros, held = box.unit_weights, box.zeros, box.held
    else:   # a model fitted by linear least squares: its regressors searched, its held values held
        kinds = {"displacement": (KIND.stiffness, -4.0, 1.0), "velocity": (KIND.damping, -5.0, 1.0)}
        coordinates = tuple(SearchCoordinate(name, *kinds[regressor]) for name, regressor in base.linear.regressors
                            if name not in held_out)
        unit_weights, zeros, held = (), (), base.linear.held
    zeros = tuple(name for name in zeros if name not in held_out)
    if options.knots:
        k = options.knots
        anchor = k // 2
        coordinates += (SearchCoordinate(f"backbone_F{anchor + 1}", KIND.offset_force, -1.0, 1.0),)
        for i in range(anchor + 1, k):
            coordinates += (SearchCoordinate(f"backbone_F{i + 1}", KIND.segment, -4.0, 2.0,
                                             over=(f"backbone_x{i + 1}", f"backbone_x{i}"), partner=f"backbone_F{i}"),)
        for i in range(anchor - 1, -1, -1):
            coordinates += (SearchCoordinate(f"backbone_F{i + 1}", KIND.segment, -4.0, 2.0,
                                             over=(f"backbone_x{i + 1}", f"backbone_x{i + 2}"),
                                             partner=f"backbone_F{i + 2}"),)
    if options.limits:
        for side, _ in LIMIT_SIDES:
            coordinates += (SearchCoordinate(f"limit_gap_{side}", KIND.travel, -3.0, 0.3),
                            SearchCoordinate(f"limit_k_{side}", KIND.stiffness, -2.0, 3.0))
        coordinates += (SearchCoordinate("limit_width", KIND.travel, -4.0, -1.0),)
        held = held + LIMIT_HELD
    if options.rig:
        coordinates += (SearchCoordinate("rig_displacement_zero", KIND.offset_travel, -0.25, 0.25),
                        SearchCoordinate("rig_force_zero", KIND.offset_force, -0.5, 0.5))
    return SearchBox(coordinates, unit_weights=unit_weights, zeros=zeros, held=held,
                     loop_start=base.search.loop_start if base.search is not None and not options.knots else None,
                     table_start=None)


def derive(base: BushingModel, options: Options) -> BushingModel:
    """``base`` with ``options`` (module docstring): a new model, generated once per process."""
    if not options:
        return base
    name = derived_name(base, options)
    cached = _DERIVED.get(name)
    if cached is not None:
        return cached
    held = set(base.static_spring) if options.knots else set()
    specs = tuple(spec for spec in base.specs if spec.name not in held) + option_specs(options)
    names = [spec.name for spec in specs]
    clashes = sorted({n for n in names if names.count(n) > 1} | ({"offset", "preload"} & {s.name for s in option_specs(options)}))
    if clashes:
        raise ModelContractError(f"the {base.name} model's parameters {clashes} clash with its options'")
    module = _module(base, options)
    g = vars(module)
    constraints = tuple(c for c in base.constraints if not any(term in held for term, _ in c.terms))
    if options.knots:
        constraints += backbone_constraints(options.knots)
    switch_specs = base.switch_specs
    if options.limits:
        k = len(switch_specs)
        switch_specs += (StateSpec("limit_upper", k, "m", "u - limit_gap_pos: the positive limit's corner"),
                         StateSpec("limit_lower", k + 1, "m", "u + limit_gap_neg: the negative limit's corner"))
    words = {BACKBONE: "a measured backbone", LIMITS: "travel limits", RIG: "the rig's offsets"}
    title = f"{base.title} with " + ", ".join(words[t.rstrip('0123456789')] for t in options.tokens)
    model = BushingModel(
        name, derived_identifier(base, options), title, specs, base.states, base.default_file,
        g["prepare"], g["initial_state"], g["jump"], g["integrate"], g["force"], g["derivatives"], g["switches"],
        constraints=constraints, switch_specs=switch_specs, update=g.get("update"), search=_search(base, options),
        description=f"{base.description or base.title}; with {', '.join(options.tokens)}",
        plot_style=base.plot_style, rank=base.rank, settling_s=base.settling_s, rotational=base.rotational,
        static_spring=(), base=base, options=options)
    _DERIVED[name] = model
    return model


_DERIVED: dict[str, BushingModel] = {}
