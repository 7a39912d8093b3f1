"""The generated part of a native bushing FMU's C: ``bushing_model.c``.

From the FMU's axes [(axes.Axis, model on that axis, parameters)] it writes

- the models' kernels (``prepare``, ``initial_state``, ``step`` (``integration.step``), ``jump``,
  ``force``, ``derivatives``, ``switches``, ``update`` where a model has one, and the shared
  machinery they call), translated from
  their Python source by ``python_to_c``;
- their tangents (``tangents``: ``force`` and ``derivatives`` in a direction of the state and
  the inputs, ``jump`` in the jump), generated from the same source and translated the same way,
  for the FMU's directional derivatives;
- per model, wrappers with the array interface of ``bw_model`` (``c/bushing_fmu.h``), and its
  parameter rules (``ParameterSpec``, ``Constraint``) as tables;
- the FMU's axes with their start values, its variables (``variables.fmu_variables`` and the
  states' derivatives, numbered as the pythonfmu FMU numbers its variables) and the states'
  nominal values.

Nothing here knows a model's equations: a model added to ``registry`` is generated too.
"""
from __future__ import annotations

import hashlib
import json
import uuid
from dataclasses import dataclass

from ...model import elements, integration
from ..axes import group_name as axis_group_name
from ...kernels.tangents import tangent
from ...model.definition import BushingModel
from ..variables import FmuVariable, all_variables, exact_text, nominal
from ...kernels.python_to_c import DOUBLE, INT, Translation, describe

KINDS = {"parameter": "BW_PARAMETER", "displacement": "BW_DISPLACEMENT", "velocity": "BW_VELOCITY",
         "output": "BW_OUTPUT", "state": "BW_STATE", "derivative": "BW_DERIVATIVE", "indicator": "BW_INDICATOR",
         "time": "BW_TIME"}

def c_string(text: str) -> str:
    return json.dumps(text)      # a C string literal for ASCII text (json escapes as C does)


def c_identifier(model_name: str) -> str:
    """A model's name as C names it: a derived model's ``+`` (``proposed+limits``) as ``__``."""
    return model_name.replace("+", "__")


class ModelCode:
    """One model's translated kernels and the C types of their tuples."""

    def __init__(self, translation: Translation, model: BushingModel, coupled: bool = False):
        self.model = model
        self.name = c_identifier(model.name)
        parameters = (DOUBLE,) * len(model.specs)
        self.parameters_type = parameters
        prepare = translation.function(model.prepare, (parameters,))
        self.constants_type = prepare.return_type
        initial = translation.function(model.initial_state, (self.constants_type, DOUBLE))
        self.state_type = initial.return_type
        if not all(t == DOUBLE for t in self.state_type):
            raise ValueError(f"{model.name}: a state must be a tuple of floats, not {describe(self.state_type)}")
        m, s = self.constants_type, self.state_type
        self.kernels = {
            "prepare": prepare, "initial_state": initial,
            "step": translation.function(model.step, (m, s, DOUBLE, DOUBLE, DOUBLE, DOUBLE, INT)),
            "jump": translation.function(model.jump, (m, s, DOUBLE)),
            "force": translation.function(model.force, (m, s, DOUBLE, DOUBLE)),
            "derivatives": translation.function(model.derivatives, (m, s, DOUBLE, DOUBLE)),
            "switches": translation.function(model.switches, (m, s, DOUBLE, DOUBLE)),
        }
        tangent_arguments = (m, s, DOUBLE, DOUBLE, s, DOUBLE, DOUBLE)
        self.kernels["force_tangent"] = translation.function(tangent(model.force), tangent_arguments)
        self.kernels["derivatives_tangent"] = translation.function(tangent(model.derivatives), tangent_arguments)
        self.kernels["jump_tangent"] = translation.function(tangent(model.jump, inactive=("m", "state")),
                                                            (m, s, DOUBLE, DOUBLE))
        if model.update is not None:
            self.kernels["update"] = translation.function(model.update, (m, s, DOUBLE, DOUBLE))
        if model.resting_state is not None:
            self.kernels["resting_state"] = translation.function(model.resting_state, (m, DOUBLE, DOUBLE))
        self.coupled = CoupledCode(translation, model, self.constants_type) if coupled else None
        self.switches = len(self.kernels["switches"].return_type)
        if [s.index for s in model.switch_specs] != list(range(self.switches)):
            raise ValueError(f"{model.name}: switch_specs must name the {self.switches} values switches() returns, "
                             "in order")
        self.translation = translation

    def state_literal(self, array: str) -> str:
        fields = ", ".join(f"{array}[{i}]" for i in range(len(self.state_type))) or "0"
        return f"({self.translation.c_type(self.state_type)}){{{fields}}}"

    def wrappers(self) -> str:
        """The array interface of ``bw_model`` around the translated kernels."""
        k, name = self.kernels, self.name
        constants = f"((const bw_constants *)c)->{name}"
        states = len(self.state_type)
        parameters = ", ".join(f"p[{i}]" for i in range(len(self.parameters_type)))
        copy_state = lambda source, target: "".join(f"    {target}[{i}] = {source}.f{i};\n" for i in range(states)) \
            or "    (void)s;\n"
        lines = [
            f"static void bw_{name}_prepare(const double *p, void *c) {{\n"
            f"    ((bw_constants *)c)->{name} = {k['prepare'].name}(({self.translation.c_type(self.parameters_type)})"
            f"{{{parameters}}});\n}}\n",
            f"static void bw_{name}_initial_state(const void *c, double x0, double *s) {{\n"
            f"    {self.translation.c_type(self.state_type)} r = {k['initial_state'].name}({constants}, x0);\n"
            + (copy_state("r", "s") if states else "    (void)r;\n    (void)s;\n") + "}\n",
            f"static int bw_{name}_step(const void *c, double *s, double state_x, double x, double v, double h, "
            f"int max_substeps) {{\n"
            f"    {self.translation.c_type(k['step'].return_type)} r = {k['step'].name}({constants}, "
            f"{self.state_literal('s')}, state_x, x, v, h, max_substeps);\n"
            + copy_state("r.f0", "s") + "    return r.f2;\n}\n",
            f"static int bw_{name}_jump(const void *c, double *s, double jump) {{\n"
            f"    {self.translation.c_type(k['jump'].return_type)} r = {k['jump'].name}({constants}, "
            f"{self.state_literal('s')}, jump);\n" + copy_state("r.f0", "s") + "    return r.f1;\n}\n",
            f"static double bw_{name}_force(const void *c, const double *s, double x, double v) {{\n"
            + ("    (void)s;\n" if not states else "")
            + f"    return {k['force'].name}({constants}, {self.state_literal('s')}, x, v);\n}}\n",
        ]
        if "update" in k:
            compare = " || ".join(f"r.f{i} != s[{i}]" for i in range(states))
            lines.append(
                f"static int bw_{name}_update(const void *c, double *s, double x, double v) {{\n"
                f"    {self.translation.c_type(self.state_type)} r = {k['update'].name}({constants}, "
                f"{self.state_literal('s')}, x, v);\n    int changed = {compare};\n"
                + copy_state("r", "s") + "    return changed;\n}\n")
        else:
            lines.append(f"static int bw_{name}_update(const void *c, double *s, double x, double v) {{\n"
                         "    (void)c;\n    (void)s;\n    (void)x;\n    (void)v;\n    return 0;\n}\n")
        if "resting_state" in k:
            lines.append(
                f"static void bw_{name}_resting_state(const void *c, double x0, double force, double *s) {{\n"
                f"    {self.translation.c_type(self.state_type)} r = {k['resting_state'].name}({constants}, x0, "
                f"force);\n" + copy_state("r", "s") + "}\n")
        for kernel, out in (("derivatives", "rates"), ("switches", "values")):
            count = len(k[kernel].return_type)
            lines.append(
                f"static void bw_{name}_{kernel}(const void *c, const double *s, double x, double v, double *{out}) {{\n"
                f"    {self.translation.c_type(k[kernel].return_type)} r = {k[kernel].name}({constants}, "
                f"{self.state_literal('s')}, x, v);\n"
                + ("".join(f"    {out}[{i}] = r.f{i};\n" for i in range(count))
                   + ("    (void)s;\n" if not states else "") if count else
                   f"    (void)r;\n    (void){out};\n" + ("    (void)s;\n" if not states else "")) + "}\n")
        lines.append(self.tangent_wrappers())
        if self.coupled is not None:
            lines.append(self.coupled.wrappers(name, constants))
        return "\n".join(lines)

    def tangent_wrappers(self) -> str:
        """The array interface of ``bw_model``'s tangents: ``force_tangent`` returns dF,
        ``derivatives_tangent`` writes d(rates), both in the direction (ds, dx, dv);
        ``jump_tangent`` takes the state through the jump (as ``jump``) and writes its
        derivative with respect to the jump."""
        k, name = self.kernels, self.name
        constants = f"((const bw_constants *)c)->{name}"
        states = len(self.state_type)
        unused = "".join(f"    (void){a};\n" for a in ("s", "ds")) if not states else ""

        def elements(expression: str, t) -> list[str]:
            # A tangent whose value does not depend on the direction at all is the scalar 0.0.
            return [f"{expression}.f{i}" for i in range(states)] if isinstance(t, tuple) else [expression] * states

        force = k["force_tangent"]
        derivatives = k["derivatives_tangent"]
        jump = k["jump_tangent"]
        call = f"({constants}, {self.state_literal('s')}, x, v, {self.state_literal('ds')}, dx, dv)"
        rates = elements("r.f1", derivatives.return_type[1])
        jumped_state = elements("r.f0.f0", jump.return_type[0][0])
        jump_derivative = jump.return_type[1]
        d_state = elements("r.f1.f0", jump_derivative[0]) if isinstance(jump_derivative, tuple) else ["0.0"] * states
        return (
            f"static double bw_{name}_force_tangent(const void *c, const double *s, double x, double v, "
            f"const double *ds, double dx, double dv) {{\n{unused}"
            f"    return {force.name}{call}.f1;\n}}\n\n"
            f"static void bw_{name}_derivatives_tangent(const void *c, const double *s, double x, double v, "
            f"const double *ds, double dx, double dv, double *d_rates) {{\n"
            + unused + f"    {self.translation.c_type(derivatives.return_type)} r = {derivatives.name}{call};\n"
            + ("".join(f"    d_rates[{i}] = {e};\n" for i, e in enumerate(rates)) or "    (void)r;\n    (void)d_rates;\n")
            + "}\n\n"
            f"static int bw_{name}_jump_tangent(const void *c, double *s, double jump, double *ds) {{\n"
            f"    {self.translation.c_type(jump.return_type)} r = {jump.name}({constants}, {self.state_literal('s')}, "
            f"jump, 1.0);\n"
            + "".join(f"    s[{i}] = {e};\n" for i, e in enumerate(jumped_state))
            + "".join(f"    ds[{i}] = {e};\n" for i, e in enumerate(d_state))
            + ("    (void)s;\n    (void)ds;\n" if not states else "") + "    return r.f0.f1;\n}\n")

    def tables(self, suffix: str, model: BushingModel) -> str:
        """The parameter rules of ``model`` (this model on one kind of axis: its units) and its
        ``bw_model``, named ``bw_model_<name><suffix>``."""
        index = {spec.name: i for i, spec in enumerate(model.fmu_specs)}
        specs = []
        for spec in model.fmu_specs:      # the model's, then its mounting's
            weight = index.get(model.gain_weight(spec.name), -1)
            powers = model.bound_powers(spec)
            specs.append(f"    {{{c_string(spec.name)}, {c_string(spec.unit)}, {int(spec.minimum is not None)}, "
                         f"{exact_text(spec.minimum or 0.0)}, {int(spec.maximum is not None)}, "
                         f"{exact_text(spec.maximum or 0.0)}, {int(spec.exclusive)}, {c_string(spec.allowed)}, "
                         f"{c_string(spec.why)}, {int(powers is not None)}, {(powers or (0, 0))[0]}, "
                         f"{(powers or (0, 0))[1]}, {weight}}}")
        constraints = []
        for c in model.constraints:
            terms = list(c.terms)
            parameters = ", ".join(str(index[name]) for name, _ in terms) or "0"
            coefficients = ", ".join(exact_text(coefficient) for _, coefficient in terms) or "0.0"
            constraints.append(f"    {{{len(terms)}, {{{parameters}}}, {{{coefficients}}}, {exact_text(c.bound)}, "
                               f"{int(c.strict)}, {int(c.error)}, {c_string(c.expression)}, {c_string(c.unit)}, "
                               f"{c_string(c.why)}}}")
        name = f"{self.name}{suffix}"
        out = f"static const bw_parameter_spec bw_specs_{name}[] = {{\n" + ",\n".join(specs) + "\n};\n"
        if constraints:
            out += f"static const bw_constraint bw_constraints_{name}[] = {{\n" + ",\n".join(constraints) + "\n};\n"
        kernels = ", ".join(f"bw_{self.name}_{kernel}" for kernel in
                            ("prepare", "initial_state", "step", "jump", "force", "derivatives", "switches",
                             "update", "force_tangent", "derivatives_tangent", "jump_tangent"))
        kernels += f", {'bw_' + self.name + '_resting_state' if 'resting_state' in self.kernels else 'NULL'}"
        mounting = {spec.name: index[spec.name] for spec in model.mounting_specs}
        coupled = f"&bw_coupled_{self.name}" if self.coupled is not None else "NULL"
        out += (f"static const bw_model bw_model_{name} = {{{c_string(self.name)}, {len(model.specs)}, "
                f"{len(model.fmu_specs)}, {mounting.get('offset', -1)}, {mounting.get('preload', -1)}, "
                f"{mounting.get('held_force', -1)}, "
                f"{len(self.state_type)}, {self.switches}, bw_specs_{name}, {len(constraints)}, "
                f"{'bw_constraints_' + name if constraints else 'NULL'}, {kernels}, {coupled}}};\n")
        return out


VECTOR = (DOUBLE, DOUBLE, DOUBLE)


class CoupledCode:
    """A model's coupled kernels (``definition.CoupledKernels``) translated for a coupled
    group: 3-vectors for x, v, a jump and the force, the flat state; with the array interface of
    ``bw_coupled_model`` (``c/bushing_fmu.h``)."""

    def __init__(self, translation: Translation, model: BushingModel, constants_type):
        kernels = model.coupled
        self.kernels_spec = kernels
        self.size = kernels.size
        m, s, v = constants_type, (DOUBLE,) * kernels.size, VECTOR
        self.kernels = {
            "initial_state": translation.function(kernels.initial_state, (m, v)),
            "step": translation.function(kernels.step, (m, s, v, v, v, DOUBLE, INT)),
            "jump": translation.function(kernels.jump, (m, s, v)),
            "force": translation.function(kernels.force, (m, s, v, v)),
            "derivatives": translation.function(kernels.derivatives, (m, s, v, v)),
            "switches": translation.function(kernels.switches, (m, s, v, v)),
            "force_tangent": translation.function(tangent(kernels.force), (m, s, v, v, s, v, v)),
            "derivatives_tangent": translation.function(tangent(kernels.derivatives), (m, s, v, v, s, v, v)),
            "jump_tangent": translation.function(tangent(kernels.jump, inactive=("m", "state")), (m, s, v, v)),
        }
        if kernels.update is not None:
            self.kernels["update"] = translation.function(kernels.update, (m, s, v, v))
        self.switches = len(self.kernels["switches"].return_type)
        if [spec.index for spec in kernels.switch_specs] != list(range(self.switches)):
            raise ValueError(f"{model.name}: the coupled switch_specs must name the {self.switches} values its "
                             "switches() returns, in order")
        index = {spec.name: i for i, spec in enumerate(model.specs)}
        self.zero_parameters = [index[name] for name in kernels.zero_parameters]
        self.translation = translation

    def literal(self, array: str, count: int, t: str | None = None) -> str:
        """A C compound literal of ``count`` doubles from ``array`` (a tuple of doubles' struct)."""
        t = t or self.translation.c_type((DOUBLE,) * count)
        return f"({t}){{{', '.join(f'{array}[{i}]' for i in range(count))}}}"

    def wrappers(self, name: str, constants: str) -> str:
        k = self.kernels
        size = self.size
        state = self.literal("s", size)
        vec = lambda array: self.literal(array, 3)     # noqa: E731 (a 3-vector's literal)
        copy = lambda source, target, count: "".join(   # noqa: E731
            f"    {target}[{i}] = {source}.f{i};\n" for i in range(count))

        def elements(expression: str, t, count: int) -> list[str]:
            # a tangent that does not depend on the direction at all is the scalar 0.0
            return [f"{expression}.f{i}" for i in range(count)] if isinstance(t, tuple) else [expression] * count

        c_type = self.translation.c_type
        call = f"({constants}, {state}, {vec('x')}, {vec('v')}"
        tangent_call = f"({constants}, {state}, {vec('x')}, {vec('v')}, {self.literal('ds', size)}, {vec('dx')}, {vec('dv')})"
        lines = [
            f"static void bw_{name}_coupled_initial_state(const void *c, const double *x, double *s) {{\n"
            f"    {c_type(k['initial_state'].return_type)} r = {k['initial_state'].name}({constants}, {vec('x')});\n"
            + copy("r", "s", size) + "}\n",
            f"static int bw_{name}_coupled_step(const void *c, double *s, const double *state_x, const double *x, "
            f"const double *v, double h, int max_substeps) {{\n"
            f"    {c_type(k['step'].return_type)} r = {k['step'].name}({constants}, {state}, {vec('state_x')}, "
            f"{vec('x')}, {vec('v')}, h, max_substeps);\n" + copy("r.f0", "s", size) + "    return r.f2;\n}\n",
            f"static int bw_{name}_coupled_jump(const void *c, double *s, const double *jump) {{\n"
            f"    {c_type(k['jump'].return_type)} r = {k['jump'].name}({constants}, {state}, {vec('jump')});\n"
            + copy("r.f0", "s", size) + "    return r.f1;\n}\n",
            f"static void bw_{name}_coupled_force(const void *c, const double *s, const double *x, const double *v, "
            f"double *force) {{\n    {c_type(k['force'].return_type)} r = {k['force'].name}{call});\n"
            + copy("r", "force", 3) + "}\n",
        ]
        for kernel, out, count in (("derivatives", "rates", size), ("switches", "values", self.switches)):
            lines.append(
                f"static void bw_{name}_coupled_{kernel}(const void *c, const double *s, const double *x, "
                f"const double *v, double *{out}) {{\n    {c_type(k[kernel].return_type)} r = {k[kernel].name}{call});\n"
                + (copy("r", out, count) or f"    (void)r;\n    (void){out};\n") + "}\n")
        if "update" in k:
            compare = " || ".join(f"r.f{i} != s[{i}]" for i in range(size))
            lines.append(
                f"static int bw_{name}_coupled_update(const void *c, double *s, const double *x, const double *v) {{\n"
                f"    {c_type(k['update'].return_type)} r = {k['update'].name}{call});\n    int changed = {compare};\n"
                + copy("r", "s", size) + "    return changed;\n}\n")
        else:
            lines.append(f"static int bw_{name}_coupled_update(const void *c, double *s, const double *x, "
                         "const double *v) {\n    (void)c;\n    (void)s;\n    (void)x;\n    (void)v;\n    return 0;\n}\n")
        force, rates, jump = k["force_tangent"], k["derivatives_tangent"], k["jump_tangent"]
        d_force = elements("r.f1", force.return_type[1], 3)
        d_rates = elements("r.f1", rates.return_type[1], size)
        jumped = elements("r.f0.f0", jump.return_type[0][0], size)
        derivative = jump.return_type[1]
        d_state = elements("r.f1.f0", derivative[0], size) if isinstance(derivative, tuple) else ["0.0"] * size
        lines.append(
            f"static void bw_{name}_coupled_force_tangent(const void *c, const double *s, const double *x, "
            f"const double *v, const double *ds, const double *dx, const double *dv, double *d_force) {{\n"
            f"    {c_type(force.return_type)} r = {force.name}{tangent_call};\n"
            + "".join(f"    d_force[{i}] = {e};\n" for i, e in enumerate(d_force)) + "}\n")
        lines.append(
            f"static void bw_{name}_coupled_derivatives_tangent(const void *c, const double *s, const double *x, "
            f"const double *v, const double *ds, const double *dx, const double *dv, double *d_rates) {{\n"
            f"    {c_type(rates.return_type)} r = {rates.name}{tangent_call};\n"
            + "".join(f"    d_rates[{i}] = {e};\n" for i, e in enumerate(d_rates)) + "}\n")
        lines.append(
            f"static int bw_{name}_coupled_jump_tangent(const void *c, double *s, const double *jump, "
            f"const double *d_jump, double *ds) {{\n"
            f"    {c_type(jump.return_type)} r = {jump.name}({constants}, {state}, {vec('jump')}, {vec('d_jump')});\n"
            + "".join(f"    s[{i}] = {e};\n" for i, e in enumerate(jumped))
            + "".join(f"    ds[{i}] = {e};\n" for i, e in enumerate(d_state)) + "    return r.f0.f1;\n}\n")
        zeros = ", ".join(str(i) for i in self.zero_parameters) or "0"
        kernels = ", ".join(f"bw_{name}_coupled_{kernel}" for kernel in
                            ("initial_state", "step", "jump", "force", "derivatives", "switches", "update",
                             "force_tangent", "derivatives_tangent", "jump_tangent"))
        lines.append(f"static const bw_coupled_model bw_coupled_{name} = {{{size}, {self.switches}, "
                     f"{len(self.zero_parameters)}, {{{zeros}}}, {kernels}}};\n")
        return "\n".join(lines)


@dataclass(frozen=True)
class GeneratedModel:
    source: str               # bushing_model.c
    token: str                # the instantiation token (FMI 2: guid)
    event_indicators: int


def model_source(axis_models, identifier: str, groups=()) -> GeneratedModel:
    """bushing_model.c for an FMU whose axes are ``axis_models`` [(axes.Axis, model on that axis,
    parameters)] with the coupled ``groups`` (tuples of positions among them; a group of a model
    without a coupled form, Kelvin-Voigt, is its axes as they are). The instantiation token is
    derived from the C and the identifier, so a rebuild of the same FMU gives the same token."""
    translation = Translation(prefix="bw")
    groups = tuple(tuple(group) for group in groups if axis_models[group[0]][1].coupled is not None)
    coupled = {axis_models[group[0]][1].name for group in groups}
    models: dict[str, ModelCode] = {}
    for _, model, _ in axis_models:
        if model.name not in models:
            models[model.name] = ModelCode(translation, model, model.name in coupled)
    variables = all_variables(axis_models, groups)
    jump_test = translation.function(integration.displacement_jumped, (DOUBLE, DOUBLE, DOUBLE, DOUBLE))
    kernels = translation.source()

    parts = [kernels, "\ntypedef union {"]
    parts += [f"    {translation.c_type(code.constants_type)} {code.name};" for code in models.values()]
    parts.append("} bw_constants;\n")
    for code in models.values():
        parts.append(code.wrappers())
    done = set()
    for axis, model, _ in axis_models:
        suffix = "_rotational" if axis.rotational else ""
        if (model.name, suffix) not in done:
            done.add((model.name, suffix))
            parts.append(models[model.name].tables(suffix, model))
    parts += _axis_table(axis_models)
    parts += _group_table(axis_models, groups)
    parts += _variable_table(variables)
    body = "\n".join(parts)
    token = "{" + str(uuid.UUID(hashlib.sha256((identifier + body).encode()).hexdigest()[:32])) + "}"
    indicators = sum(v.kind == "indicator" for v in variables)
    return GeneratedModel(_defines(identifier, token, axis_models, groups, models, variables, jump_test) + body, token,
                          indicators)


def _axis_table(axis_models) -> list[str]:
    """Each axis's default parameters and its row of bw_axis_specs (ports, units, the model's tables)."""
    parts, axis_lines = [], []
    for position, (axis, model, parameters) in enumerate(axis_models):
        values = ", ".join(exact_text(parameters.get(spec.name, 0.0)) for spec in model.fmu_specs)
        parts.append(f"static const double bw_defaults_{position}[] = {{{values}}};")
        suffix = "_rotational" if axis.rotational else ""
        plausible = (1.0, 50.0) if axis.rotational else (100.0, 1000.0)
        axis_lines.append(
            f"    {{{c_string(axis.name)}, {c_string(axis.label)}, {c_string(axis.displacement)}, {c_string(axis.velocity)}, "
            f"{c_string(axis.output)}, {int(axis.rotational)}, {exact_text(axis.to_kernel)}, {exact_text(axis.from_kernel)}, "
            f"{exact_text(axis.plausible_travel)}, {exact_text(plausible[0])}, {exact_text(plausible[1])}, "
            f"&bw_model_{c_identifier(model.name)}{suffix}, bw_defaults_{position}}}")
    parts.append("\nstatic const bw_axis_spec bw_axis_specs[BW_AXES] = {\n" + ",\n".join(axis_lines) + "\n};\n")
    return parts


def _group_table(axis_models, groups) -> list[str]:
    """bw_group_specs (each coupled group's label and members) and each axis's group and component."""
    group_of, component = [-1] * len(axis_models), [0] * len(axis_models)
    group_lines = []
    for g, group in enumerate(groups):
        names = ", ".join(axis_models[i][0].name for i in group)
        label = f"the {axis_group_name(tuple(axis_models[i][0].name for i in group))} group ({names}): "
        members = ", ".join(str(i) for i in group) + ", 0" * (3 - len(group))
        group_lines.append(f"    {{{c_string(label)}, {len(group)}, {{{members}}}}}")
        for c, i in enumerate(group):
            group_of[i], component[i] = g, c
    return ["static const bw_group_spec bw_group_specs[BW_GROUP_SLOTS] = {\n"
            + (",\n".join(group_lines) or '    {"", 0, {0, 0, 0}}') + "\n};\n",
            "static const int bw_axis_group[BW_AXES] = {" + ", ".join(map(str, group_of)) + "};",
            "static const int bw_axis_component[BW_AXES] = {" + ", ".join(map(str, component)) + "};\n"]


def _variable_table(variables) -> list[str]:
    """bw_variables (name, kind, axis, index, port scale) and bw_nominal, in value-reference order."""
    return ["static const bw_variable bw_variables[BW_VARIABLES] = {\n" + ",\n".join(
            f"    {{{c_string(v.name)}, {KINDS[v.kind]}, {v.axis}, {v.index}, {exact_text(v.scale)}}}" for v in variables)
            + "\n};\n",
            "static const double bw_nominal[BW_VARIABLES] = {" + ", ".join(exact_text(nominal(v)) for v in variables)
            + "};\n"]


def _defines(identifier: str, token: str, axis_models, groups, models, variables, jump_test) -> str:
    """The generated file's comment and its #defines: sizes, status codes, the jump test's name."""
    states = sum(v.kind == "state" for v in variables)
    indicators = sum(v.kind == "indicator" for v in variables)
    return (
        f"/* Generated by fmu_src/fmi/native/generate.py for the FMU {identifier}: the models' kernels translated\n"
        " * from their Python source, the FMU's axes, variables and parameter rules. Do not edit: build the\n"
        " * FMU again (build_fmu.py --native). */\n"
        f"#define BW_MODEL_IDENTIFIER {c_string(identifier)}\n"
        f"#define BW_INSTANTIATION_TOKEN {c_string(token)}\n"
        f"#define BW_AXES {len(axis_models)}\n"
        f"#define BW_VARIABLES {len(variables)}\n"
        f"#define BW_MAX_PARAMETERS {max(len(m.fmu_specs) for _, m, _ in axis_models)}\n"
        f"#define BW_MAX_STATES {max([1] + [len(code.state_type) for code in models.values()])}\n"
        f"#define BW_MAX_SWITCHES {max([1] + [code.switches for code in models.values()])}\n"
        f"#define BW_GROUPS {len(groups)}\n"
        f"#define BW_GROUP_SLOTS {max(1, len(groups))}\n"
        f"#define BW_MAX_GROUP_STATES {max([1] + [c.coupled.size for c in models.values() if c.coupled])}\n"
        f"#define BW_MAX_GROUP_SWITCHES {max([1] + [c.coupled.switches for c in models.values() if c.coupled])}\n"
        f"#define BW_CONTINUOUS_STATES {states}\n"
        f"#define BW_EVENT_INDICATORS {indicators}\n"
        f"#define BW_KERNEL_OK {integration.OK}\n"
        f"#define BW_KERNEL_TOO_MANY_SUBSTEPS {integration.TOO_MANY_SUBSTEPS}\n"
        f"#define BW_KERNEL_NOT_FINITE {integration.NOT_FINITE}\n"
        f"#define BW_MAX_SUBSTEPS {integration.DEFAULT_MAX_SUBSTEPS}\n"
        f"#define BW_DISPLACEMENT_JUMPED {jump_test.name}\n"
        f"#define BW_JUMP_WINDOW {integration.JUMP_WINDOW}\n"
        f"#define BW_JUMP_COUNT {integration.JUMP_COUNT}\n"
        f"#define BW_ROUNDING_JUMP {elements.ROUNDING_JUMP_MM!r}\n\n")
