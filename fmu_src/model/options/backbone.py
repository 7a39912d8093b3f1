"""``backbone<K>``: a measured static force-deflection curve through K knots (``backbone_x1`` ...
[mm], ``backbone_F1`` ... [N]), the monotone cubic of ``elements.pchip_slope`` (scipy's
PchipInterpolator: monotone data give a monotone curve) and straight beyond the end knots with
their slopes; it replaces the base's static spring (``BushingModel.static_spring``, held at 0) and
adds to its force. A model whose static spring carries more than its static force (the paper's k0
also carries the left block's hysteresis) names none, and the backbone adds to it."""
from __future__ import annotations

from ..definition import SearchCoordinate
from ..parameter_specs import Constraint, ParameterSpec
from ..search_coordinates import KIND
from .element import OptionElement, tuple_text

BACKBONE = "backbone"
MAX_KNOTS = 32
"""The most knots a backbone takes (a static curve needs a few; each is two FMU parameters)."""


def backbone_specs(knots: int) -> tuple[ParameterSpec, ...]:
    """The knots' positions [mm] and forces [N]: ``backbone_x1`` ... ``backbone_xK``, ``backbone_F1`` ..."""
    return (tuple(ParameterSpec(f"backbone_x{i + 1}", "mm", f"the backbone's knot {i + 1}: its displacement "
                                "(increasing from knot to knot)", bound_powers=None) for i in range(knots))
            + tuple(ParameterSpec(f"backbone_F{i + 1}", "N", f"the backbone's knot {i + 1}: its static force "
                                  "(not decreasing from knot to knot)", bound_powers=(0, 0),
                                  temperature="elastic") for i in range(knots)))


def backbone_constraints(knots: int) -> tuple[Constraint, ...]:
    """Knots increasing, forces not decreasing: refused otherwise (both FMUs and parameter files)."""
    out = []
    for i in range(1, knots):
        out.append(Constraint(((f"backbone_x{i + 1}", 1.0), (f"backbone_x{i}", -1.0)), 0.0, True, True, "mm",
                              "the backbone's knots must increase"))
        out.append(Constraint(((f"backbone_F{i + 1}", 1.0), (f"backbone_F{i}", -1.0)), 0.0, False, True, "N",
                              "a backbone is monotone: its forces must not decrease from knot to knot"))
    return tuple(out)


def backbone_coordinates(knots: int) -> tuple[SearchCoordinate, ...]:
    """The force at the middle knot as an offset, the others as the slopes of their segments outward."""
    anchor = knots // 2
    coordinates = (SearchCoordinate(f"backbone_F{anchor + 1}", KIND.offset_force, -1.0, 1.0),)
    for i in range(anchor + 1, knots):
        coordinates += (SearchCoordinate(f"backbone_F{i + 1}", KIND.segment, -4.0, 2.0,
                                         over=(f"backbone_x{i + 1}", f"backbone_x{i}"), partner=f"backbone_F{i}"),)
    for i in range(anchor - 1, -1, -1):
        coordinates += (SearchCoordinate(f"backbone_F{i + 1}", KIND.segment, -4.0, 2.0,
                                         over=(f"backbone_x{i + 1}", f"backbone_x{i + 2}"),
                                         partner=f"backbone_F{i + 2}"),)
    return coordinates


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


ELEMENT = OptionElement(
    token=BACKBONE, word="a measured backbone", order=10, usage=f"{BACKBONE}<K> (a backbone of K knots, 2 to {MAX_KNOTS})",
    specs=backbone_specs, coordinates=backbone_coordinates, constraints=backbone_constraints,
    counted=True, count_range=(2, MAX_KNOTS), replaces_static_spring=True,
    prepare=lambda p: f"backbone_prepare({tuple_text(p)})",
    helpers=backbone_source, shared=frozenset({"pchip_slope", "pchip_end_slope", "hermite"}),
    force=lambda slot: f"backbone_force({slot.m}, u)",
    rest_force=lambda slot: f"backbone_force({slot.m}, u)")
