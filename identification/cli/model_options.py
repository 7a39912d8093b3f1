"""The command line's model options: ``--options``, ``--static``, ``--backbone-knots``, ``--fix``.

They turn a model's name into the model a fit or ``compare`` runs (``fmu_src.model.derived``: the
model with a backbone, travel limits or the rig's offsets) and the parameters it holds:

- ``--options backbone9,limits,maxwell,rig``: the options every model gets (``fit --model berg+limits``
  names them too); ``--options none``: none (``compare`` assumes none either:
  ``identification.analysis.first_contact``);
- ``--backbone-knots -4,-2,0,2,4`` [mm]: the backbone's knots, held (its forces fitted), which
  gives the models a backbone of that many knots;
- ``--static FILE``: a quasi-static test (a slow triangle or ramp); the backbone's forces are read
  off it (``identification.measured.static_curve``) at ``--backbone-knots``, or at as many knots as
  ``--options backbone<K>`` says (9 without) over its range, and held; it is a training test too. With the rig's offsets the backbone passes through
  0 at its knot at 0 mm, the load-cell zero carries the force there, and the displacement zero is
  the static test's (held at 0);
- ``--fix NAME=VALUE``: a parameter held at a value (the model's units), repeatable.

Every problem is a ``UsageError`` naming the argument and what is allowed.
"""
from __future__ import annotations

from dataclasses import dataclass

from fmu_src.model.derived import derive
from fmu_src.model.options import Options
from fmu_src.model.options.backbone import BACKBONE
from fmu_src.model.options.rig import RIG
from fmu_src.model.parameter_specs import ParameterError
from fmu_src.model.registry import get_model
from identification.errors import UsageError
from identification.measured.measurements import load_measurement
from identification.measured.rig_tests import RigTest
from identification.measured.static_curve import DEFAULT_KNOTS, StaticCurve, read_static_curve

NONE = "none"
"""``--options none``: no option, and nothing assumed (``compare``'s first contact off)."""


@dataclass(frozen=True)
class ModelOptions:
    """What the model options ask for: the options every model gets, the parameters held, the
    static curve read (or None) and the training test it adds (or None)."""
    options: Options
    fixed: dict
    curve: StaticCurve | None = None
    static_test: RigTest | None = None

    def model(self, name):
        """The model ``name`` (a name, an identifier, a model) with these options added."""
        bushing = get_model(name)
        base = bushing.base if bushing.base is not None else bushing
        present = bushing.options or Options()
        try:
            merged = present.union(self.options)
        except ParameterError as error:
            raise UsageError(f"{bushing.name} and the options ({', '.join(self.options.tokens)}): {error}") from None
        return derive(base, merged)

    def fixed_for(self, bushing) -> dict[str, float]:
        """The held parameters ``bushing`` has (a --fix the model does not have is refused)."""
        unknown = sorted(set(self.fixed) - set(bushing.parameter_names))
        if unknown:
            raise UsageError(f"--fix {', '.join(unknown)}: not parameters of the {bushing.name} model; its parameters: "
                             f"{', '.join(bushing.parameter_names)}")
        return dict(self.fixed)

    def training(self, tests: list) -> list:
        """The training tests with the quasi-static test added (where it is not among them)."""
        if self.static_test is None:
            return list(tests)
        names = {t.name for t in tests}
        return list(tests) + ([self.static_test] if self.static_test.name not in names else [])

    def describe(self) -> str:
        return self.curve.describe() if self.curve is not None else ""


def model_options_of(args) -> ModelOptions:
    """The model options of the parsed ``args`` (module docstring); ``--options none`` is no option."""
    text = (args.options or "").strip()
    try:
        options = Options() if text.lower() == NONE else Options.parse(part for part in text.split(",") if part.strip())
    except ParameterError as exc:
        raise UsageError(f"--options {args.options}: {exc}") from None
    static = load_measurement(args.static) if args.static is not None else None
    return build_model_options(options, fixed_values(args.fix), static, args.backbone_knots)


def build_model_options(options: Options, fixed: dict, static=None, knots=None) -> ModelOptions:
    """The model options for ``options``, the parameters held by ``--fix`` (``fixed``), a
    quasi-static test's ``Measurement`` (``static``, or None) and the backbone's knot positions
    [mm] (``knots``, or None): the static curve read at the knots, or at as many as the options'
    backbone has (9 without one), and held."""
    fixed = dict(fixed)
    curve = static_test = None
    if static is not None:
        curve = read_static_curve(static, knots, len(knots) if knots is not None else options.count(BACKBONE) or DEFAULT_KNOTS)
        knots = list(curve.knots_mm)
        static_test = RigTest(static)
    if knots is not None:
        if len(knots) < 2 or any(b <= a for a, b in zip(knots, knots[1:])):
            raise UsageError(f"--backbone-knots {','.join(f'{k:g}' for k in knots)}: give 2 or more knot positions "
                             "[mm], increasing")
        if options.count(BACKBONE) and options.count(BACKBONE) != len(knots):
            raise UsageError(f"--options backbone{options.count(BACKBONE)} and {len(knots)} backbone knots: give one count")
        options = options.without(BACKBONE).union(Options(((BACKBONE, len(knots)),)))
        fixed.update({f"backbone_x{i + 1}": float(k) for i, k in enumerate(knots)})
    if curve is not None:
        forces = curve.parameters(pinned_at_zero=RIG in options)
        fixed.update({name: value for name, value in forces.items() if name.startswith("backbone_F")})
        if RIG in options:     # the static test's displacement is the backbone's: its zero is the model's
            fixed.setdefault("rig_displacement_zero", 0.0)
    return ModelOptions(options, fixed, curve, static_test)


def fixed_values(texts) -> dict[str, float]:
    """{name: value} of repeated ``--fix NAME=VALUE``."""
    out = {}
    for text in texts or ():
        name, _, value = text.partition("=")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise UsageError(f"--fix {text}: give NAME=VALUE with a number in the parameter's unit, e.g. "
                             "--fix limit_exponent_pos=2") from None
    return out
