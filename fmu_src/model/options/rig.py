"""``rig``: the displacement zero ``rig_displacement_zero`` [mm] and the load-cell zero
``rig_force_zero`` [N] of a measured test, F_measured = F(x - zero) + force zero: what a fit
estimates as nuisance parameters and keeps out of the FMU (an FMU takes them, where asked, as its
mounting's ``offset`` and ``preload``)."""
from __future__ import annotations

from ..definition import SearchCoordinate
from ..parameter_specs import ParameterSpec
from ..search_coordinates import KIND
from .element import OptionElement

RIG = "rig"


def rig_specs(count: int = 0) -> tuple[ParameterSpec, ...]:
    return (ParameterSpec("rig_displacement_zero", "mm", "the rig's displacement zero: the model sees x - it",
                          bound_powers=None),
            ParameterSpec("rig_force_zero", "N", "the load cell's zero: added to the model's force",
                          bound_powers=(0, 0), temperature="none"))


def rig_coordinates(count: int) -> tuple[SearchCoordinate, ...]:
    return (SearchCoordinate("rig_displacement_zero", KIND.rig_travel, -0.25, 0.25),
            SearchCoordinate("rig_force_zero", KIND.rig_force, -0.5, 0.5))


ELEMENT = OptionElement(
    token=RIG, word="the rig's offsets", order=90, usage=RIG, specs=rig_specs, coordinates=rig_coordinates,
    displacement_zero=lambda slot: f"{slot.m}[0]",
    force=lambda slot: f"{slot.m}[1]",
    rest_force=lambda slot: f"{slot.m}[1]",
    neutral=(("rig_displacement_zero", 0.0), ("rig_force_zero", 0.0)))
