"""A model with options: a registered model (its *base*) composed with option elements.

A derived model is named ``<base>+<option>[+<option>...]``, its FMI identifier the base's with the
options appended (``proposed+limits`` -> ``BoucWenBushing_Limits``). Each option is an element
defined once in its module of ``fmu_src.model.options`` (the contract: ``options.element``; the
table: ``options.ELEMENTS``), such as ``backbone<K>`` (a measured static curve that replaces the
base's static spring), ``maxwell`` (a parallel Maxwell element with a state of its own) or ``rig``
(a measured test's displacement and load-cell zeros, which a fit estimates and an FMU takes as its
mounting's ``offset`` and ``preload``).

Every option works on the base's displacement u = x - the displacement zero (x where no option
has one): F = base(u) + each option's force, in the options' order; the options' states follow
the base's; their switches follow the base's.

One definition. The derived model is a kernel module of its own, generated as source text
(``derived_source``) and registered beside the models (``<package>.<base>__<options>``): numba
compiles it, the C translator translates it and the tangent generator differentiates it as it
does any model module; the base model itself, its generated C and its compiled module are
unchanged. ``registry.get_model`` makes a derived model from its name or identifier on demand
(in every worker process and inside a packed pythonfmu FMU alike).
"""
from __future__ import annotations

import linecache
import sys
import types
from dataclasses import replace

from .definition import BushingModel, ModelContractError, SearchBox, SearchCoordinate, StateSpec
from .derived_source import derived_source
from .options import Options
from .parameter_specs import ParameterSpec
from .search_coordinates import KIND

SEPARATOR = "+"


def split_name(name: str) -> tuple[str, Options]:
    """(the base's name or identifier, the options) of a derived model's name
    (``proposed+limits``) or identifier (``BoucWenBushing_Limits``)."""
    if SEPARATOR in name:
        base, *tokens = name.split(SEPARATOR)
        return base, Options.parse(tokens)
    # an identifier: the base's (which may hold underscores) and then the options' capitalised words
    words = name.split("_")
    for cut in range(1, len(words) + 1):
        options = Options.of_identifier_words(words[cut:])
        if options is not None:
            return "_".join(words[:cut]), options
    return name, Options()


def derived_name(base: BushingModel, options: Options) -> str:
    return SEPARATOR.join((base.name, *options.tokens))


def derived_identifier(base: BushingModel, options: Options) -> str:
    return "_".join((base.identifier, *(token.capitalize() for token in options.tokens)))


def option_specs(options: Options) -> tuple[ParameterSpec, ...]:
    """The options' parameters, in their order."""
    return tuple(spec for element, count in options.elements for spec in element.specs(count))


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
    """The derived model's box: the base's (less its static spring, where an option replaces it)
    and the options'."""
    held_out = set(base.static_spring) if options.replaces_static_spring else set()
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
    for element, count in options.elements:
        coordinates += element.coordinates(count)
        held = held + element.held
    roles = {spec.temperature_role for spec in base.specs if spec.name not in held_out}
    roles |= {spec.temperature_role for element, count in options.elements if not element.law_roles
              for spec in element.specs(count)}
    idle = {name for element, _ in options.elements for name, role in element.law_roles if role not in roles}
    if idle:       # a law's constant that moves nothing is held at its neutral value
        coordinates = tuple(c for c in coordinates if c.parameter not in idle)
        held = held + tuple(pair for pair in options.neutral if pair[0] in idle)
    loop = base.search.loop_start if base.search is not None and not options.replaces_static_spring else None
    if loop is not None:       # the friction alone: the options' neutral values too
        loop = replace(loop, friction_alone=loop.friction_alone + options.neutral)
    return SearchBox(coordinates, unit_weights=unit_weights, zeros=zeros, held=held, loop_start=loop, table_start=None)


def derive(base: BushingModel, options: Options) -> BushingModel:
    """``base`` with ``options`` (module docstring): a new model, generated once per process."""
    if not options:
        return base
    name = derived_name(base, options)
    cached = _DERIVED.get(name)
    if cached is not None:
        return cached
    held = set(base.static_spring) if options.replaces_static_spring else set()
    specs = tuple(spec for spec in base.specs if spec.name not in held) + option_specs(options)
    names = [spec.name for spec in specs]
    clashes = sorted({n for n in names if names.count(n) > 1} | ({"offset", "preload"} & {s.name for s in option_specs(options)}))
    if clashes:
        raise ModelContractError(f"the {base.name} model's parameters {clashes} clash with its options'")
    module = _module(base, options)
    g = vars(module)
    constraints = tuple(c for c in base.constraints if not any(term in held for term, _ in c.terms))
    switch_specs, states = base.switch_specs, base.states
    for element, count in options.elements:
        constraints += element.constraints(count)
        switch_specs += tuple(StateSpec(s.name, len(switch_specs) + i, s.unit, s.description)
                              for i, s in enumerate(element.switches(count)))
        own = element.states(count)
        if own and element.step is None and not element.series and not element.heating:
            raise ModelContractError(f"the {element.token} option has states but no step")
        states += tuple(StateSpec(s.name, len(states) + i, s.unit, s.description) for i, s in enumerate(own))
    title = f"{base.title} with " + ", ".join(element.word for element, _ in options.elements)
    model = BushingModel(
        name, derived_identifier(base, options), title, specs, states, base.default_file,
        g["prepare"], g["initial_state"], g["jump"], g["integrate"], g["force"], g["derivatives"], g["switches"],
        constraints=constraints, switch_specs=switch_specs, update=g.get("update"), search=_search(base, options),
        description=f"{base.description or base.title}; with {', '.join(options.tokens)}",
        plot_style=base.plot_style, rank=base.rank, settling_s=base.settling_s, rotational=base.rotational,
        static_spring=(), base=base, options=options, resting_state=g.get("resting_state"),
        conditions=tuple(pair for element, _ in options.elements for pair in element.conditions))
    _DERIVED[name] = model
    return model


_DERIVED: dict[str, BushingModel] = {}
