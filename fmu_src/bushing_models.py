"""The four bushing models of the project, all run by one core (``bushing_core``).

- ``proposed``: the paper's model, eqs. 1-5, 16 parameters (``bushing_params``).
- ``spencer``: Spencer et al. (1997), Fig. 7 of the paper:
      F = c1*dy/dt + k1*(x - x0)
      dy/dt = [alpha*z + c0*dx/dt + k0*(x - y)] / (c0 + c1)
      dz/dt = -gamma*|u|*z*|z|^(n-1) - beta*u*|z|^n + A*u,   u = dx/dt - dy/dt
  Spencer puts gamma on the |u| term where the paper's eqs. 1-2 put beta; the parameters
  here keep Spencer's names and meaning, and the map below swaps them.
- ``bouc_wen``: the classic single Bouc-Wen element (Ok et al. 2005), Fig. 6 of the paper:
      F = c0*dx/dt + k0*x + alpha*z,   dz/dt from eq. 1 with u = dx/dt (paper's beta, gamma)
- ``kelvin_voigt``: the linear bushing of ADAMS/RecurDyn, one axis: F = k*x + c*dx/dt + preload.

Units are the paper's N-mm-s units throughout: z is a force in N, so alpha is
dimensionless and A in N/mm (Spencer's paper writes z in m and alpha in N/m; the force is
the same with z_here = alpha_Spencer * z_Spencer).

How the baselines run on the proposed model's core. Each is the proposed network (eqs. 1-5)
with elements made rigid or grounded in the limit:
- the left block becomes a plain spring to ground (``k0`` of the core): no hysteresis
  (alpha1 = A1 = beta1 = gamma1 = 0) and a spring k1 = RIGID*(k0 + 1 N/mm) in parallel with
  c1 = 1 N*s/mm, so y = x up to k0/k1 <= 1e-12;
- the right block's dashpot to ground c0 = RIGID*(c2 + k2 + A2 + 1) is a wall for the
  single Bouc-Wen and Kelvin-Voigt models (dw/dt = 0 up to c2/c0 <= 1e-12, so u2 = dx/dt),
  while for Spencer it is Spencer's own c1 and the right block is exactly Spencer's element.
The force differs from the exact baseline by about 1e-12 of itself (tests compare with
analytic forces and with scipy on the baselines' own equations); the integrator, its error
control and the FMU's error handling are the ones of the proposed model.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping

from . import bushing_params as proposed
from .bushing_params import (DAMPING, EXPONENT, GAIN, SPRING, WEIGHT, ParameterError, ParameterSpec, number_errors,
                             range_errors)

RIGID = 1e12
"""How much stiffer (or more viscous) than the rest a limit element is made (see above)."""
PLAUSIBLE_TRAVEL_MM = 100.0
PLAUSIBLE_VELOCITY_MM_S = 1000.0
"""Beyond a rubber bushing's travel and speed in service: the FMU warns above them (most likely
millimetres entered where metres are expected), and :meth:`BushingModel.plausible_force_bound`
is the force there."""


@dataclass(frozen=True)
class StateSpec:
    """An internal state exposed by the FMU: ``core_field`` of ``bushing_core.BushingState``."""
    name: str
    core_field: str
    unit: str      # "N" or "m" at the FMU (the core works in mm)
    meaning: str


@dataclass(frozen=True)
class BushingModel:
    name: str                    # command-line name: proposed, spencer, bouc_wen, kelvin_voigt
    identifier: str              # FMI modelIdentifier and the "model" of parameter files
    title: str
    specs: tuple[ParameterSpec, ...]
    states: tuple[StateSpec, ...]
    default_file: str            # parameter set in data/ used as the FMU's defaults
    _to_core: Callable[[Mapping[str, float]], dict]
    _check: Callable[[Mapping[str, float]], tuple[list[str], list[str]]]
    _offset: Callable[[Mapping[str, float]], float] = lambda p: 0.0

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(spec.name for spec in self.specs)

    @property
    def units(self) -> dict[str, str]:
        return {spec.name: spec.unit for spec in self.specs}

    def validate(self, params: Mapping[str, float]) -> tuple[list[str], list[str]]:
        """(errors, warnings) for a parameter set of this model, never raising. Errors make it
        unusable (missing, non-numbers, NaN, what the equations cannot take); warnings are
        physically doubtful but simulable values."""
        errors = number_errors(params, self.units, f" of the {self.name} model")
        if errors:
            return errors, []
        values = {name: float(params[name]) for name in self.parameter_names}
        errors, warnings = self._check(values)
        return range_errors(values, self.specs) + errors, warnings

    def check(self, params: Mapping[str, float]) -> dict[str, float]:
        """The parameters as floats in spec order, or ParameterError listing every problem
        (unknown names included)."""
        errors, _ = self.validate(params)
        unknown = sorted(set(params) - set(self.parameter_names))
        if unknown:
            errors.append(f"unknown parameter names {unknown} for the {self.name} model; "
                          f"allowed: {', '.join(self.parameter_names)}")
        if errors:
            raise ParameterError(f"invalid {self.name} parameters: " + "; ".join(errors))
        return {name: float(params[name]) for name in self.parameter_names}

    def core_parameters(self, params: Mapping[str, float]) -> dict[str, float]:
        """The proposed model's 16 parameters that simulate this model (see module docstring)."""
        return self._to_core(params)

    def plausible_force_bound(self, params: Mapping[str, float]) -> float:
        """A force [N] no bushing with these parameters should reach in service: every spring
        and Bouc-Wen gain of the model (A weighted by its alpha) and every dashpot in parallel,
        at PLAUSIBLE_TRAVEL_MM and PLAUSIBLE_VELOCITY_MM_S, plus the constant force. Above it
        the inputs are most likely in the wrong units (millimetres in the metre port)."""
        def weight(name):   # a Bouc-Wen gain A<i> counts with its alpha<i>
            return abs(params.get("alpha" + name[1:], 1.0)) if name.startswith("A") else 1.0
        stiffness = sum(abs(params[s.name]) * weight(s.name) for s in self.specs if s.unit == "N/mm")
        damping = sum(abs(params[s.name]) for s in self.specs if s.unit == "N.s/mm")
        return (stiffness * PLAUSIBLE_TRAVEL_MM + damping * PLAUSIBLE_VELOCITY_MM_S
                + abs(self.force_offset(params)))

    def force_offset(self, params: Mapping[str, float]) -> float:
        """Constant force [N] added to the core's force (Spencer's -k1*x0, Kelvin-Voigt's preload)."""
        return self._offset(params)


def _rigid_left_block(spring_to_ground: float) -> dict[str, float]:
    """Core parameters of block 1 reduced to a spring to ground (y = x)."""
    return {"k0": spring_to_ground, "k1": RIGID * (abs(spring_to_ground) + 1.0), "c1": 1.0,
            "alpha1": 0.0, "A1": 0.0, "beta1": 0.0, "gamma1": 0.0, "n1": 1.0}


def _wall(c2: float, k2: float, A2: float) -> float:
    """A dashpot to ground that does not move: dw/dt = 0 up to 1/RIGID."""
    return RIGID * (abs(c2) + abs(k2) + abs(A2) + 1.0)


# ---------------------------------------------------------------- Spencer
SPENCER_SPECS = (
    ParameterSpec("c0", "N.s/mm", "viscous damping in parallel with the Bouc-Wen element (large velocities)",
                  **DAMPING),
    ParameterSpec("k0", "N/mm", "stiffness in parallel with the Bouc-Wen element (large velocities)", **SPRING),
    ParameterSpec("c1", "N.s/mm", "dashpot from the internal displacement y to ground (roll-off at low velocity)",
                  minimum=0.0, exclusive=True, why="it divides dy/dt"),
    ParameterSpec("k1", "N/mm", "accumulator spring from x to ground", **SPRING),
    ParameterSpec("x0", "mm", "initial displacement of the accumulator spring k1 (preload -k1*x0)"),
    ParameterSpec("alpha", "1", "weight of the hysteretic force z", **WEIGHT),
    ParameterSpec("A", "N/mm", "Bouc-Wen initial stiffness", **GAIN),
    ParameterSpec("beta", "N^(1-n)/mm", "Spencer's beta: on u*|z|^n (the paper's gamma)"),
    ParameterSpec("gamma", "N^(1-n)/mm", "Spencer's gamma: on |u|*z*|z|^(n-1) (the paper's beta)"),
    ParameterSpec("n", "1", "Bouc-Wen exponent", **EXPONENT),
)


def _spencer_to_core(p):
    core = _rigid_left_block(p["k1"])
    core.update(c0=p["c1"], c2=p["c0"], k2=p["k0"], alpha2=p["alpha"], A2=p["A"],
                beta2=p["gamma"], gamma2=p["beta"], n2=p["n"])  # Spencer's gamma is eq. 2's beta
    return core


def _single_block_check(p):
    """Beyond the ranges of the specs, shared by Spencer and the single Bouc-Wen (both name
    their element's shape parameters beta, gamma)."""
    warnings = []
    if not p["beta"] + p["gamma"] > 0:
        warnings.append(f"beta + gamma = {p['beta'] + p['gamma']} should be > 0 (bounded hysteresis)")
    return [], warnings


# ---------------------------------------------------------------- single Bouc-Wen
BOUC_WEN_SPECS = (
    ParameterSpec("c0", "N.s/mm", "viscous damping in parallel", **DAMPING),
    ParameterSpec("k0", "N/mm", "linear stiffness in parallel", **SPRING),
    ParameterSpec("alpha", "1", "weight of the hysteretic force z", **WEIGHT),
    ParameterSpec("A", "N/mm", "Bouc-Wen initial stiffness", **GAIN),
    ParameterSpec("beta", "N^(1-n)/mm", "Bouc-Wen shape parameter on |u|*z*|z|^(n-1) (as in eq. 1)"),
    ParameterSpec("gamma", "N^(1-n)/mm", "Bouc-Wen shape parameter on u*|z|^n (as in eq. 1)"),
    ParameterSpec("n", "1", "Bouc-Wen exponent", **EXPONENT),
)


def _bouc_wen_to_core(p):
    core = _rigid_left_block(p["k0"])
    core.update(c0=_wall(p["c0"], 0.0, p["A"]), c2=p["c0"], k2=0.0, alpha2=p["alpha"], A2=p["A"],
                beta2=p["beta"], gamma2=p["gamma"], n2=p["n"])
    return core


# ---------------------------------------------------------------- Kelvin-Voigt
KELVIN_VOIGT_SPECS = (
    ParameterSpec("k", "N/mm", "stiffness", **SPRING),
    ParameterSpec("c", "N.s/mm", "viscous damping", **DAMPING),
    ParameterSpec("preload", "N", "force at x = 0"),
)


def _kelvin_voigt_to_core(p):
    core = _rigid_left_block(p["k"])
    core.update(c0=_wall(p["c"], 0.0, 0.0), c2=p["c"], k2=0.0, alpha2=0.0, A2=0.0,
                beta2=0.0, gamma2=0.0, n2=1.0)
    return core


def _no_further_check(p):
    return [], []


_Z1 = StateSpec("z1", "z1", "N", "hysteretic force of the left block (eq. 1)")
_Z2 = StateSpec("z2", "z2", "N", "hysteretic force of the right block (eq. 2)")
_Y = StateSpec("y", "y", "m", "displacement of the left plate (eq. 3)")
_W = StateSpec("w", "w", "m", "displacement of the right plate (eq. 4)")

MODELS: dict[str, BushingModel] = {
    "proposed": BushingModel(
        "proposed", proposed.MODEL_NAME, "proposed (paper eqs. 1-5)", proposed.PARAMETER_SPECS,
        (_Z1, _Z2, _Y, _W), "params_table5_combined.json", dict, proposed.constraint_checks),
    "spencer": BushingModel(
        "spencer", "SpencerBushing", "Spencer (1997)", SPENCER_SPECS,
        (StateSpec("z", "z2", "N", "hysteretic force"),
         StateSpec("y", "w", "m", "internal displacement (between the Bouc-Wen element and c1)")),
        "params_spencer_fit_synthetic_table5.json", _spencer_to_core, _single_block_check,
        lambda p: -p["k1"] * p["x0"]),
    "bouc_wen": BushingModel(
        "bouc_wen", "SingleBoucWenBushing", "single Bouc-Wen", BOUC_WEN_SPECS,
        (StateSpec("z", "z2", "N", "hysteretic force"),), "params_bouc_wen_fit_synthetic_table5.json",
        _bouc_wen_to_core, _single_block_check),
    "kelvin_voigt": BushingModel(
        "kelvin_voigt", "KelvinVoigtBushing", "Kelvin-Voigt (linear)", KELVIN_VOIGT_SPECS, (),
        "params_kelvin_voigt_fit_synthetic_table5.json", _kelvin_voigt_to_core, _no_further_check,
        lambda p: p["preload"]),
}
MODEL_NAMES = tuple(MODELS)


def get_model(name: str) -> BushingModel:
    """The model called ``name`` (command-line name or FMI identifier)."""
    if name in MODELS:
        return MODELS[name]
    for model in MODELS.values():
        if model.identifier == name:
            return model
    raise ParameterError(f"unknown model {name!r}; choose one of {', '.join(MODEL_NAMES)} "
                         f"(identifiers {', '.join(m.identifier for m in MODELS.values())})")
