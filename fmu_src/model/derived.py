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
- ``maxwell``: a Maxwell element in parallel (``maxwell_k`` [N/mm] in series with ``maxwell_c``
  [N.s/mm]: a relaxation of time constant c/k, filled rubber's rate dependence), its force a state
  of its own (``maxwell_f``, after the base's), stepped exactly;
- ``rig``: a displacement zero ``rig_displacement_zero`` [mm] and a load-cell zero
  ``rig_force_zero`` [N] of a measured test, F_measured = F(x - zero) + force zero: what a fit
  estimates as nuisance parameters and keeps out of the FMU (an FMU takes them, where asked, as
  its mounting's ``offset`` and ``preload``).

Every option works on the base's displacement u = x - the displacement zero (x where there is no
rig option): F = base(u) + backbone(u) + limits(u, v) + Maxwell force + force zero.

One definition. The derived model is a kernel module of its own, generated as source text
(``derived_source``) and registered beside the models (``<package>.<base>__<options>``): numba
compiles it, the C translator translates it and the tangent generator differentiates it as it
does any model module; the base model itself, its generated C and its compiled module are
unchanged. ``registry.get_model`` makes a derived model from its name or identifier on demand
(in every worker process and inside a packed pythonfmu FMU alike).
"""
from __future__ import annotations

import linecache
import math
import re
import sys
import types
from dataclasses import dataclass, replace

from .definition import BushingModel, ModelContractError, SearchBox, SearchCoordinate, StateSpec
from .derived_source import derived_source
from .parameter_specs import Constraint, ParameterError, ParameterSpec
from .search_coordinates import KIND

SEPARATOR = "+"
BACKBONE, LIMITS, MAXWELL, RIG = "backbone", "limits", "maxwell", "rig"
MAX_KNOTS = 32
"""The most knots a backbone takes (a static curve needs a few; each is two FMU parameters)."""
LIMIT_SIDES = (("pos", "positive"), ("neg", "negative"))
LIMIT_HELD = (("limit_exponent_pos", 2.0), ("limit_exponent_neg", 2.0), ("limit_c_pos", 0.0), ("limit_c_neg", 0.0),
              ("limit_depth_pos", 1.0), ("limit_depth_neg", 1.0))
"""What a fit holds of the limits unless told otherwise (``fit(fixed=...)``): a quadratic stop
(exponent 2), no damping (so the depth is immaterial)."""


@dataclass(frozen=True)
class Options:
    """Which options a derived model has: ``knots`` of a backbone (0: none), ``limits``, ``rig``,
    ``maxwell``."""
    knots: int = 0
    limits: bool = False
    rig: bool = False
    maxwell: bool = False

    def __post_init__(self):
        if self.knots and not 2 <= self.knots <= MAX_KNOTS:
            raise ParameterError(f"a backbone of {self.knots} knots: give 2 to {MAX_KNOTS}")

    @property
    def tokens(self) -> tuple[str, ...]:
        """The options' names in their one order: backbone<K>, limits, maxwell, rig."""
        return ((f"{BACKBONE}{self.knots}",) if self.knots else ()) + ((LIMITS,) if self.limits else ()) \
            + ((MAXWELL,) if self.maxwell else ()) + ((RIG,) if self.rig else ())

    def __bool__(self) -> bool:
        return bool(self.tokens)

    def without_rig(self) -> "Options":
        return replace(self, rig=False)

    @classmethod
    def parse(cls, tokens) -> "Options":
        """From option names (``backbone5``, ``limits``, ``maxwell``, ``rig``; any order, any case)."""
        knots, limits, rig, maxwell = 0, False, False, False
        for token in tokens:
            word = token.strip().lower()
            match = re.fullmatch(rf"{BACKBONE}(\d+)", word)
            if match:
                knots = int(match.group(1))
            elif word == LIMITS:
                limits = True
            elif word == RIG:
                rig = True
            elif word == MAXWELL:
                maxwell = True
            else:
                raise ParameterError(f"unknown model option {token!r}; the options are {BACKBONE}<K> (a backbone of "
                                     f"K knots, 2 to {MAX_KNOTS}), {LIMITS}, {MAXWELL} and {RIG}")
        return cls(knots, limits, rig, maxwell)


def split_name(name: str) -> tuple[str, Options]:
    """(the base's name or identifier, the options) of a derived model's name
    (``proposed+limits``) or identifier (``BoucWenBushing_Limits``)."""
    if SEPARATOR in name:
        base, *tokens = name.split(SEPARATOR)
        return base, Options.parse(tokens)
    # an identifier: the base's (which may hold underscores) and then the options' capitalised words
    words = name.split("_")
    for cut in range(1, len(words) + 1):
        tail = words[cut:]
        if all(re.fullmatch(r"(Backbone\d+|Limits|Maxwell|Rig)", word) for word in tail):
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
            ParameterSpec(f"limit_k_{side}", "N/mm^e", f"the {word} limit's stiffness: force k*d^e at penetration d "
                          "[mm], e its exponent", minimum=0.0, why="a negative stiffness is unstable", bound_powers=None),
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


def maxwell_specs() -> tuple[ParameterSpec, ...]:
    return (ParameterSpec("maxwell_k", "N/mm", "the parallel Maxwell element's spring", minimum=0.0,
                          why="a negative spring is unstable"),
            ParameterSpec("maxwell_c", "N.s/mm", "the parallel Maxwell element's dashpot (time constant c/k)",
                          minimum=0.0, exclusive=True, why="a Maxwell element without a dashpot is a spring"))


def rig_specs() -> tuple[ParameterSpec, ...]:
    return (ParameterSpec("rig_displacement_zero", "mm", "the rig's displacement zero: the model sees x - it",
                          bound_powers=None),
            ParameterSpec("rig_force_zero", "N", "the load cell's zero: added to the model's force",
                          bound_powers=(0, 0)))


def option_specs(options: Options) -> tuple[ParameterSpec, ...]:
    return ((backbone_specs(options.knots) if options.knots else ()) + (limit_specs() if options.limits else ())
            + (maxwell_specs() if options.maxwell else ()) + (rig_specs() if options.rig else ()))


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
    if options.maxwell:
        coordinates += (SearchCoordinate("maxwell_k", KIND.stiffness, -4.0, 1.0),
                        SearchCoordinate("maxwell_c", KIND.time_constant, -math.inf, 4.0, over=("maxwell_k",)))
    if options.rig:
        coordinates += (SearchCoordinate("rig_displacement_zero", KIND.rig_travel, -0.25, 0.25),
                        SearchCoordinate("rig_force_zero", KIND.rig_force, -0.5, 0.5))
    loop = base.search.loop_start if base.search is not None and not options.knots else None
    if loop is not None:       # the friction alone: the options' neutral values too
        loop = replace(loop, friction_alone=loop.friction_alone + NEUTRAL[LIMITS] * options.limits
                       + NEUTRAL[MAXWELL] * options.maxwell + NEUTRAL[RIG] * options.rig)
    return SearchBox(coordinates, unit_weights=unit_weights, zeros=zeros, held=held, loop_start=loop, table_start=None)


NEUTRAL = {
    LIMITS: (("limit_gap_pos", 1.0), ("limit_gap_neg", 1.0), ("limit_k_pos", 0.0), ("limit_k_neg", 0.0),
             ("limit_exponent_pos", 2.0), ("limit_exponent_neg", 2.0), ("limit_c_pos", 0.0), ("limit_c_neg", 0.0),
             ("limit_depth_pos", 1.0), ("limit_depth_neg", 1.0), ("limit_width", 0.0)),
    MAXWELL: (("maxwell_k", 0.0), ("maxwell_c", 1.0)),
    RIG: (("rig_displacement_zero", 0.0), ("rig_force_zero", 0.0)),
}
"""Each option's values that leave the base's force as it is (a slow loop's friction alone)."""


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
    words = {BACKBONE: "a measured backbone", LIMITS: "travel limits", MAXWELL: "a Maxwell element",
             RIG: "the rig's offsets"}
    states = base.states + ((StateSpec("maxwell_f", len(base.states), "N", "the parallel Maxwell element's force"),)
                            if options.maxwell else ())
    title = f"{base.title} with " + ", ".join(words[t.rstrip('0123456789')] for t in options.tokens)
    model = BushingModel(
        name, derived_identifier(base, options), title, specs, states, base.default_file,
        g["prepare"], g["initial_state"], g["jump"], g["integrate"], g["force"], g["derivatives"], g["switches"],
        constraints=constraints, switch_specs=switch_specs, update=g.get("update"), search=_search(base, options),
        description=f"{base.description or base.title}; with {', '.join(options.tokens)}",
        plot_style=base.plot_style, rank=base.rank, settling_s=base.settling_s, rotational=base.rotational,
        static_spring=(), base=base, options=options, resting_state=g.get("resting_state"))
    _DERIVED[name] = model
    return model


_DERIVED: dict[str, BushingModel] = {}
