"""How the fit's coordinates map to parameters: one object per kind of coordinate.

A model's search box (``definition.SearchBox``) lists a ``SearchCoordinate`` per free
parameter; its ``kind`` is one of the objects here. Each kind holds, together:

- ``reads(c)``: the other parameters its map reads (the search maps them first);
- ``bounds(c, scales)``: the coordinate's bounds, the declared ``c.low``, ``c.high`` unless the
  kind tightens them from the data;
- ``to_parameter(c, u, values, scales)``: coordinate u -> parameter value. Written with numpy's
  arithmetic alone, so that it takes complex u: the derivative of every kind is the complex step
  of this map (``SearchSpace.to_parameters_and_seeds``), exact to rounding, and no second
  definition of the map exists to drift from it;
- ``to_coordinate(c, value, params, scales)``: its inverse (a scale of 0 maps to -inf);
- ``floor_is_search_limit``: whether the lower bound is a limit of the search rather than a
  physical one a fit may rightly sit on (``FitResult.at_box_edge``).

``scales`` is the ``identification.fitting.search_space.SearchSpace`` (duck-typed: k_ref [N/mm], c_ref
[N*s/mm], F_ref [N], x_ref [mm], tau_ref = c_ref/k_ref [s], ``shortest_time_constant_s`` and
``time_constant(values, dashpot)``); ``values`` maps each parameter to its column of values.
"""
from __future__ import annotations

import math


class CoordinateKind:
    """A kind of coordinate (module docstring). Subclasses give ``to_parameter`` and
    ``to_coordinate``; the defaults read nothing and keep the declared bounds."""
    name = ""
    floor_is_search_limit = False

    def reads(self, c) -> tuple[str, ...]:
        return ()

    def bounds(self, c, scales) -> tuple[float, float]:
        return c.low, c.high

    def to_parameter(self, c, u, values, scales):
        raise NotImplementedError

    def to_coordinate(self, c, value: float, params, scales) -> float:
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"<coordinate kind {self.name}>"


def _log_ratio(value: float, scale: float) -> float:
    if not value > 0:
        return -math.inf
    ratio = value / scale
    # a subnormal value (a slow loop's start of 5e-324) over a scale of 100 underflows to 0, which
    # log10 refuses: the difference of the logs then, the log of the ratio (as ever) otherwise
    return math.log10(ratio) if ratio > 0 else math.log10(value) - math.log10(scale)


class LogScaled(CoordinateKind):
    """log10(value/scale), scale the data's reference named ``scale`` (k_ref, c_ref, F_ref, x_ref)."""

    def __init__(self, name: str, scale: str):
        self.name, self.scale = name, scale

    def to_parameter(self, c, u, values, scales):
        return getattr(scales, self.scale) * 10.0 ** u

    def to_coordinate(self, c, value, params, scales):
        return _log_ratio(value, getattr(scales, self.scale))


class Compliance(CoordinateKind):
    """log10(value * k_ref): a compliance [mm/N] over the data's reference compliance 1/k_ref
    (0, a rigid link, maps to -inf: the box's lowest)."""
    name = "compliance"

    def to_parameter(self, c, u, values, scales):
        return 10.0 ** u / scales.k_ref

    def to_coordinate(self, c, value, params, scales):
        return _log_ratio(value * scales.k_ref, 1.0)


class Gain(LogScaled):
    """A Bouc-Wen gain A: log10(A/k_ref), with A >= 1 N/mm (the paper's constraint) as a bound."""

    def __init__(self):
        super().__init__("gain", "k_ref")

    def bounds(self, c, scales):
        return max(c.low, max(math.log10(1.0 / scales.k_ref), -4.0)), c.high

    def to_parameter(self, c, u, values, scales):
        # the clamp keeps rounding at the bound from crossing it (its derivative there is 0);
        # numpy imported here: the FMUs load this module and carry no numpy, only the fit maps
        import numpy as np
        return np.maximum(scales.k_ref * 10.0 ** u, 1.0)


class Exponent(CoordinateKind):
    """The value itself (a Bouc-Wen exponent n, a fractional order alpha); its floor (n >= 0.1) is the search's."""
    name, floor_is_search_limit = "exponent", True

    def to_parameter(self, c, u, values, scales):
        return u

    def to_coordinate(self, c, value, params, scales):
        return value


class Value(CoordinateKind):
    """The value itself, in its own unit (a WLF constant C1 [1] or C2 [K], a temperature
    coefficient [1/K]): a law's constant that no reference of the data scales."""
    name = "value"

    def to_parameter(self, c, u, values, scales):
        return u

    def to_coordinate(self, c, value, params, scales):
        return value


class Linear(CoordinateKind):
    """value/scale, scale the data's reference named ``scale`` (F_ref, x_ref): a signed offset
    (a backbone's force at its middle knot). With ``centre``, the data's estimate of the value
    named so (x_zero, F_zero: where the records' stroke and force are centred) is its origin:
    (value - centre)/scale, a rig's zero searched about what the records show."""

    def __init__(self, name: str, scale: str, centre: str = ""):
        self.name, self.scale, self.centre = name, scale, centre

    def _origin(self, scales) -> float:
        return getattr(scales, self.centre, 0.0) if self.centre else 0.0

    def to_parameter(self, c, u, values, scales):
        origin = self._origin(scales)
        return u * getattr(scales, self.scale) + origin if origin else u * getattr(scales, self.scale)

    def to_coordinate(self, c, value, params, scales):
        return (value - self._origin(scales)) / getattr(scales, self.scale)


class Segment(CoordinateKind):
    """log10 of a backbone segment's secant stiffness over k_ref: the knot's force is its
    neighbour's (``c.partner``) plus 10^value*k_ref times the knots' distance (``c.over``: this
    knot's position, the neighbour's), so that a backbone built outward from its middle knot is
    monotone by construction."""
    name = "segment"

    def reads(self, c):
        return (c.partner, *c.over)

    def to_parameter(self, c, u, values, scales):
        return values[c.partner] + 10.0 ** u * scales.k_ref * (values[c.over[0]] - values[c.over[1]])

    def to_coordinate(self, c, value, params, scales):
        secant = (value - params[c.partner]) / (params[c.over[0]] - params[c.over[1]])
        return _log_ratio(max(secant, 1e-12 * scales.k_ref), scales.k_ref)


class Cubic(CoordinateKind):
    """value*x_ref^2/k_ref: a cubic spring's share of the force at the largest amplitude, in k_ref's."""
    name = "cubic"

    def to_parameter(self, c, u, values, scales):
        return u * scales.k_ref / scales.x_ref ** 2

    def to_coordinate(self, c, value, params, scales):
        return value * scales.x_ref ** 2 / scales.k_ref


class TimeConstant(CoordinateKind):
    """log10(tau/tau_ref) of a dashpot over the stiffnesses it works against (``c.over``),
    tau = value/sum(over); the floor is TIME_CONSTANT_FLOOR sample intervals (faster modes are
    invisible in the samples)."""
    name, floor_is_search_limit = "time_constant", True

    def reads(self, c):
        return tuple(c.over)

    def bounds(self, c, scales):
        return max(c.low, math.log10(scales.shortest_time_constant_s / scales.tau_ref)), c.high

    def to_parameter(self, c, u, values, scales):
        return scales.tau_ref * 10.0 ** u * sum(values[name] for name in c.over)

    def to_coordinate(self, c, value, params, scales):
        return _log_ratio(value / sum(params[name] for name in c.over), scales.tau_ref) if value > 0 else -math.inf


class Slower(CoordinateKind):
    """log10(tau/tau_partner): a dashpot's time constant (value over the stiffnesses ``c.over``)
    over that of the dashpot ``c.partner`` (a time-constant coordinate), so two Maxwell elements
    never swap places between fits."""
    name = "slower"

    def reads(self, c):
        return (*c.over, c.partner)

    def to_parameter(self, c, u, values, scales):
        return scales.time_constant(values, c.partner) * 10.0 ** u * sum(values[name] for name in c.over)

    def to_coordinate(self, c, value, params, scales):
        tau = value / sum(params[name] for name in c.over)
        return _log_ratio(tau, scales.time_constant(params, c.partner))


def shape_scale(scales, n):
    """beta = coordinate * k_ref / F_ref^n: a Bouc-Wen shape parameter's scale [N^(1-n)/mm]."""
    return scales.k_ref / scales.F_ref ** n


class Shape(CoordinateKind):
    """value*F_ref^n/k_ref, n the block's exponent (``c.exponent``); beta >= 0 is the paper's constraint."""
    name = "shape"

    def reads(self, c):
        return (c.exponent,)

    def to_parameter(self, c, u, values, scales):
        return u * shape_scale(scales, values[c.exponent])

    def to_coordinate(self, c, value, params, scales):
        return value / shape_scale(scales, params[c.exponent])


class ShapeSum(CoordinateKind):
    """partner' + sign*value' of a block (value' = value*F_ref^n/k_ref), >= 0: the paper's
    constraints beta1 + gamma1 > 0 (sign +1) and beta2 - gamma2 > 0 (sign -1) as a bound."""
    name = "shape_sum"

    def reads(self, c):
        return (c.exponent, c.partner)

    def to_parameter(self, c, u, values, scales):
        return c.sign * (u * shape_scale(scales, values[c.exponent]) - values[c.partner])

    def to_coordinate(self, c, value, params, scales):
        return (params[c.partner] + c.sign * value) / shape_scale(scales, params[c.exponent])


class PowerLaw(CoordinateKind):
    """log10(value/(k_ref*tau_ref^a)), a the parameter ``c.exponent``: the coefficient of an element
    whose stiffness grows like omega^a (a fractional derivative's), as its |K*| at the data's own
    time scale in units of k_ref."""
    name = "power_law"

    def reads(self, c):
        return (c.exponent,)

    def to_parameter(self, c, u, values, scales):
        return scales.k_ref * scales.tau_ref ** values[c.exponent] * 10.0 ** u

    def to_coordinate(self, c, value, params, scales):
        return _log_ratio(value, scales.k_ref * scales.tau_ref ** params[c.exponent])


class Resonance(CoordinateKind):
    """log10(f/1 Hz) of a mass [N.s^2/mm] as the resonance f = sqrt(k/mass)/(2*pi) it makes with
    the stiffnesses ``c.over`` (k their sum): a hydraulic mount's inertia track by its tuning."""
    name = "resonance"

    def reads(self, c):
        return tuple(c.over)

    def to_parameter(self, c, u, values, scales):
        return sum(values[name] for name in c.over) / (2.0 * math.pi * 10.0 ** u) ** 2

    def to_coordinate(self, c, value, params, scales):
        return math.log10(math.sqrt(sum(params[name] for name in c.over) / value) / (2.0 * math.pi))


class DampingRatio(CoordinateKind):
    """log10(zeta) of a dashpot as the damping ratio zeta = value/(2*sqrt(k*mass)) of the
    oscillator it damps: the stiffnesses ``c.over`` (k their sum) and the mass ``c.partner``."""
    name = "damping_ratio"

    def reads(self, c):
        return (*c.over, c.partner)

    def to_parameter(self, c, u, values, scales):
        return 2.0 * 10.0 ** u * (sum(values[name] for name in c.over) * values[c.partner]) ** 0.5

    def to_coordinate(self, c, value, params, scales):
        critical = 2.0 * math.sqrt(sum(params[name] for name in c.over) * params[c.partner])
        return _log_ratio(value, critical)


class QuadraticDamping(CoordinateKind):
    """log10(value/(c_ref^2/(k_ref*x_ref))) of a damping whose force is value*|v|*v
    [N.s^2/mm^2]: against the force c_ref*v_ref of the data's damping at its velocity scale
    v_ref = x_ref/tau_ref."""
    name = "quadratic_damping"

    def to_parameter(self, c, u, values, scales):
        return scales.c_ref ** 2 / (scales.k_ref * scales.x_ref) * 10.0 ** u

    def to_coordinate(self, c, value, params, scales):
        return _log_ratio(value, scales.c_ref ** 2 / (scales.k_ref * scales.x_ref))


class _Kinds:
    """The kinds by name, as models name them: ``KIND.stiffness`` (an attribute per kind)."""

    def __init__(self, *kinds: CoordinateKind):
        for kind in kinds:
            setattr(self, kind.name, kind)

    def __iter__(self):
        return iter(vars(self).values())


KIND = _Kinds(
    LogScaled("stiffness", "k_ref"),      # log10(value/k_ref)
    LogScaled("damping", "c_ref"),        # log10(value/c_ref)
    LogScaled("force", "F_ref"),          # log10(value/F_ref): a friction force limit
    LogScaled("travel", "x_ref"),         # log10(value/x_ref): a friction's travel, x_ref the largest amplitude
    Compliance(),                         # log10(value*k_ref): a compliance in series
    Linear("offset_force", "F_ref"),      # value/F_ref: a signed force (a backbone's at its middle knot)
    Linear("rig_travel", "x_ref", "x_zero"),    # (value - x_zero)/x_ref: a rig's displacement zero
    Linear("rig_force", "F_ref", "F_zero"),     # (value - F_zero)/F_ref: a load cell's zero
    Value(),                              # the value itself: a temperature law's constant
    Segment(), Gain(), Exponent(), Cubic(), TimeConstant(), Slower(), Shape(), ShapeSum(), PowerLaw(), Resonance(), DampingRatio(),
    QuadraticDamping())
"""Every kind of coordinate, by name: ``KIND.stiffness``, ``KIND.time_constant``, ..."""


def evaluation_order(coordinates) -> list:
    """The coordinates in an order where each kind's ``reads`` are mapped before it (a
    parameter no coordinate maps, such as a weight held at 1, is there from the start). Raises
    ValueError naming the coordinates of a cycle."""
    pending = list(coordinates)
    mapped = {c.parameter for c in pending}
    done: set[str] = set()
    ordered = []
    while pending:
        ready = [c for c in pending if all(name in done or name not in mapped for name in c.kind.reads(c))]
        if not ready:
            raise ValueError("the search coordinates " + ", ".join(c.parameter for c in pending)
                             + " read each other in a cycle")
        for c in ready:
            ordered.append(c)
            done.add(c.parameter)
        pending = [c for c in pending if c.parameter not in done]
    return ordered
